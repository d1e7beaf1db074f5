#pragma once
// The one live loop behind `lumar record`, `lumar overlay --source` and `lumar envmap
// --source`. A capture thread fills a frame queue; the loop takes the tracker's samples
// as they come (through the pose filter, if any), holds each frame briefly until the
// tracker has a sample past its time (so that its pose is interpolated, not
// extrapolated), pairs it with the camera pose through the rig and hands it on. It ends
// when the source ends, on SIGINT / SIGTERM, after max_frames or duration, or when the
// caller says so. It tells once when the tracker is lost and once when it is back.
//
// A `recording:DIR` source without a tracker brings its own poses: each frame is paired
// with the recording's tracker stream at the time it was recorded.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "lumar/base/time.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/frame_pose_pairing.h"
#include "lumar/capture/frame_queue.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/tracking/one_euro_filter.h"
#include "lumar/tracking/rig.h"
#include "lumar/tracking/tracker_driver.h"

namespace lumar::pipeline {

struct LiveLoopSettings {
  // A display wants the newest frame (KeepNewest, a short queue); a recording every
  // frame (KeepAll, seconds of slack for a slow disk).
  capture::QueuePolicy policy = capture::QueuePolicy::KeepNewest;
  std::size_t queue_frames = 1;
  Nanos max_wait = 40'000'000;                         // longest a frame waits for the tracker to cover its time
  Nanos shutter = 0;  // motion blur: ... to cover its shutter's end, half this past its time
  int max_frames = 0;                                  // stop after this many frames (0: no limit)
  Nanos duration = 0;                                  // stop this long after the start (0: no limit)
  bool drain_on_stop = false;                          // when stopped, frames already captured are handed on too
  std::optional<tracking::PoseFilterSettings> filter;  // on the tracker's samples, as they arrive
  std::string what = "live";                           // for messages: "record", "overlay", "envmap"
};

struct LiveLoopStats {
  std::uint64_t frames = 0;        // handed on
  std::uint64_t without_pose = 0;  // of those, without a pose
  std::uint64_t extrapolated = 0;  // of those, with a pose past the tracker's newest sample
  std::uint64_t samples = 0;       // tracker samples taken
  Nanos last_sample = 0;           // CLOCK_MONOTONIC when the newest sample was taken (0: none)
  capture::QueueStats queue;
};

class LiveLoop {
 public:
  // Called with every batch of tracker samples as taken from the driver (before the
  // filter), e.g. to record them.
  using SampleObserver = std::function<void(const std::vector<tracking::PoseSample>&)>;

  // `driver` may be null: no tracker (frames without poses, or a recording's own poses).
  // Nothing starts before run() or wait_for_tracker().
  LiveLoop(std::unique_ptr<capture::FrameSource> source, std::unique_ptr<tracking::TrackerDriver> driver,
           tracking::Rig rig, LiveLoopSettings settings);
  ~LiveLoop();  // stops the tracker and the capture thread
  LiveLoop(const LiveLoop&) = delete;
  LiveLoop& operator=(const LiveLoop&) = delete;

  // The poses of a `recording:` source played without a tracker.
  void use_recorded_poses(std::shared_ptr<const capture::RecordingReplay> recording);
  void on_samples(SampleObserver observer) { observer_ = std::move(observer); }

  // The camera at time t, near a frame's time (another instant of its shutter), from
  // the same poses the frame was paired with: the tracker's, or the recording's.
  std::optional<Pose> camera_at(const capture::Frame& frame, Nanos t) const;

  // Starts the tracker and waits until its first pose arrives, so that no frame is
  // captured before poses flow. InputError naming the tracker after `timeout`.
  void wait_for_tracker(Nanos timeout, const std::string& tracker_name);

  // Starts the tracker and the capture thread and calls on_frame for each frame, in
  // order, until the loop ends (see above) or a callback returns false. on_idle runs
  // at least every 50 ms, frames or not (events, periodic writes, progress). Whatever
  // ends it, the capture thread and the tracker are stopped when run() returns or throws.
  void run(const std::function<bool(capture::PairedFrame&)>& on_frame, const std::function<bool()>& on_idle = {});

  // After run(): InputError / RuntimeError with the source's one line when it vanished
  // or failed; nothing when it ended or was stopped.
  void check_source() const;
  capture::CaptureEnd source_end() const;
  std::string source_message() const;
  bool source_input_error() const;  // it failed on bad input (a corrupt file), not a device fault
  bool stopped_by_signal() const { return stopped_by_signal_; }

  const LiveLoopStats& stats() const { return stats_; }
  capture::QueueStats queue_stats() const { return queue_.stats(); }
  std::size_t frames_waiting() const { return queue_.size(); }
  Nanos start_time() const { return start_; }  // CLOCK_MONOTONIC when the capture started
  std::string describe_source() const;
  std::uint64_t frames_read() const;
  tracking::TrackerDriver* driver() const { return driver_.get(); }

 private:
  void take_samples();
  void report_tracker_state();
  // At the recorded time of the frame + offset.
  std::optional<Pose> recorded_pose(const capture::Frame& frame, Nanos offset = 0) const;
  capture::PairedFrame pair(capture::Frame frame);
  void count(const capture::PairedFrame& paired);

  std::unique_ptr<capture::FrameSource> source_;
  std::unique_ptr<tracking::TrackerDriver> driver_;
  LiveLoopSettings settings_;
  capture::FramePosePairing pairing_;
  std::optional<tracking::PoseSampleFilter> filter_;
  std::shared_ptr<const capture::RecordingReplay> recording_;
  std::vector<Nanos> recorded_times_;  // by frame index, for recorded poses
  SampleObserver observer_;
  std::vector<tracking::PoseSample> batch_;
  capture::FrameQueue queue_;
  std::unique_ptr<capture::CaptureThread> capture_;
  LiveLoopStats stats_;
  Nanos start_ = 0;
  bool tracker_ok_ = false, was_connected_ = false;
  bool stopped_by_signal_ = false;
};

}  // namespace lumar::pipeline
