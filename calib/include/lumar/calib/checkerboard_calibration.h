#pragma once
// Camera intrinsics from photographs of a planar checkerboard (OpenCV calibrateCamera,
// Brown–Conrady k1 k2 p1 p2 k3).
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "lumar/calib/board_views.h"
#include "lumar/calib/camera_file.h"

namespace lumar::calib {

struct CalibrationResult {
  CameraFile camera;                             // avg_reprojection_error = overall RMS, pixels
  std::vector<std::string> used_views;           // images where the board was found (paths as given)
  std::vector<double> per_view_rms;              // pixels, one per used view
  std::vector<std::string> views_without_board;  // images where it was not
};

// The board's corners in its own plane, row by row as findChessboardCorners orders them.
std::vector<cv::Point3f> checkerboard_points(cv::Size inner_corners, double square_size_m);

// Finds the board in each image (sub-pixel refined; views without it are listed). Throws
// InputError for no images, a bad board size or square, images of different sizes, or
// fewer than 3 views where the board is found.
BoardViews detect_checkerboard_views(const std::vector<NamedImage>& images, cv::Size inner_corners,
                                     double square_size_m);

// Plain calibration, every view kept (robust_calibration.h drops outliers).
// inner_corners: corners where four squares meet, e.g. 9x6 for a 10x7-square board.
// The reference beside calibrate_robust: plain cv::calibrateCamera on every view.
// Throws InputError as load_board_images and detect_checkerboard_views do.
CalibrationResult calibrate_checkerboard(const std::vector<std::filesystem::path>& images, cv::Size inner_corners,
                                         double square_size_m);

}  // namespace lumar::calib
