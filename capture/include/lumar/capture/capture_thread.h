#pragma once
// One thread per frame source, reading frames into a FrameQueue until the source ends,
// fails, or stop() is called. The queue's policy decides what happens when the
// consumer is slow (frame_queue.h). However the thread ends, it closes the queue, so
// a consumer waiting in pop() wakes up and can ask end() and message() why.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "lumar/capture/frame_queue.h"
#include "lumar/capture/frame_source.h"

namespace lumar::capture {

enum class CaptureEnd {
  Running,
  EndOfStream,  // the source said there are no more frames
  Stopped,      // stop() was called, or the queue was closed
  Vanished,     // the camera went away (CameraVanished)
  Failed,       // the source threw (a stalled camera, a corrupt file, ...)
};
const char* to_string(CaptureEnd end);

class CaptureThread {
 public:
  // Starts reading at once. The queue must outlive the thread.
  CaptureThread(std::unique_ptr<FrameSource> source, FrameQueue& queue);
  ~CaptureThread();  // stop()
  CaptureThread(const CaptureThread&) = delete;
  CaptureThread& operator=(const CaptureThread&) = delete;

  // Asks the thread to end, closes the queue (waking a blocked push) and joins. Returns
  // once the source's current read() has returned. Idempotent.
  void stop();
  // Joins without asking (after the source ended by itself). Idempotent.
  void join();

  CaptureEnd end() const;
  bool input_error() const;     // Failed because of bad input (InputError), not a device fault
  std::string message() const;  // the source's one-line error for Vanished / Failed ("" otherwise)
  std::uint64_t frames_read() const { return frames_read_; }
  std::string describe() const { return description_; }

 private:
  void run();
  void finish(CaptureEnd end, std::string message, bool input_error = false);

  std::unique_ptr<FrameSource> source_;
  FrameQueue& queue_;
  const std::string description_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_read_{0};
  mutable std::mutex mutex_;  // guards end_, message_, input_error_
  CaptureEnd end_ = CaptureEnd::Running;
  std::string message_;
  bool input_error_ = false;
  std::thread thread_;
};

// Plays a file-like source (video file, image sequence, recording) as a live camera:
// each frame is returned when its time has come on CLOCK_MONOTONIC, counted from the
// first read(), and its time becomes that CLOCK_MONOTONIC time. Frames the consumer
// takes too late are not skipped (a file holds every frame).
class RealTimeSource final : public FrameSource {
 public:
  explicit RealTimeSource(std::unique_ptr<FrameSource> file, double speed = 1.0);
  bool read(Frame& frame) override;
  cv::Size frame_size() const override { return file_->frame_size(); }
  double nominal_fps() const override { return file_->nominal_fps() * speed_; }
  std::string describe() const override { return file_->describe(); }
  // In the played-back time, as the frames' times.
  Nanos shutter_time() const override { return Nanos(std::llround(double(file_->shutter_time()) / speed_)); }

 private:
  std::unique_ptr<FrameSource> file_;
  double speed_;
  Nanos start_ = -1, first_time_ = 0, last_ = 0;
};

}  // namespace lumar::capture
