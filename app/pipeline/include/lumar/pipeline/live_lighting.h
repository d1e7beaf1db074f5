#pragma once
// Keeps the objects' lighting current while the overlay runs, live or on replay
// (docs/envmap.md, "Keeping the map current"). Every few frames the undistorted,
// linearised video is compared with what the captured map predicts for the same view
// (the proxy room textured from the map's capture point), cell by cell of the map's
// directions and per colour (calib/lighting_adapter.h). When a cell's published ratio
// moves, the map times the ratios is re-baked into an irradiance volume in the
// background (relit_scene_lighting: the same layout as the scene's volume), and the
// objects' lighting fades from the old volume to the new over `fade_s` of frame time,
// so nothing pops. Live, the bake runs on its own thread and is swapped in when done;
// on replay it runs at once, so that a replay's frames do not depend on the machine.
#include <future>
#include <memory>
#include <opencv2/core.hpp>

#include "lumar/base/pose.h"
#include "lumar/calib/camera_response.h"
#include "lumar/calib/lighting_adapter.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/session.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/render/compositor.h"

namespace lumar::pipeline {

struct LiveLightingSettings {
  int every_n_frames = 1;  // compare on every n-th frame with a pose
  int cell_cols = 32;      // cells over the map's directions (the knob), cell_cols / 2 rows
  double fade_s = 0.5;     // from the old lighting to the re-baked one, frame time
  bool background = true;  // bake on a thread (live); false: at once (replay)
};

class LiveLighting {
 public:
  // `video_camera` and `maps`: the distorted camera and the overlay's undistortion;
  // `response` (relative linear value per code) and `radiometry`: how the video was made.
  LiveLighting(const CameraIntrinsics& video_camera, const calib::UndistortionMaps& maps,
               const calib::CameraResponse& response, const capture::Radiometry& radiometry,
               const LiveLightingSettings& settings);
  ~LiveLighting();
  LiveLighting(const LiveLighting&) = delete;
  LiveLighting& operator=(const LiveLighting&) = delete;

  // One frame: measures on every n-th call, starts a bake when the measured light moved,
  // and steps the fade, handing the compositor its lighting for this frame.
  void update(Compositor& compositor, const cv::Mat& video_bgr8, const Pose& T_world_camera, Nanos time);
  // Hands the compositor the scene's own lighting again (adaptation switched off).
  void restore(Compositor& compositor) const;

  // The room's overall brightness against the map (1: as captured), for reports.
  double scale() const { return adapter_.global_ratio(); }
  const calib::LightingAdapter& adapter() const { return adapter_; }
  int measurements() const { return measurements_; }
  int bakes() const { return bakes_; }  // re-baked lightings swapped in
  double last_bake_ms() const { return bake_ms_; }
  // The longest a frame spent handing the compositor a faded lighting (blend, upload,
  // shadow lines relit): what a change costs the frames that show it.
  double worst_fade_step_ms() const { return worst_fade_step_ms_; }
  bool transition() const { return fading_ || pending_.valid(); }  // a bake or a fade under way

 private:
  struct Baked {
    SceneLighting lighting;
    double ms = 0;
  };
  Baked bake(const std::shared_ptr<const LoadedScene>& scene, const cv::Mat& ratios_bgr);
  void start_fade(Baked baked, Nanos time);

  LiveLightingSettings settings_;
  cv::Mat map_x_, map_y_;
  CameraIntrinsics small_camera_;  // the comparison runs at a quarter of the resolution
  cv::Mat inverse_gain_;           // 1 / vignetting in the distorted image
  calib::CameraResponse response_;
  double exposure_;
  int calls_ = 0, measurements_ = 0, bakes_ = 0;
  double bake_ms_ = 0, worst_fade_step_ms_ = 0;
  calib::LightingAdapter adapter_;

  std::shared_ptr<const LoadedScene> scene_;  // the compositor's, while this lighting is its
  std::unique_ptr<RoomRadiance> base_;        // the scene's radiance, made by the first bake
  SceneLighting original_, from_, to_;
  std::uint64_t baked_version_ = 0;
  std::future<Baked> pending_;
  bool fading_ = false;
  Nanos fade_start_ = 0;
};

}  // namespace lumar::pipeline
