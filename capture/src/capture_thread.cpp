#include "lumar/capture/capture_thread.h"

#include <chrono>
#include <cmath>

#include "lumar/base/error.h"
#include "lumar/capture/v4l2_source.h"

namespace lumar::capture {

const char* to_string(CaptureEnd end) {
  switch (end) {
    case CaptureEnd::Running:
      return "running";
    case CaptureEnd::EndOfStream:
      return "end of stream";
    case CaptureEnd::Stopped:
      return "stopped";
    case CaptureEnd::Vanished:
      return "camera vanished";
    case CaptureEnd::Failed:
      return "failed";
  }
  return "?";
}

CaptureThread::CaptureThread(std::unique_ptr<FrameSource> source, FrameQueue& queue)
    : source_(std::move(source)), queue_(queue), description_(source_->describe()) {
  thread_ = std::thread([this] { run(); });
}

CaptureThread::~CaptureThread() { stop(); }

void CaptureThread::finish(CaptureEnd end, std::string message, bool input_error) {
  {
    std::lock_guard lock(mutex_);
    end_ = end;
    message_ = std::move(message);
    input_error_ = input_error;
  }
  queue_.close();
}

void CaptureThread::run() {
  try {
    Frame frame;
    while (!stop_) {
      if (!source_->read(frame)) return finish(CaptureEnd::EndOfStream, {});
      ++frames_read_;
      if (!queue_.push(std::move(frame))) break;  // closed under us: the consumer is done
      frame = Frame{};
    }
    finish(CaptureEnd::Stopped, {});
  } catch (const CameraVanished& e) {
    finish(CaptureEnd::Vanished, e.what());
  } catch (const InputError& e) {
    finish(CaptureEnd::Failed, e.what(), true);
  } catch (const std::exception& e) {
    finish(CaptureEnd::Failed, e.what());
  }
}

void CaptureThread::stop() {
  stop_ = true;
  queue_.close();
  join();
}

void CaptureThread::join() {
  if (thread_.joinable()) thread_.join();
}

CaptureEnd CaptureThread::end() const {
  std::lock_guard lock(mutex_);
  return end_;
}

bool CaptureThread::input_error() const {
  std::lock_guard lock(mutex_);
  return input_error_;
}

std::string CaptureThread::message() const {
  std::lock_guard lock(mutex_);
  return message_;
}

RealTimeSource::RealTimeSource(std::unique_ptr<FrameSource> file, double speed)
    : file_(std::move(file)), speed_(speed) {
  if (!(speed > 0) || !std::isfinite(speed)) throw InputError(file_->describe() + ": playback speed must be positive");
}

bool RealTimeSource::read(Frame& frame) {
  if (!file_->read(frame)) return false;
  if (start_ < 0) {
    start_ = monotonic_now();
    first_time_ = frame.time;
  }
  Nanos due = start_ + Nanos(std::llround(double(frame.time - first_time_) / speed_));
  due = std::max(due, last_ + 1);  // times must increase
  const Nanos wait = due - monotonic_now();
  if (wait > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
  frame.time = due;
  last_ = due;
  return true;
}

}  // namespace lumar::capture
