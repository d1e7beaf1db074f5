#include "lumar/capture/frame_queue.h"

#include <chrono>

#include "lumar/base/error.h"

namespace lumar::capture {

FrameQueue::FrameQueue(std::size_t capacity, QueuePolicy policy) : capacity_(capacity), policy_(policy) {
  if (capacity == 0) throw InputError("frame queue: capacity must be at least 1");
}

bool FrameQueue::push(Frame frame) {
  std::unique_lock lock(mutex_);
  ++stats_.pushed;
  if (closed_) return false;
  if (frames_.size() >= capacity_) {
    if (policy_ == QueuePolicy::KeepNewest) {
      frames_.pop_front();
      ++stats_.stale_dropped;
    } else {
      ++stats_.back_pressure;
      const Nanos t0 = monotonic_now();
      not_full_.wait(lock, [&] { return closed_ || frames_.size() < capacity_; });
      stats_.back_pressure_time += monotonic_now() - t0;
      if (closed_) return false;
    }
  }
  frames_.push_back(std::move(frame));
  stats_.high_water = std::max(stats_.high_water, frames_.size());
  lock.unlock();
  not_empty_.notify_one();
  return true;
}

bool FrameQueue::pop(Frame& frame, Nanos timeout) {
  std::unique_lock lock(mutex_);
  if (!not_empty_.wait_for(lock, std::chrono::nanoseconds(timeout), [&] { return closed_ || !frames_.empty(); }))
    return false;
  if (frames_.empty()) return false;  // closed and drained
  frame = std::move(frames_.front());
  frames_.pop_front();
  ++stats_.popped;
  lock.unlock();
  not_full_.notify_one();
  return true;
}

void FrameQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  not_empty_.notify_all();
  not_full_.notify_all();
}

bool FrameQueue::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

QueueStats FrameQueue::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::size_t FrameQueue::size() const {
  std::lock_guard lock(mutex_);
  return frames_.size();
}

}  // namespace lumar::capture
