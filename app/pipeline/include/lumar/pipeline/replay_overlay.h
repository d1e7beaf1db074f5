#pragma once
// The overlay path over a recording, shared by `lumar overlay`, `lumar regress` and the
// benchmarks: recording -> frames and tracked poses -> compositor -> output frames.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "lumar/calib/undistortion.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/live_lighting.h"
#include "lumar/render/compositor.h"
#include "lumar/render/platform/context.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar::pipeline {

enum class PoseSource { Tracker, Truth };

struct StageTimes {  // milliseconds, summed over frames
  double decode = 0, pose = 0, lighting = 0, upload = 0, background = 0, depth = 0, objects = 0, readback = 0,
         output = 0;
  int frames = 0;
};

struct OverlayFrame {
  std::int64_t index = 0;
  Nanos time = 0;
  cv::Mat video;                       // as recorded
  cv::Mat composite;                   // BGR8 output
  std::optional<Pose> T_world_camera;  // the pose used (nullopt: no pose, video only)
  double lighting_scale = 1.0;         // the map's light as the room measured now (1: unchanged)
};

class ReplayOverlay {
 public:
  // `window`: a GLFW window to draw into; otherwise a headless EGL context is made.
  // `undistortion`: which undistorted camera the output uses (calib/undistortion.h).
  // `adapt_lighting_every` > 0: compare the video with the map every that many frames and
  // scale the objects' lighting as the room gets brighter or darker (live_lighting.h).
  ReplayOverlay(const std::filesystem::path& recording, const std::filesystem::path& scene_override, PoseSource poses,
                bool window, calib::UndistortedCamera undistortion = calib::UndistortedCamera::SameMatrix,
                int adapt_lighting_every = 0);
  ~ReplayOverlay();

  // Runs every frame (up to max_frames, 0 = all) through the compositor; `sink` sees each
  // result and returns false to stop early (e.g. the window was closed).
  void run(int max_frames, const std::function<bool(const OverlayFrame&)>& sink);

  const capture::RecordingReplay& replay() const { return replay_; }
  const LoadedScene& scene() const { return *scene_; }
  Compositor& compositor() { return *compositor_; }
  gl::WindowContext* window() { return window_; }
  const StageTimes& times() const { return times_; }
  int frames_without_pose() const { return frames_without_pose_; }
  const LiveLighting* live_lighting() const { return live_lighting_ ? &*live_lighting_ : nullptr; }

 private:
  capture::RecordingReplay replay_;
  std::shared_ptr<const LoadedScene> scene_;
  PoseSource pose_source_;
  std::unique_ptr<gl::Context> context_;
  gl::WindowContext* window_ = nullptr;
  std::unique_ptr<Compositor> compositor_;
  StageTimes times_;
  int frames_without_pose_ = 0;
  std::optional<LiveLighting> live_lighting_;
};

// One line per stage: mean milliseconds per frame and share of the total.
std::string format_stage_times(const StageTimes& t);

}  // namespace lumar::pipeline
