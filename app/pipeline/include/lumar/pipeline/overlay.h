#pragma once
// What the replay and the live overlay share, frame by frame: a GL context (a window or
// headless EGL), the compositor over the undistorted video, the video's radiometry
// (response, vignetting, exposure: how the camera turned radiance into codes), the
// lighting adaptation, and the time each stage took.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lumar/calib/camera_response.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/frame_source.h"
#include "lumar/capture/session.h"
#include "lumar/pipeline/live_lighting.h"
#include "lumar/pipeline/proxy_alignment.h"
#include "lumar/render/compositor.h"
#include "lumar/render/platform/context.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar::pipeline {

// The knobs that trade a frame's time for its accuracy (docs/results.md, "Quality
// knobs"); the defaults are full quality. `--quality auto` picks them per recording
// (quality_choice.h).
struct OverlayQuality {
  ObjectShading shading = ObjectShading::PerPixel;  // the volume's light per pixel or per vertex
  ShadowQuality shadows;                            // lines per receiver and emitter patch (docs/shadows.md)
  // The exact lights the irradiance volume evaluates with shadow maps, instead of the
  // manifest's lighting.irradiance.max_lights (0 to 16), and the texels per side of their
  // shadow maps, instead of its shadow_map_resolution (8 to 1024); the volume is built, or
  // taken from the cache, for them.
  std::optional<int> exact_lights, shadow_map;
  // The antialiasing's coverage from simplified meshes within this many output pixels of
  // the objects' own (gl::Renderer::set_coverage_mesh_error); 0: the meshes as given, the
  // full quality. At 0.5 px the edge's error against the truth grows by 0.15–0.35 point
  // and the walk's antialiasing costs 3 ms less a frame (docs/results.md); `auto` may
  // take 0.5, 1, 2 or 4 px.
  double coverage_mesh_px = 0.0;
  bool operator==(const OverlayQuality&) const = default;
  // "vertex, 4 lines, 6 lights, 64 px shadow maps, 1 px coverage meshes" (unset counts as
  // "manifest's").
  std::string describe() const;
};

struct OverlaySettings {
  calib::UndistortedCamera undistortion = calib::UndistortedCamera::SameMatrix;
  // > 0: every that many frames, compare the video with the map and follow the room's
  // light per direction and colour: re-baked, faded in (live_lighting.h).
  int adapt_lighting_every = 0;
  int adapt_lighting_cells = 32;  // the map's directions in that many columns (half as many rows)
  bool window = false;            // a GLFW window to draw into; else a headless EGL context
  std::string window_title = "lumar overlay";
  // > 0: room for panels right of the video (the interactive window), which is then at
  // least 720 pixels tall; else the window is the camera's size.
  int window_panel_width = 0;
  bool volume_cache = true;  // the irradiance volume from / into the disk cache
  // What makes the objects look like the camera's pixels; the camera's noise and blur
  // are estimated from the first frames of the video (calib/sensor_noise.h,
  // calib/camera_blur.h) unless blur_sigma_px >= 0 gives the blur.
  gl::CompositeFeatures features;
  double blur_sigma_px = -1.0;
  // Motion blur (features.motion_blur): how long the shutter was open, seconds, instead
  // of the session's radiometry.shutter_s (0: none), and at how many instants of it the
  // objects are drawn (kMinShutterInstants to kMaxShutterInstants; each costs one more
  // drawing of the objects).
  std::optional<double> shutter_s;
  int shutter_instants = 3;
  static constexpr int kMinShutterInstants = 2, kMaxShutterInstants = 16;
  OverlayQuality quality;
  // Animated objects (the manifest's paths) play in recording time; live, from the first
  // frame the overlay sees.
  bool live = false;
};

struct StageTimes {  // milliseconds, summed over frames
  double decode = 0, pose = 0, measure = 0, lighting = 0, shadows = 0, vertex_light = 0, upload = 0, background = 0,
         depth = 0, objects = 0, antialiasing = 0, motion_blur = 0, blur = 0, readback = 0, output = 0;
  // From a frame's start (replay: its decode; live: the middle of its exposure) to its
  // composite handed on, summed over frames.
  double latency = 0;
  int frames = 0;
  double total() const;  // every stage
  // Each stage's name ("decode video", ...) and its sum, in pipeline order.
  std::vector<std::pair<std::string, double>> stages() const;
};

