#pragma once
// A bounded queue between two stages of the pipelined replay (replay_overlay.cpp): push
// waits while full, pop while empty, and close() wakes both for good, so that a stage
// that stops (the sink said so, or threw) never leaves another waiting. Frames from a
// camera, with their drop policies and statistics, go through capture::FrameQueue instead.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>

namespace lumar::pipeline {

template <typename T>
class StageQueue {
 public:
  explicit StageQueue(std::size_t capacity) : capacity_(capacity) {}

  // False once closed (the item is dropped).
  bool push(T item) {
    std::unique_lock lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }
  // Waits until a push would not wait; false once closed. A producer that calls it
  // before making its item starts the item no earlier than the next stage can take it,
  // so the item's latency is not time spent queued.
  bool wait_for_room() {
    std::unique_lock lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    return !closed_;
  }
  // False once closed and empty.
  bool pop(T& item) {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return false;
    item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return true;
  }
  // No more pushes; what is queued can still be popped. Idempotent.
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

 private:
  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace lumar::pipeline
