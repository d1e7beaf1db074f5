#pragma once
// The camera's pose from 3-D points and where they are seen, near a guess: what
// image-aided tracking (frame to frame) and proxy alignment (absolute fixes) share.
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "lumar/base/pose.h"

namespace lumar::pipeline {

struct PoseFromPoints {
  Pose T_world_camera;
  std::vector<int> inliers;  // indices into the points
  double rms = 0;            // the inliers' reprojection error, normalised image units
};

// `seen`: on the normalised image plane (distortion removed). RANSAC (`threshold` in
// normalised units, `iterations` draws, started from the guess) only picks the inliers:
// its pose may be the mirror image that puts the points behind the camera, which
// reprojection cannot tell apart, so the pose is refined on the inliers (Levenberg-
// Marquardt) from the guess, which is near the answer. Nothing when fewer than
// `min_inliers` agree or the result is not finite.
std::optional<PoseFromPoints> pose_from_points(const std::vector<cv::Point3f>& points,
                                               const std::vector<cv::Point2f>& seen, const Pose& guess,
                                               double threshold, int iterations, int min_inliers);

}  // namespace lumar::pipeline
