#pragma once
// The overlay over a recording, shared by `lumar overlay`, `lumar regress` and the
// benchmarks: recording -> frames and camera poses (the tracker stream through the real
// parser and the pose filter, that stream steadied by the video, or the recording's
// truth) -> Overlay -> output frames.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/image_aided_pose.h"
#include "lumar/pipeline/overlay.h"
#include "lumar/pipeline/quality_choice.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/tracking/one_euro_filter.h"

namespace lumar::pipeline {

// Tracker: the tracker stream alone. Fused: the tracker's poses steadied by the video
// (image_aided_pose.h). Truth: the recording's ground truth.
enum class PoseSource { Tracker, Fused, Truth };

struct ReplayOverlaySettings {
  std::filesystem::path scene;  // empty: the one the recording's session names
  PoseSource poses = PoseSource::Tracker;
  std::optional<tracking::PoseFilterSettings> filter;  // on the tracker's samples (not on the truth)
  ImageAidedSettings image_aided;                      // for PoseSource::Fused
  OverlaySettings overlay;
  // Set: the quality knobs chosen on the recording's own frames before the run, from
  // overlay.quality as full quality (quality_choice.h).
  std::optional<QualityBudget> auto_quality;
  // Replay a recording whose writer never closed it (killed, crashed, disk full): its
  // closed segments are whole, but it may end early. Refused by default.
  bool allow_incomplete = false;
};

class ReplayOverlay {
 public:
  // InputError naming the file when the recording, its session or the scene is unusable.
  ReplayOverlay(const std::filesystem::path& recording, const ReplayOverlaySettings& settings = {});

  // Runs every frame (up to max_frames, 0 = all) through the overlay; `sink` sees each
  // result and returns false to stop early (e.g. the window was closed).
  // Pipelined: decoding, then the pose and the composite (this thread, which holds the GL
  // context), then the sink each run on their own thread, handing frames on through
  // queues kPipelineDepth deep, so the throughput is the slowest stage's. The sink then
  // runs off this thread and must not touch the overlay; it still sees the frames in
  // order, and a false from it stops the run within kPipelineDepth frames. Serial: one
  // stage after another on this thread (the baseline, and what a window needs).
  static constexpr int kPipelineDepth = 1;
  void run(int max_frames, const std::function<bool(const OverlayFrame&)>& sink, bool pipelined = false);

  // The camera's pose for a frame of this recording, from the settings' source (nullopt:
  // the tracker has nothing for it). Fused poses want the frames in order; any other
  // frame starts the fusion again from the tracker.
  std::optional<Pose> camera_pose(const capture::Frame& frame);
  // The camera at each instant of the frame's shutter (Overlay::shutter_times; empty
  // without motion blur or without `pose`, the frame's camera_pose): the truth
  // interpolated between its frames, or the tracker's motion from the frame's time to the
  // instant's applied to `pose`.
  std::vector<std::optional<Pose>> shutter_cameras(const capture::Frame& frame, const std::optional<Pose>& pose) const;
  PoseSource pose_source() const { return pose_source_; }
  // Truth: InputError when the recording has none. Fused without a proxy room in the
  // scene: the tracker's, with a warning.
  void set_pose_source(PoseSource source);

  // Decodes the tracker stream again through this filter (nullopt: none). Frame sources
  // opened from replay() before are stale afterwards: open them again.
  void set_pose_filter(const std::optional<tracking::PoseFilterSettings>& filter);

  // `count` frames spread evenly over the recording (each the first at or after its place
  // that has a camera pose), for choose_quality.
  std::vector<ProbeFrame> probe_frames(int count);
  // Chooses the quality knobs on probe_frames(budget.frames + 1), from the overlay's
  // current quality as full quality (quality_choice.h), and leaves the overlay at the
  // choice; the fusion of poses starts again. What settings.auto_quality asks for before
  // the run; the window's "Choose" asks for it again after edits.
  const QualityChoice& choose_quality(const QualityBudget& budget);
  // The last choice (nullopt: none asked for).
  const std::optional<QualityChoice>& quality_choice() const { return quality_choice_; }

  const capture::RecordingReplay& replay() const { return replay_; }
  Overlay& overlay() { return *overlay_; }
  const LoadedScene& scene() const { return overlay_->scene(); }
  Compositor& compositor() { return overlay_->compositor(); }
  gl::WindowContext* window() { return overlay_->window(); }
  const StageTimes& times() const { return overlay_->times(); }
  int frames_without_pose() const { return overlay_->frames_without_pose(); }
  const LiveLighting* live_lighting() const { return overlay_->live_lighting(); }

 private:
  void run_pipelined(int max_frames, const std::function<bool(const OverlayFrame&)>& sink);
  std::filesystem::path recording_;
  capture::RecordingReplay replay_;
  PoseSource pose_source_;
  std::unique_ptr<Overlay> overlay_;
  ImageAidedSettings image_aided_;
  std::unique_ptr<ImageAidedPose> fused_;  // while the source is Fused
  std::optional<QualityChoice> quality_choice_;
};

}  // namespace lumar::pipeline
