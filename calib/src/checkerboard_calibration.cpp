#include "lumar/calib/checkerboard_calibration.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"

namespace lumar::calib {

namespace {

std::string size_text(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// A board given too small (--board 8x6 on a 9x6 board) is still found, as a part of the
// real one, and calibrates wrongly without a word. So a few views are searched again
// for a board one corner wider or taller: if most of them hold one, the size is wrong.
void check_not_part_of_a_larger_board(const std::vector<cv::Mat>& greys, const std::vector<std::string>& names,
                                      cv::Size inner_corners) {
  for (const cv::Size larger : {cv::Size(inner_corners.width + 1, inner_corners.height),
                                cv::Size(inner_corners.width, inner_corners.height + 1)}) {
    int found = 0;
    std::vector<cv::Point2f> corners;
    for (const cv::Mat& grey : greys)
      found += cv::findChessboardCorners(
          grey, larger, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
    if (found * 2 > int(greys.size()))
      throw InputError("--board " + size_text(inner_corners) + ": " + std::to_string(found) + " of " +
                       std::to_string(greys.size()) + " views checked (" + names.front() + ", ...) show a board of " +
                       size_text(larger) + " or more inner corners; give the whole board's inner corners");
  }
}

}  // namespace

std::vector<cv::Point3f> checkerboard_points(cv::Size inner_corners, double square_size_m) {
  std::vector<cv::Point3f> board;
  for (int r = 0; r < inner_corners.height; ++r)
    for (int c = 0; c < inner_corners.width; ++c)
      board.emplace_back(float(c * square_size_m), float(r * square_size_m), 0.f);
  return board;
}

BoardViews detect_checkerboard_views(const std::vector<NamedImage>& images, cv::Size inner_corners,
                                     double square_size_m) {
  if (images.empty()) throw InputError("checkerboard calibration: no images given; pass the board photographs");
  if (inner_corners.width < 2 || inner_corners.height < 2)
    throw InputError("checkerboard calibration: board size " + size_text(inner_corners) +
                     " is too small; give the inner corners, e.g. 9x6 for a 10x7-square board");
  if (!(square_size_m > 0.0) || !std::isfinite(square_size_m))
    throw InputError("checkerboard calibration: square size must be a positive length in metres");
  const std::vector<cv::Point3f> board = checkerboard_points(inner_corners, square_size_m);
  BoardViews result;
  std::vector<cv::Mat> checked;  // the first views with a board, to check its size on
  std::vector<std::string> checked_names;
  result.image_size = images.front().image.size();
  for (const auto& named : images) {
    throw_if_stopped("calibrate: while looking for the board in " + named.name);
    if (named.image.size() != result.image_size)
      throw InputError(named.name + ": image is " + size_text(named.image.size()) + " but " + images.front().name +
                       " is " + size_text(result.image_size) + "; calibrate one camera mode at a time");
    cv::Mat grey;
    if (named.image.channels() == 3)
      cv::cvtColor(named.image, grey, cv::COLOR_BGR2GRAY);
    else
      grey = named.image;
    std::vector<cv::Point2f> corners;
    // FAST_CHECK: video frames without the board are rejected quickly.
    if (!cv::findChessboardCorners(
            grey, inner_corners, corners,
            cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
      result.views_without_board.push_back(named.name);
      continue;
    }
    // OpenCV's 11 px half-window (its calibration sample's), narrowed only where it would
    // reach the neighbouring corner: a small board far away in a video frame.
    double spacing = 1e9;
    for (std::size_t i = 0; i + 1 < corners.size(); ++i)
      if ((i + 1) % std::size_t(inner_corners.width) != 0)
        spacing = std::min(spacing, double(cv::norm(corners[i + 1] - corners[i])));
    const int half = std::clamp(int(spacing) - 2, 3, 11);
    cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.0001));
    result.corners.push_back(std::move(corners));
    result.objects.push_back(board);
    result.names.push_back(named.name);
    if (checked.size() < 3) checked.push_back(grey), checked_names.push_back(named.name);
  }
  require_board_views(result, images.size(),
                      size_text(inner_corners) + " inner-corner board (inner corners, not squares)");
  check_not_part_of_a_larger_board(checked, checked_names, inner_corners);
  return result;
}

CalibrationResult calibrate_checkerboard(const std::vector<std::filesystem::path>& images, cv::Size inner_corners,
                                         double square_size_m) {
  const BoardViews views = detect_checkerboard_views(load_board_images(images), inner_corners, square_size_m);
  const auto& image_points = views.corners;
  const cv::Size image_size = views.image_size;
  CalibrationResult result;
  result.used_views = views.names;
  result.views_without_board = views.views_without_board;
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(views.objects, image_points, image_size, K, D, rvecs, tvecs);

  for (std::size_t i = 0; i < image_points.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(views.objects[i], rvecs[i], tvecs[i], K, D, projected);
    double sum = 0.0;
    for (std::size_t j = 0; j < projected.size(); ++j) {
      const cv::Point2f e = projected[j] - image_points[i][j];
      sum += double(e.x) * e.x + double(e.y) * e.y;
    }
    result.per_view_rms.push_back(std::sqrt(sum / double(projected.size())));
  }

  CameraIntrinsics& c = result.camera.intrinsics;
  c.width = image_size.width;
  c.height = image_size.height;
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) c.distortion[i] = D.at<double>(i);
  result.camera.avg_reprojection_error = rms;
  return result;
}

}  // namespace lumar::calib
