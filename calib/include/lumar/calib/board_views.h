#pragma once
// Calibration views: a calibration board's points found in a set of images, before any
// solving. Checkerboards (checkerboard_calibration.h) and ChArUco boards
// (charuco_calibration.h) both produce them; robust_calibration.h solves them.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace lumar::calib {

struct NamedImage {
  std::string name;  // the path as given, or "<source>#<frame>" for a sampled frame
  cv::Mat image;     // BGR8 or grey
};

struct BoardViews {
  cv::Size image_size;
  std::vector<std::string> names;                 // one per view with the board
  std::vector<std::vector<cv::Point2f>> corners;  // sub-pixel image points of each view
  std::vector<std::vector<cv::Point3f>> objects;  // the same points on the board, metres, z = 0
  std::vector<std::string> views_without_board;
};

// Reads image files (grey). InputError naming the file when one is missing or unreadable.
std::vector<NamedImage> load_board_images(const std::vector<std::filesystem::path>& paths);

// InputError unless `views` holds at least 3 views, naming the board (`board_text`) and
// how many images were searched.
void require_board_views(const BoardViews& views, std::size_t images, const std::string& board_text);

}  // namespace lumar::calib
