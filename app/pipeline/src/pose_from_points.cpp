#include "pose_from_points.h"

#include <cmath>
#include <opencv2/calib3d.hpp>

#include "lumar/calib/board_pose.h"

namespace lumar::pipeline {

std::optional<PoseFromPoints> pose_from_points(const std::vector<cv::Point3f>& points,
                                               const std::vector<cv::Point2f>& seen, const Pose& guess,
                                               double threshold, int iterations, int min_inliers) {
  if (static_cast<int>(points.size()) < min_inliers) return std::nullopt;
  cv::Vec3d rvec, tvec;
  calib::pose_to_rvec_tvec(guess.inverse(), rvec, tvec);  // OpenCV's pose is T_camera_world
  PoseFromPoints out;
  const bool solved = cv::solvePnPRansac(points, seen, cv::Matx33d::eye(), cv::noArray(), rvec, tvec, true, iterations,
                                         float(threshold), 0.999, out.inliers, cv::SOLVEPNP_ITERATIVE);
  if (!solved || static_cast<int>(out.inliers.size()) < min_inliers) return std::nullopt;
  std::vector<cv::Point3f> in_points;
  std::vector<cv::Point2f> in_seen;
  for (int i : out.inliers) in_points.push_back(points[i]), in_seen.push_back(seen[i]);
  calib::pose_to_rvec_tvec(guess.inverse(), rvec, tvec);
  cv::solvePnPRefineLM(in_points, in_seen, cv::Matx33d::eye(), cv::noArray(), rvec, tvec);
  out.T_world_camera = calib::pose_from_rvec_tvec(rvec, tvec).inverse();
  if (!out.T_world_camera.is_finite()) return std::nullopt;
  std::vector<cv::Point2f> back;
  cv::projectPoints(in_points, rvec, tvec, cv::Matx33d::eye(), cv::noArray(), back);
  double sum = 0;
  for (std::size_t i = 0; i < back.size(); ++i) {
    const cv::Point2f d = back[i] - in_seen[i];
    sum += double(d.dot(d));
  }
  out.rms = std::sqrt(sum / back.size());
  return out;
}

}  // namespace lumar::pipeline
