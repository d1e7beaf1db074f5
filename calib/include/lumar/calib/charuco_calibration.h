#pragma once
// ChArUco boards (OpenCV 4.6 contrib aruco): a checkerboard whose
// white squares hold ArUco markers, so that corners are identified even when the board
// is only partly in view.
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lumar/calib/board_views.h"

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

// The board's chessboard corners found in each image, with their board-plane points
// (views with fewer than 6 corners are listed as without the board), ready for
// calibrate_robust (robust_calibration.h) like checkerboard views. Throws InputError for
// an unknown dictionary, a marker not smaller than its square, no images, images of
// different sizes, or fewer than 3 views with the board.
BoardViews detect_charuco_views(const std::vector<NamedImage>& images, const CharucoBoardSpec& board);

}  // namespace lumar::calib
