#pragma once
// Camera intrinsics from ChArUco boards (OpenCV 4.6 contrib aruco): a checkerboard whose
// white squares hold ArUco markers, so that corners are identified even when the board
// is only partly in view.
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lumar/calib/camera_file.h"

namespace lumar::calib {

struct CharucoBoardSpec {
  int squares_x = 7, squares_y = 5;  // squares (not inner corners)
  double square_m = 0.04, marker_m = 0.03;
  std::string dictionary = "DICT_5X5_100";  // cv::aruco predefined dictionary name
};

// cv::aruco::PREDEFINED_DICTIONARY_NAME of a name such as "DICT_5X5_100"; InputError
// listing the accepted names otherwise.
int charuco_dictionary_id(const std::string& name);

// The board as cv::aruco::CharucoBoard::draw prints it (8-bit grey), `pixels` wide and
// tall including `margin` white pixels on each side.
cv::Mat draw_charuco_board(const CharucoBoardSpec& board, cv::Size pixels, int margin = 0);

struct CharucoCorners {
  std::vector<cv::Point2f> corners;  // sub-pixel, from interpolateCornersCharuco
  std::vector<int> ids;
};

// Markers, then the chessboard corners between them; nullopt with fewer than
// `min_corners` corners.
std::optional<CharucoCorners> detect_charuco(const cv::Mat& image, const CharucoBoardSpec& board, int min_corners = 6);

struct CharucoCalibration {
  CameraFile camera;             // avg_reprojection_error = RMS over all corners
  std::array<double, 9> std_dev{};  // fx fy cx cy k1 k2 p1 p2 k3 (kIntrinsicNames)
  std::vector<double> per_view_rms;
  std::vector<int> used_views;   // indices into the images with enough corners
};

// cv::aruco::calibrateCameraCharuco over the images where the board is found. Throws
// InputError for an unknown dictionary, a marker not smaller than its square, images of
// different sizes, or fewer than 3 views with the board.
CharucoCalibration calibrate_charuco(const std::vector<cv::Mat>& images, const CharucoBoardSpec& board, int flags = 0);

}  // namespace lumar::calib