struct OverlayFrame {
  std::int64_t index = 0;
  Nanos time = 0;
  cv::Mat video;                       // as recorded
  cv::Mat composite;                   // BGR8 output
  std::optional<Pose> T_world_camera;  // the pose used (nullopt: no pose, video only)
  double lighting_scale = 1.0;         // the room's overall brightness against the map, as measured (1: unchanged)
  bool lighting_settled = true;        // no re-bake or fade of the objects' lighting under way
};

class Overlay {
 public:
  // `camera`: the video's calibration; `radiometry` and `response` (nullopt: sRGB): how
  // the video was made.
  Overlay(std::shared_ptr<const LoadedScene> scene, const CameraIntrinsics& camera,
          const capture::Radiometry& radiometry, const std::optional<calib::CameraResponse>& response,
          const OverlaySettings& settings);
  ~Overlay();
  Overlay(const Overlay&) = delete;
  Overlay& operator=(const Overlay&) = delete;

  // Moves the animated objects to where their paths are at the frame's time, adapts the
  // lighting (with a pose, on every n-th call) and composites the frame.
  // `shutter_cameras`: the camera's pose at each of shutter_times(frame.time), for the
  // motion blur; without them, or with one missing, the frame has none.
  OverlayFrame composite(const capture::Frame& frame, const std::optional<Pose>& T_world_camera,
                         std::span<const std::optional<Pose>> shutter_cameras = {});
  // The instants of a frame's shutter at which the motion blur draws the objects, the
  // shutter centred on the frame's time; empty when the shutter time is 0 or the motion
  // blur is off.
  std::vector<Nanos> shutter_times(Nanos frame_time) const;
  // The camera at each of shutter_times(frame_time): the frame's `pose` (the tracker's,
  // or the tracker's fixed by the video) moved by the tracker's own motion from the
  // frame's time to each instant, `tracked_at(t)` being the tracker's camera at t; so a
  // correction by the video holds over the whole shutter. The frame's own time gets
  // `pose` bit for bit. Empty without a pose or without motion blur.
  std::vector<std::optional<Pose>> shutter_cameras(Nanos frame_time, const std::optional<Pose>& pose,
                                                   const std::function<std::optional<Pose>(Nanos)>& tracked_at) const;
  double shutter_s() const { return shutter_s_; }
  // Only the first step of composite(): the animated objects where their paths are then.
  void play_paths(Nanos frame_time);

  // composite() in two halves for a pipelined replay: prepare() moves the animated
  // objects and works out their shadows and light (Compositor::prepare: no GL, so on
  // another thread, a frame or two ahead), render() draws the frame with them on the
  // thread that holds the GL context. Only while can_prepare_ahead(): the lighting
  // adaptation changes the light between frames on the GL thread.
  bool can_prepare_ahead() const { return !live_lighting_; }
  FrameLight prepare(Nanos frame_time);
  OverlayFrame render(const capture::Frame& frame, const std::optional<Pose>& T_world_camera, const FrameLight& light,
                      std::span<const std::optional<Pose>> shutter_cameras = {});

  // Swaps in another scene (objects added or removed, another lighting method): a new
  // compositor with this one's features, quality and measured camera; the irradiance
  // volume comes from the cache when its inputs are unchanged.
  void set_scene(std::shared_ptr<const LoadedScene> scene);
  // Another exact-light count or shadow-map size makes a new compositor (as set_scene);
  // the other knobs are the compositor's own. InputError for a count out of range.
  void set_quality(const OverlayQuality& quality);
  // The knobs now (the window's panel may change the shadow lines on the compositor).
  OverlayQuality quality() const;
  // > 0: every that many frames, compare the video with the map and follow the room's
  // lighting (OverlaySettings::adapt_lighting_every); 0: off, back to the map's light.
  void set_adapt_lighting_every(int every_n_frames);
  // Scales the objects' brightness against the video's (1: the session's exposure).
  void set_exposure_scale(double scale) {
    exposure_scale_ = scale;
    frames_since_clip_check_ = kClipCheckEvery;  // measure the clipping again on the next frame
  }
  double exposure_scale() const { return exposure_scale_; }

