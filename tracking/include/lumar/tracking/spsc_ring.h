#pragma once
// A bounded single-producer single-consumer queue without locks: the tracker's reader
// thread pushes, the render loop pops, and neither ever waits for the other. When the
// consumer falls behind and the ring is full, push() refuses (the caller counts it).
#include <atomic>
#include <cstddef>
#include <optional>
#include <vector>

namespace lumar::tracking {

template <class T>
class SpscRing {
 public:
  // Holds up to `capacity` items (at least 1).
  explicit SpscRing(std::size_t capacity) : slots_(std::max<std::size_t>(capacity, 1) + 1) {}

  // Producer thread only. False when full.
  bool push(const T& item) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t next = (tail + 1) % slots_.size();
    if (next == head_.load(std::memory_order_acquire)) return false;
    slots_[tail] = item;
    tail_.store(next, std::memory_order_release);
    return true;
  }

  // Consumer thread only.
  std::optional<T> pop() {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return std::nullopt;
    T item = slots_[head];
    head_.store((head + 1) % slots_.size(), std::memory_order_release);
    return item;
  }

  std::size_t capacity() const { return slots_.size() - 1; }

 private:
  std::vector<T> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};  // next to pop
  alignas(64) std::atomic<std::size_t> tail_{0};  // next to fill
};

}  // namespace lumar::tracking
