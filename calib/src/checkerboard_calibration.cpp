#include "lumar/calib/checkerboard_calibration.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/core/error.h"

namespace lumar::calib {

namespace {

std::string size_text(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

}  // namespace

std::vector<cv::Point3f> checkerboard_points(cv::Size inner_corners, double square_size_m) {
  std::vector<cv::Point3f> board;
  for (int r = 0; r < inner_corners.height; ++r)
    for (int c = 0; c < inner_corners.width; ++c)
      board.emplace_back(float(c * square_size_m), float(r * square_size_m), 0.f);
  return board;
}

CheckerboardViews detect_checkerboard_views(const std::vector<std::filesystem::path>& images,
                                            cv::Size inner_corners, double square_size_m) {
  if (images.empty()) throw InputError("checkerboard calibration: no images given; pass the board photographs");
  if (inner_corners.width < 2 || inner_corners.height < 2)
    throw InputError("checkerboard calibration: board size " + size_text(inner_corners) +
                     " is too small; give the inner corners, e.g. 9x6 for a 10x7-square board");
  if (!(square_size_m > 0.0) || !std::isfinite(square_size_m))
    throw InputError("checkerboard calibration: square size must be a positive length in metres");

  CheckerboardViews result;
  result.board = checkerboard_points(inner_corners, square_size_m);
  auto& image_points = result.corners;
  cv::Size& image_size = result.image_size;
  std::string first_image;
  for (const auto& path : images) {
    const std::string name = path.string();
    if (!std::filesystem::is_regular_file(path))
      throw InputError(name + ": image not found; check the path or remove it from the list");
    const cv::Mat gray = cv::imread(name, cv::IMREAD_GRAYSCALE);
    if (gray.empty())
      throw InputError(name + ": cannot read image (missing or not an image file); remove it from the list");
    if (image_size.empty()) {
      image_size = gray.size();
      first_image = name;
    } else if (gray.size() != image_size) {
      throw InputError(name + ": image is " + size_text(gray.size()) + " but " + first_image + " is " +
                       size_text(image_size) + "; calibrate one camera mode at a time");
    }
    std::vector<cv::Point2f> corners;
    const bool found = cv::findChessboardCorners(
        gray, inner_corners, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
    if (!found) {
      result.views_without_board.push_back(name);
      continue;
    }
    cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.0001));
    image_points.push_back(std::move(corners));
    result.names.push_back(name);
  }
  if (image_points.empty())
    throw InputError("checkerboard calibration: no " + size_text(inner_corners) +
                     " inner-corner board found in any of the " + std::to_string(images.size()) +
                     " images; check the board size (inner corners, not squares)");
  if (image_points.size() < 3)
    throw InputError("checkerboard calibration: the board was found in only " +
                     std::to_string(image_points.size()) + " image(s); at least 3 views are needed, "
                     "better 10 or more at varied angles");

  return result;
}

CalibrationResult calibrate_checkerboard(const std::vector<std::filesystem::path>& images,
                                         cv::Size inner_corners, double square_size_m) {
  const CheckerboardViews views = detect_checkerboard_views(images, inner_corners, square_size_m);
  const auto& board = views.board;
  const auto& image_points = views.corners;
  const cv::Size image_size = views.image_size;
  CalibrationResult result;
  result.used_views = views.names;
  result.views_without_board = views.views_without_board;
  const std::vector<std::vector<cv::Point3f>> object_points(image_points.size(), board);
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(object_points, image_points, image_size, K, D, rvecs, tvecs);

  for (std::size_t i = 0; i < image_points.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(board, rvecs[i], tvecs[i], K, D, projected);
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
