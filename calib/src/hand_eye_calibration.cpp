#include "lumar/calib/hand_eye_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/board_pose.h"

namespace lumar::calib {

std::vector<int> spread_rotations(const std::vector<glm::dquat>& rotations, int count) {
  const int n = int(rotations.size());
  std::vector<int> picked;
  if (n == 0 || count <= 0) return picked;
  std::vector<double> nearest(std::size_t(n), std::numeric_limits<double>::infinity());
  int next = 0;
  while (int(picked.size()) < std::min(count, n)) {
    picked.push_back(next);
    int best = -1;
    double best_angle = -1;
    for (int i = 0; i < n; ++i) {
      nearest[std::size_t(i)] = std::min(nearest[std::size_t(i)],
                                         rotation_angle_deg(rotations[std::size_t(i)], rotations[std::size_t(next)]));
      if (nearest[std::size_t(i)] > best_angle) best_angle = nearest[std::size_t(i)], best = i;
    }
    if (best_angle <= 0) break;  // every remaining rotation repeats a picked one
    next = best;
  }
  return picked;
}

Pose mean_pose(const std::vector<Pose>& poses) {
  Pose mean;
  if (poses.empty()) return mean;
  glm::dquat sum(0, 0, 0, 0);
  glm::dvec3 t(0.0);
  const glm::dquat ref = poses.front().rotation;
  for (const auto& p : poses) {
    const glm::dquat q = glm::dot(p.rotation, ref) < 0 ? -p.rotation : p.rotation;
    sum = glm::dquat(sum.w + q.w, sum.x + q.x, sum.y + q.y, sum.z + q.z);
    t += p.translation;
  }
  mean.rotation = glm::normalize(sum);
  mean.translation = t / double(poses.size());
  return mean;
}

namespace {

cv::HandEyeCalibrationMethod to_cv(HandEyeMethod m) {
  switch (m) {
    case HandEyeMethod::Tsai:
      return cv::CALIB_HAND_EYE_TSAI;
    case HandEyeMethod::Park:
      return cv::CALIB_HAND_EYE_PARK;
    case HandEyeMethod::Horaud:
      return cv::CALIB_HAND_EYE_HORAUD;
    case HandEyeMethod::Andreff:
      return cv::CALIB_HAND_EYE_ANDREFF;
    case HandEyeMethod::Daniilidis:
      return cv::CALIB_HAND_EYE_DANIILIDIS;
  }
  return cv::CALIB_HAND_EYE_PARK;
}

}  // namespace

HandEyeSolution solve_hand_eye(const std::vector<Pose>& T_transmitter_sensor, const std::vector<Pose>& T_camera_board,
                               const HandEyeOptions& options) {
  if (T_transmitter_sensor.size() != T_camera_board.size())
    throw InputError("hand-eye calibration: tracker and board poses differ in number");
  if (T_transmitter_sensor.size() < 3)
    throw InputError("hand-eye calibration: need at least 3 views with both a tracker pose and the board");

  std::vector<glm::dquat> sensor_rotations;
  for (const auto& p : T_transmitter_sensor) sensor_rotations.push_back(p.rotation);
  HandEyeSolution out;
  out.views_used = spread_rotations(sensor_rotations, std::max(3, options.max_views));
  out.min_pair_rotation_deg = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < out.views_used.size(); ++a)
    for (std::size_t b = a + 1; b < out.views_used.size(); ++b)
      out.min_pair_rotation_deg =
          std::min(out.min_pair_rotation_deg, rotation_angle_deg(sensor_rotations[std::size_t(out.views_used[a])],
                                                                 sensor_rotations[std::size_t(out.views_used[b])]));

  std::vector<cv::Mat> R_gripper2base, t_gripper2base, R_target2cam, t_target2cam;
  for (int i : out.views_used) {
    const Pose& s = T_transmitter_sensor[std::size_t(i)];
    const Pose& c = T_camera_board[std::size_t(i)];
    R_gripper2base.push_back(cv::Mat(rotation_matx(s)).clone());
    t_gripper2base.push_back((cv::Mat_<double>(3, 1) << s.translation.x, s.translation.y, s.translation.z));
    R_target2cam.push_back(cv::Mat(rotation_matx(c)).clone());
    t_target2cam.push_back((cv::Mat_<double>(3, 1) << c.translation.x, c.translation.y, c.translation.z));
  }
  cv::Mat R, t;
  cv::calibrateHandEye(R_gripper2base, t_gripper2base, R_target2cam, t_target2cam, R, t, to_cv(options.method));
  if (R.empty() || !cv::checkRange(R) || !cv::checkRange(t))
    throw RuntimeError("hand-eye calibration: cv::calibrateHandEye found no solution; record more varied motion");
  out.T_sensor_camera = pose_from_rt(cv::Matx33d(R), cv::Vec3d(t.at<double>(0), t.at<double>(1), t.at<double>(2)));

  std::vector<Pose> boards;
  for (std::size_t i = 0; i < T_camera_board.size(); ++i)
    boards.push_back(T_transmitter_sensor[i] * out.T_sensor_camera * T_camera_board[i]);
  out.T_transmitter_board = mean_pose(boards);
  return out;
}

}  // namespace lumar::calib
