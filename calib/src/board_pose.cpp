#include "lumar/calib/board_pose.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/calib/checkerboard_calibration.h"

namespace lumar::calib {

cv::Matx33d rotation_matx(const Pose& pose) {
  const glm::dmat3 m = pose.rotation_matrix();  // column-major: m[col][row]
  cv::Matx33d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = m[c][r];
  return R;
}

Pose pose_from_rt(const cv::Matx33d& R, const cv::Vec3d& t) {
  // Project onto the nearest rotation so that quat_cast sees an orthonormal matrix.
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(R), w, u, vt);
  cv::Mat Rn = u * vt;
  if (cv::determinant(Rn) < 0) {
    u.col(2) *= -1;
    Rn = u * vt;
  }
  glm::dmat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[c][r] = Rn.at<double>(r, c);
  Pose p;
  p.rotation = glm::normalize(glm::quat_cast(m));
  p.translation = {t[0], t[1], t[2]};
  return p;
}

Pose pose_from_rvec_tvec(const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  return pose_from_rt(R, tvec);
}

void pose_to_rvec_tvec(const Pose& pose, cv::Vec3d& rvec, cv::Vec3d& tvec) {
  cv::Rodrigues(rotation_matx(pose), rvec);
  tvec = {pose.translation.x, pose.translation.y, pose.translation.z};
}

BoardPose solve_board_pose(const std::vector<cv::Point2f>& corners, cv::Size inner_corners, double square_size_m,
                           const CameraIntrinsics& camera) {
  const std::vector<cv::Point3f> board = checkerboard_points(inner_corners, square_size_m);
  cv::Vec3d rvec, tvec;
  const cv::Mat K(camera.camera_matrix()), D = camera.distortion_coefficients();
  cv::solvePnP(board, corners, K, D, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE);
  std::vector<cv::Point2f> projected;
  cv::projectPoints(board, rvec, tvec, K, D, projected);
  double sum = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const cv::Point2f e = projected[i] - corners[i];
    sum += double(e.x) * e.x + double(e.y) * e.y;
  }
  BoardPose out;
  out.T_camera_board = pose_from_rvec_tvec(rvec, tvec);
  out.reprojection_rms_px = std::sqrt(sum / double(std::max<std::size_t>(1, corners.size())));
  out.corners = corners;
  return out;
}

std::optional<BoardPose> find_board_pose(const cv::Mat& image, cv::Size inner_corners, double square_size_m,
                                         const CameraIntrinsics& camera, bool thorough) {
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else
    gray = image;
  std::vector<cv::Point2f> corners;
  // Measured on a 640x480 frame holding a 9x6 board: a global threshold finds it or gives
  // up in ~10 ms; an adaptive one takes 0.25 s to give up, and adaptive + normalised
  // ~12 s when asked for a size the board does not have.
  const int quick = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  if (!cv::findChessboardCorners(gray, inner_corners, corners, quick) &&
      !(thorough && cv::findChessboardCorners(gray, inner_corners, corners,
                                              cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK)))
    return std::nullopt;
  // Half the spacing of neighbouring corners (at most 11 px, at least 3): a larger
  // window would reach the next corner on small or oblique boards.
  double spacing = 1e9;
  for (int r = 0; r < inner_corners.height; ++r)
    for (int c = 0; c + 1 < inner_corners.width; ++c) {
      const int i = r * inner_corners.width + c;
      spacing = std::min(spacing, double(cv::norm(corners[i + 1] - corners[i])));
    }
  const int half = std::clamp(int(spacing * 0.5), 3, 11);
  cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 0.001));
  return solve_board_pose(corners, inner_corners, square_size_m, camera);
}

}  // namespace lumar::calib
