#pragma once
// A bounded queue of frames between a capture thread and its consumer, with one of
// two policies:
//   KeepNewest (live display): a push into a full queue drops the oldest frame and
//     counts it as stale; the consumer always gets the freshest picture.
//   KeepAll (recording): a push into a full queue waits for room, and the wait is
//     counted and timed as back-pressure; no frame is ever dropped.
// Thread-safe for one producer and any number of consumers.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>

#include "lumar/base/time.h"
#include "lumar/capture/frame_source.h"

namespace lumar::capture {

enum class QueuePolicy { KeepNewest, KeepAll };

struct QueueStats {
  std::uint64_t pushed = 0;         // frames offered by the producer
  std::uint64_t popped = 0;         // frames handed to the consumer
  std::uint64_t stale_dropped = 0;  // KeepNewest: replaced by a newer frame before being taken
  std::uint64_t back_pressure = 0;  // KeepAll: pushes that found the queue full and waited
  Nanos back_pressure_time = 0;     // KeepAll: total time the producer waited
  std::size_t high_water = 0;       // most frames ever waiting
};

class FrameQueue {
 public:
  // InputError for capacity 0.
  FrameQueue(std::size_t capacity, QueuePolicy policy);

  // KeepNewest: never blocks. KeepAll: blocks while full. False once closed (the
  // frame is not taken).
  bool push(Frame frame);
  // Waits at most `timeout` for a frame. False on timeout, or when the queue is closed
  // and empty (check closed()).
  bool pop(Frame& frame, Nanos timeout);
  // No more pushes; waiting pushes and pops wake up. Frames already queued can still
  // be popped. Idempotent.
  void close();
  bool closed() const;

  QueueStats stats() const;
  std::size_t size() const;
  std::size_t capacity() const { return capacity_; }
  QueuePolicy policy() const { return policy_; }

 private:
  const std::size_t capacity_;
  const QueuePolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<Frame> frames_;
  bool closed_ = false;
  QueueStats stats_;
};

}  // namespace lumar::capture
