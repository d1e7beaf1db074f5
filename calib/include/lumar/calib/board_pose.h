#pragma once
// Where a planar checkerboard sits in front of a calibrated camera: the corners found
// in one image, then the board's pose from cv::solvePnP, with its reprojection error.
//
// Board frame (checkerboard_points): origin at the first inner corner, x along a row of
// corners, y down the columns, z into the board (away from a camera that sees its face).
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"

namespace lumar::calib {

struct BoardPose {
  Pose T_camera_board;
  double reprojection_rms_px = 0;  // corners against the board projected with the pose
  std::vector<cv::Point2f> corners;
};

// OpenCV's Rodrigues vector and translation <-> Pose (both map board to camera points).
Pose pose_from_rvec_tvec(const cv::Vec3d& rvec, const cv::Vec3d& tvec);
void pose_to_rvec_tvec(const Pose& pose, cv::Vec3d& rvec, cv::Vec3d& tvec);
cv::Matx33d rotation_matx(const Pose& pose);
Pose pose_from_rt(const cv::Matx33d& R, const cv::Vec3d& t);

// Finds the whole board in a BGR or grey image (sub-pixel corners) and solves its pose
// (iterative PnP on the distorted corners). nullopt when the board is not found.
// thorough: when a global threshold fails, also try an adaptive one (0.25 s per frame to
// fail, so only worth it once the board size is known to be right).
std::optional<BoardPose> find_board_pose(const cv::Mat& image, cv::Size inner_corners, double square_size_m,
                                         const CameraIntrinsics& camera, bool thorough = false);

// The pose of the board from corners already found (same order as checkerboard_points).
BoardPose solve_board_pose(const std::vector<cv::Point2f>& corners, cv::Size inner_corners, double square_size_m,
                           const CameraIntrinsics& camera);

}  // namespace lumar::calib
