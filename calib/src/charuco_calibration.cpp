#include "lumar/calib/charuco_calibration.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/core/error.h"

namespace lumar::calib {

namespace {

struct NamedDictionary {
  const char* name;
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
};

constexpr NamedDictionary kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},     {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},   {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},     {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},   {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},     {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},   {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},     {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},   {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
};

cv::Ptr<cv::aruco::CharucoBoard> make_board(const CharucoBoardSpec& b) {
  if (b.squares_x < 2 || b.squares_y < 2)
    throw InputError("--charuco " + std::to_string(b.squares_x) + "x" + std::to_string(b.squares_y) +
                     ": a ChArUco board needs at least 2x2 squares");
  if (!(b.square_m > 0) || !(b.marker_m > 0) || b.marker_m >= b.square_m)
    throw InputError("--marker: the marker must be positive and smaller than the square (--square)");
  return cv::aruco::CharucoBoard::create(b.squares_x, b.squares_y, float(b.square_m), float(b.marker_m),
                                         cv::aruco::getPredefinedDictionary(charuco_dictionary_id(b.dictionary)));
}

}  // namespace

int charuco_dictionary_id(const std::string& name) {
  for (const auto& d : kDictionaries)
    if (name == d.name) return d.id;
  std::string names;
  for (const auto& d : kDictionaries) names += std::string(names.empty() ? "" : ", ") + d.name;
  throw InputError("--dict " + name + ": unknown ArUco dictionary; use one of " + names);
}

cv::Mat draw_charuco_board(const CharucoBoardSpec& board, cv::Size pixels, int margin) {
  cv::Mat image;
  make_board(board)->draw(pixels, image, margin, 1);
  return image;
}

std::optional<CharucoCorners> detect_charuco(const cv::Mat& image, const CharucoBoardSpec& spec, int min_corners) {
  const auto board = make_board(spec);
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else
    gray = image;
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(gray, board->dictionary, marker_corners, marker_ids);
  if (marker_ids.empty()) return std::nullopt;
  CharucoCorners out;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, board, out.corners, out.ids);
  if (int(out.ids.size()) < min_corners) return std::nullopt;
  return out;
}

CharucoCalibration calibrate_charuco(const std::vector<cv::Mat>& images, const CharucoBoardSpec& spec, int flags) {
  const auto board = make_board(spec);
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<std::vector<int>> ids;
  CharucoCalibration out;
  cv::Size size;
  for (std::size_t i = 0; i < images.size(); ++i) {
    if (size.empty()) size = images[i].size();
    if (images[i].size() != size)
      throw InputError("ChArUco calibration: image " + std::to_string(i) + " differs in size from the first; "
                       "calibrate one camera mode at a time");
    if (auto c = detect_charuco(images[i], spec)) {
      corners.push_back(std::move(c->corners));
      ids.push_back(std::move(c->ids));
      out.used_views.push_back(int(i));
    }
  }
  if (corners.size() < 3)
    throw InputError("ChArUco calibration: the board was found in " + std::to_string(corners.size()) + " of " +
                     std::to_string(images.size()) + " images; at least 3 are needed (check --charuco, --dict)");
  cv::Mat K, D, std_intrinsics, std_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::aruco::calibrateCameraCharuco(corners, ids, board, size, K, D, rvecs, tvecs, std_intrinsics,
                                                       std_extrinsics, per_view, flags);
  CameraIntrinsics& c = out.camera.intrinsics;
  c.width = size.width, c.height = size.height;
  c.fx = K.at<double>(0, 0), c.fy = K.at<double>(1, 1), c.cx = K.at<double>(0, 2), c.cy = K.at<double>(1, 2);
  for (int i = 0; i < 5 && i < int(D.total()); ++i) c.distortion[std::size_t(i)] = D.at<double>(i);
  out.camera.avg_reprojection_error = rms;
  for (int i = 0; i < 9 && i < int(std_intrinsics.total()); ++i) out.std_dev[std::size_t(i)] = std_intrinsics.at<double>(i);
  for (int i = 0; i < int(per_view.total()); ++i) out.per_view_rms.push_back(per_view.at<double>(i));
  return out;
}

}  // namespace lumar::calib
