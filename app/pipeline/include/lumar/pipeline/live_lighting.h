#pragma once
// Keeps the map's lighting current while the overlay runs (issue: "keeping the map
// current"): every few frames, the undistorted, linearised video is compared with what
// the map predicts for the same view (the proxy room textured from the map's capture
// point), and the virtual objects' lighting is scaled by the smoothed global ratio.
#include <opencv2/core.hpp>
#include <optional>

#include "lumar/base/pose.h"
#include "lumar/calib/camera_response.h"
#include "lumar/calib/lighting_adapter.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/session.h"
#include "lumar/render/renderer.h"

namespace lumar::pipeline {

class LiveLighting {
 public:
  // `video_camera` and `maps`: the distorted camera and the overlay's undistortion;
  // `response` (relative linear value per code) and `radiometry`: how the video was made.
  LiveLighting(const CameraIntrinsics& video_camera, const calib::UndistortionMaps& maps,
               const calib::CameraResponse& response, const capture::Radiometry& radiometry, int every_n_frames);

  // Measures on every n-th call (with a pose); `renderer` draws the prediction and the
  // object mask (pixels of virtual objects are not room). Returns the lighting scale.
  double update(gl::Renderer& renderer, const cv::Mat& video_bgr8, const Pose& T_world_camera, Nanos time);
  double scale() const { return adapter_.global_ratio(); }
  int measurements() const { return measurements_; }

 private:
  cv::Mat map_x_, map_y_;
  CameraIntrinsics small_camera_;  // the comparison runs at a quarter of the resolution
  cv::Mat inverse_gain_;           // 1 / vignetting in the distorted image
  calib::CameraResponse response_;
  double exposure_;
  int every_, calls_ = 0, measurements_ = 0;
  calib::LightingAdapter adapter_;
};

}  // namespace lumar::pipeline
