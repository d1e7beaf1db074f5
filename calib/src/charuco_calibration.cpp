#include "lumar/calib/charuco_calibration.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"

namespace lumar::calib {

namespace {

struct NamedDictionary {
  const char* name;
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
};

constexpr NamedDictionary kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
    {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
    {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
    {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
    {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
    {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
    {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
    {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
    {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
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

BoardViews detect_charuco_views(const std::vector<NamedImage>& images, const CharucoBoardSpec& spec) {
  const auto board = make_board(spec);
  if (images.empty()) throw InputError("ChArUco calibration: no images given; pass the board photographs");
  BoardViews views;
  views.image_size = images.front().image.size();
  for (const auto& named : images) {
    throw_if_stopped("calibrate: while looking for the board in " + named.name);
    if (named.image.size() != views.image_size)
      throw InputError(named.name + ": image size differs from " + images.front().name +
                       "; calibrate one camera mode at a time");
    auto found = detect_charuco(named.image, spec);
    if (!found) {
      views.views_without_board.push_back(named.name);
      continue;
    }
    std::vector<cv::Point3f> objects;
    for (int id : found->ids) objects.push_back(board->chessboardCorners[std::size_t(id)]);
    views.corners.push_back(std::move(found->corners));
    views.objects.push_back(std::move(objects));
    views.names.push_back(named.name);
  }
  require_board_views(views, images.size(),
                      std::to_string(spec.squares_x) + "x" + std::to_string(spec.squares_y) +
                          "-square ChArUco board (" + spec.dictionary + ", check --charuco and --dict)");
  return views;
}

}  // namespace lumar::calib