  Compositor& compositor() { return *compositor_; }
  // The room's radiance from a pose as this overlay's renderer has it, on the thread that
  // composites (image-aided tracking's absolute fixes); it follows set_scene.
  RoomPrediction room_prediction() {
    return [this](const CameraIntrinsics& camera, const Pose& T_world_camera) {
      return compositor_->renderer().render_room_radiance(camera, T_world_camera);
    };
  }
  const LoadedScene& scene() const { return compositor_->scene(); }
  gl::WindowContext* window() { return window_; }
  StageTimes& times() { return times_; }  // composite() fills the rendering stages; callers the rest
  // Clears the stage times (after frames that were not the run's); the first composite's
  // time becomes `first_composite` (a live run's first frame came before a choice of quality).
  void reset_times(std::optional<std::chrono::steady_clock::time_point> first_composite = std::nullopt) {
    times_ = {};
    first_composite_ = first_composite;
  }
  // When the first frame's composite was ready (steady clock); nullopt before it.
  std::optional<std::chrono::steady_clock::time_point> first_composite_time() const { return first_composite_; }
  const StageTimes& times() const { return times_; }
  int frames_without_pose() const { return frames_without_pose_; }
  // The share of the objects' pixels that clip to white (in luma), measured on the
  // first frame with a pose and every kClipCheckEvery frames after it (nullopt before).
  // Over kClipWarnShare a warning says so, once: the objects are brighter than the camera
  // records at this exposure (under a sun, say); whether a real object would clip too, a
  // truth frame tells (docs/ground_truth.md).
  static constexpr int kClipCheckEvery = 30;
  static constexpr double kClipWarnShare = 0.05;
  std::optional<double> objects_clipped() const { return objects_clipped_; }
  const LiveLighting* live_lighting() const { return live_lighting_ ? &*live_lighting_ : nullptr; }
  // How the video's codes map to linear light, and to the composite's geometry.
  const calib::CameraResponse& response() const { return response_; }
  const calib::UndistortionMaps& undistortion() const { return maps_; }
  // The video's radiometry as the renderer has it now (noise and blur once measured).
  const gl::VideoRadiometry& video_radiometry() const { return radiometry_; }

 private:
  std::unique_ptr<gl::Context> context_;
  gl::WindowContext* window_ = nullptr;
  std::unique_ptr<Compositor> compositor_;
  double exposure_ = 1.0, exposure_scale_ = 1.0;
  CameraIntrinsics camera_;  // the video's, distorted
  capture::Radiometry session_radiometry_;
  std::optional<LiveLighting> live_lighting_;
  int lighting_every_ = 0, lighting_cells_ = 32;
  // The camera's noise and blur, measured from the video until they are known.
  void measure_camera(const cv::Mat& video);
  calib::UndistortionMaps maps_;
  double resampling_variance_ = 0;  // of the undistortion, px² per axis (calib::resampling_variance)
  calib::CameraResponse response_;
  gl::VideoRadiometry radiometry_;
  bool noise_known_ = false, blur_known_ = false, warned_ = false;
  std::int64_t frames_seen_ = 0;
  bool live_ = false, volume_cache_ = true;
  OverlayQuality quality_;
  std::shared_ptr<const LoadedScene> scene_;  // as given, before the quality's volume knobs
  std::optional<Nanos> first_frame_time_;
  StageTimes times_;
  std::optional<std::chrono::steady_clock::time_point> first_composite_;
  int frames_without_pose_ = 0;
  std::optional<double> objects_clipped_;
  int frames_since_clip_check_ = kClipCheckEvery;
  bool clip_warned_ = false;
  void measure_clipping(const cv::Mat& composite, const Pose& T_world_camera);
  // Where the paths put the animated objects at frame_time: on the compositor and its
  // renderer, or (prepare) on the compositor's CPU side alone.
  void move_along_paths(Nanos frame_time, bool renderer_too);
  double path_seconds(Nanos frame_time) const;  // where the paths are at a frame's time
  double shutter_s_ = 0.0;
  int shutter_instants_ = 3;
  // composite()'s and render()'s common start (the frame's fields, the camera measured)
  // and end (the objects drawn, the times kept).
  OverlayFrame begin(const capture::Frame& frame, const std::optional<Pose>& T_world_camera);
  void draw(OverlayFrame& out, const capture::Frame& frame, const FrameLight& light,
            std::span<const std::optional<Pose>> shutter_cameras);
};

// One line per stage: mean milliseconds per frame and share of the total.
std::string format_stage_times(const StageTimes& t);
// The run's figures as JSON (docs/formats.md, "Overlay stats"): frames, fps (frames over
// `wall_seconds`), latency_ms_mean, startup_ms (from the command's start to its first
// composite; negative: none, written as null), quality (the knobs, OverlayQuality::describe;
// empty: null) and stages (name -> mean ms per frame).
std::string stage_times_json(const StageTimes& t, double wall_seconds, double startup_ms = -1,
                             const std::string& quality = "");

}  // namespace lumar::pipeline
