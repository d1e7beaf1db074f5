#pragma once
// The camera's absolute pose from one frame: the frame against the room as the proxy and
// the environment map predict it (both made by this camera). The room's radiance is
// rendered from a guessed pose; corners of that prediction are found in the undistorted
// frame by normalised cross-correlation (which the camera's response, vignetting and
// exposure do not upset: locally they are a gain and an offset); each carries the 3-D
// point of the proxy it shows; PnP with RANSAC gives the pose. What the proxy lacks (a
// table, a wall a few centimetres off) becomes outliers or a bias of its own size, so
// image-aided tracking uses this to start from and to bound drift, weighed against the
// tracker rather than trusted outright.
#include <functional>
#include <opencv2/core.hpp>
#include <optional>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/calib/undistortion.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar::pipeline {

// The room's linear radiance (CV_32FC3 BGR, the pinhole camera's size) seen from a pose:
// gl::Renderer::render_room_radiance.
using RoomPrediction = std::function<cv::Mat(const CameraIntrinsics& pinhole, const Pose& T_world_camera)>;

struct ProxyAlignmentSettings {
  int max_corners = 200;
  int patch_px = 15;       // side of the correlated patch
  int search_px = 24;      // how far from where the guess puts it a corner is looked for
  double min_score = 0.9;  // normalised cross-correlation of a match
  int min_inliers = 40;    // fewer: no pose
  double ransac_px = 1.0;  // PnP inlier threshold
};

class ProxyAlignment {
 public:
  // `camera`: the video's intrinsics, with its distortion; `proxy`: the room (world
  // metres), kept by reference; `predict`: the room's radiance from a pose.
  ProxyAlignment(const CameraIntrinsics& camera, const RayScene& proxy, RoomPrediction predict,
                 const ProxyAlignmentSettings& settings = {});

  struct Result {
    Pose T_world_camera;
    int matches = 0, inliers = 0;
    double rms_px = 0;  // the inliers' reprojection error
  };
  // The pose that puts the prediction's corners where `frame` (the video's BGR image)
  // shows them, starting from `guess`; nothing when too few corners match.
  std::optional<Result> align(const cv::Mat& frame, const Pose& guess) const;

 private:
  CameraIntrinsics pinhole_;
  const RayScene& proxy_;
  RoomPrediction predict_;
  ProxyAlignmentSettings settings_;
  calib::UndistortionMaps undistort_;
};

}  // namespace lumar::pipeline
