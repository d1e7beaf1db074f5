#pragma once
// Refines the tracker's camera rotations of a sweep so that overlapping frames agree:
// ORB features on exposure-independent (log-luminance) images, matched between frames
// whose tracked optical axes are close, gated by the tracker's prediction, then a
// rotation-only bundle adjustment (Gauss-Newton on SO(3), robust Huber weights) with a
// weak prior pulling each frame towards its tracker rotation. The gauge (the sweep's
// overall rotation, which the images cannot see) is fixed to the mean of the tracker
// rotations, so the map stays registered to the room.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/calib/camera_response.h"

namespace lumar::calib {

struct FrameFeatures {
  std::vector<glm::dvec3> bearings;  // unit camera-frame rays (OpenCV axes) of the keypoints
  cv::Mat descriptors;               // ORB, one CV_8U row per keypoint
};

struct FeatureSettings {
  int max_features = 1200;
  int saturated_value = 250;  // keypoints near clipped pixels are dropped...
  int dark_value = 6;         // ...and near pixels too dark to carry texture
};

// Keypoints of one frame (CV_8UC3 BGR, the camera's size; else InputError). The
// response turns values into linear light so that frames of different exposure give
// alike descriptors.
FrameFeatures extract_frame_features(const cv::Mat& image_bgr8, const CameraIntrinsics& camera,
                                     const CameraResponse& response, const FeatureSettings& settings = {});

struct RefinementSettings {
  double tracker_noise_deg = 0.75;  // RMS of the tracker's rotation error (the prior)
  double match_noise_deg = 0.05;    // RMS disagreement of a good match's two rays
  double pair_max_angle_deg = 50;   // frames whose tracked axes are further apart are not matched
  double gate_deg = 4.0;            // matches further off the tracker's prediction are rejected
  double inlier_deg = 0.35;         // after a pair's relative rotation is fitted
  double ratio = 0.85;              // Lowe's ratio test on descriptor distances
  int min_matches = 15;             // per pair
  int iterations = 8;
};

struct RefinementResult {
  std::vector<glm::dquat> rotations;   // refined R_world_camera, one per frame
  std::vector<double> correction_deg;  // angle from the tracker's rotation to the refined one
  int pairs = 0;                       // frame pairs that contributed
  int matches = 0;                     // inlier matches over all pairs
  int unmatched_frames = 0;            // frames whose group found no good pair (left at the tracker's)
  double residual_before_deg = 0;      // RMS ray disagreement of the inliers, tracker rotations
  double residual_after_deg = 0;       // the same, refined rotations
};

// `tracker_rotations` are R_world_camera from the tracker, one per frame, in the same
// order as `features`. Frames with equal `groups` entries (a bracket of exposures taken
// standing still) share one rotation, which every frame's tracker reading informs and
// every frame's features constrain, so a bracket's dark frames (few features) end as
// well placed as its bright ones; empty = every frame on its own. Throws InputError
// when the sizes differ.
RefinementResult refine_orientations(const std::vector<FrameFeatures>& features,
                                     const std::vector<glm::dquat>& tracker_rotations,
                                     const RefinementSettings& settings = {}, const std::vector<int>& groups = {});

}  // namespace lumar::calib
