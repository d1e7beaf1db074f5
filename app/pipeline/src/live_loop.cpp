#include "lumar/pipeline/live_loop.h"

#include <spdlog/spdlog.h>

#include <thread>

#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"

namespace lumar::pipeline {

namespace {
constexpr Nanos kIdle = 50'000'000;  // longest wait for a frame before on_idle runs again
}  // namespace

LiveLoop::LiveLoop(std::unique_ptr<capture::FrameSource> source, std::unique_ptr<tracking::TrackerDriver> driver,
                   tracking::Rig rig, LiveLoopSettings settings)
    : source_(std::move(source)),
      driver_(std::move(driver)),
      settings_(std::move(settings)),
      pairing_(rig, driver_ ? driver_->settings().stations.front() : 1),
      queue_(settings_.queue_frames, settings_.policy) {
  if (settings_.filter) filter_.emplace(*settings_.filter);
}

LiveLoop::~LiveLoop() {
  if (capture_) capture_->stop();
  if (driver_) driver_->stop();
}

void LiveLoop::use_recorded_poses(std::shared_ptr<const capture::RecordingReplay> recording) {
  recording_ = std::move(recording);
  recorded_times_.clear();
  for (const auto& f : recording_->reader().frames()) {
    if (f.index < 0) continue;
    if (std::size_t(f.index) >= recorded_times_.size()) recorded_times_.resize(std::size_t(f.index) + 1, -1);
    recorded_times_[std::size_t(f.index)] = f.time;
  }
}

void LiveLoop::take_samples() {
  if (!driver_) return;
  batch_.clear();
  driver_->take_samples(batch_);
  if (batch_.empty()) return;
  if (observer_) observer_(batch_);
  stats_.samples += batch_.size();
  stats_.last_sample = monotonic_now();
  if (filter_)
    for (auto& s : batch_) s = filter_->filter(s);
  pairing_.add(batch_);
}

// One line when the tracker stops delivering (unplugged, silent, resetting) and one when
// it is back, not one per frame or per reset attempt; nothing while it first connects.
void LiveLoop::report_tracker_state() {
  if (!driver_) return;
  const auto status = driver_->status();
  const bool connected = status.state == tracking::TrackerState::connected;
  if (connected == tracker_ok_) return;
  if (!connected && was_connected_)
    spdlog::warn("{}: tracker lost ({}); frames have no pose until it is back", settings_.what, status.message);
  else if (connected && was_connected_)
    spdlog::info("{}: tracker back", settings_.what);
  was_connected_ = was_connected_ || connected;
  tracker_ok_ = connected;
}

void LiveLoop::wait_for_tracker(Nanos timeout, const std::string& tracker_name) {
  if (!driver_) return;
  catch_stop_signals();
  driver_->start();
  const Nanos give_up = monotonic_now() + timeout;
  while (pairing_.samples() == 0 && !stop_requested()) {
    if (monotonic_now() >= give_up) {
      const std::string why = driver_->status().message;
      driver_->stop();
      throw InputError(tracker_name + ": no pose from the tracker within " +
                       std::to_string(int(nanos_to_seconds(timeout))) + " s (" + (why.empty() ? "no answer" : why) +
                       "); check that it is on, the port, --tracker-device and --baud");
    }
    take_samples();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::optional<Pose> LiveLoop::recorded_pose(const capture::Frame& frame, Nanos offset) const {
  if (frame.index < 0 || std::size_t(frame.index) >= recorded_times_.size()) return std::nullopt;
  const Nanos t = recorded_times_[std::size_t(frame.index)];
  if (t < 0) return std::nullopt;
  return recording_->tracked_camera_pose(t + offset);
}

std::optional<Pose> LiveLoop::camera_at(const capture::Frame& frame, Nanos t) const {
  // A recording played live has its frames restamped; its poses keep the recorded times.
  if (!driver_ && recording_) return recorded_pose(frame, t - frame.time);
  return pairing_.camera_at(t);
}

capture::PairedFrame LiveLoop::pair(capture::Frame frame) {
  if (!driver_ && recording_) {
    capture::PairedFrame out;
    out.T_world_camera = recorded_pose(frame);
    out.sensor.status = out.T_world_camera ? tracking::PoseStatus::Interpolated : tracking::PoseStatus::NoSamples;
    out.frame = std::move(frame);
    return out;
  }
  // Hold the frame briefly until the tracker has a sample past its time: then the pose
  // is interpolated, not extrapolated.
  if (driver_ && settings_.max_wait > 0) {
    const Nanos deadline = monotonic_now() + settings_.max_wait;
    for (;;) {
      take_samples();
      if (pairing_.covers(frame.time + settings_.shutter / 2) || monotonic_now() >= deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  const Nanos t = frame.time;
  capture::PairedFrame paired = pairing_.pair(std::move(frame));
  // Keep a long session's memory bounded: a second of samples behind the frames.
  if ((stats_.frames + 1) % 300 == 0) pairing_.forget_before(t - kNanosPerSecond);
  return paired;
}

void LiveLoop::count(const capture::PairedFrame& paired) {
  ++stats_.frames;
  if (!paired.T_world_camera) ++stats_.without_pose;
  if (paired.sensor.status == tracking::PoseStatus::Extrapolated) ++stats_.extrapolated;
}

void LiveLoop::run(const std::function<bool(capture::PairedFrame&)>& on_frame, const std::function<bool()>& on_idle) {
  catch_stop_signals();
  if (driver_) driver_->start();
  start_ = monotonic_now();
  capture_ = std::make_unique<capture::CaptureThread>(std::move(source_), queue_);
  // Whatever ends the loop (an exception from a callback included), the capture thread
  // and the tracker stop here.
  struct Stop {
    LiveLoop& loop;
    ~Stop() {
      loop.capture_->stop();
      if (loop.driver_) loop.driver_->stop();
      loop.stats_.queue = loop.queue_.stats();
    }
  } stop{*this};

  const Nanos end = settings_.duration > 0 ? start_ + settings_.duration : 0;
  bool asked_to_stop = false;
  for (;;) {
    if (stop_requested()) {
      stopped_by_signal_ = asked_to_stop = true;
      break;
    }
    if ((settings_.max_frames > 0 && stats_.frames >= std::uint64_t(settings_.max_frames)) ||
        (end > 0 && monotonic_now() >= end)) {
      asked_to_stop = true;
      break;
    }
    take_samples();
    report_tracker_state();
    if (on_idle && !on_idle()) {
      asked_to_stop = true;
      break;
    }
    capture::Frame frame;
    if (!queue_.pop(frame, kIdle)) {
      if (queue_.closed()) break;  // the source ended (or failed: check_source)
      continue;
    }
    capture::PairedFrame paired = pair(std::move(frame));
    count(paired);
    if (!on_frame(paired)) {
      asked_to_stop = true;
      break;
    }
  }
  capture_->stop();
  if (asked_to_stop && settings_.drain_on_stop) {
    // Frames still queued were captured: they belong with the others.
    capture::Frame frame;
    while (queue_.pop(frame, 0)) {
      capture::PairedFrame paired = pair(std::move(frame));
      count(paired);
      on_frame(paired);
    }
  }
  take_samples();
}

capture::CaptureEnd LiveLoop::source_end() const { return capture_ ? capture_->end() : capture::CaptureEnd::Running; }

std::string LiveLoop::source_message() const { return capture_ ? capture_->message() : std::string(); }

bool LiveLoop::source_input_error() const { return capture_ && capture_->input_error(); }

std::string LiveLoop::describe_source() const {
  return capture_ ? capture_->describe() : (source_ ? source_->describe() : std::string());
}

std::uint64_t LiveLoop::frames_read() const { return capture_ ? capture_->frames_read() : 0; }

void LiveLoop::check_source() const {
  if (!capture_) return;
  const auto end = capture_->end();
  if (end != capture::CaptureEnd::Vanished && end != capture::CaptureEnd::Failed) return;
  if (capture_->input_error()) throw InputError(capture_->message());
  throw RuntimeError(capture_->message());
}

}  // namespace lumar::pipeline
