#include "lumar/calib/undistortion.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

void check_size(const cv::Mat& image, const UndistortionMaps& maps) {
  if (image.size() != maps.map_x.size())
    throw InputError("image is " + size_text(image.cols, image.rows) + " but the camera calibration is for " +
                     size_text(maps.map_x.cols, maps.map_x.rows) +
                     "; use the calibration file made for this camera mode");
}

// The code whose light is nearest `linear`: the midpoints between neighbouring codes'
// light are the boundaries (the response's tables never decrease).
std::uint8_t nearest_code(const std::array<float, 256>& table, float linear) {
  const auto above = std::lower_bound(table.begin(), table.end(), linear);
  if (above == table.begin()) return 0;
  if (above == table.end()) return 255;
  const auto code = above - table.begin();
  return std::uint8_t(linear - table[std::size_t(code - 1)] < *above - linear ? code - 1 : code);
}

CameraIntrinsics pinhole_from_matrix(const CameraIntrinsics& like, const cv::Mat& K) {
  CameraIntrinsics c = like.without_distortion();
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  return c;
}

}  // namespace

UndistortionMaps make_undistortion_maps(const CameraIntrinsics& distorted, UndistortedCamera output) {
  if (!distorted.is_valid())
    throw InputError("camera intrinsics are invalid (size " + size_text(distorted.width, distorted.height) + ", fx " +
                     std::to_string(distorted.fx) + ", fy " + std::to_string(distorted.fy) +
                     "); recalibrate the camera");
  const cv::Size size(distorted.width, distorted.height);
  const cv::Mat K(distorted.camera_matrix());
  const cv::Mat D = distorted.distortion_coefficients();
  cv::Mat new_K = K.clone();
  if (output != UndistortedCamera::SameMatrix) {
    const double alpha = output == UndistortedCamera::KeepAll ? 1.0 : 0.0;
    new_K = cv::getOptimalNewCameraMatrix(K, D, size, alpha, size);
  }
  UndistortionMaps maps;
  maps.output = pinhole_from_matrix(distorted, new_K);
  cv::initUndistortRectifyMap(K, D, cv::noArray(), new_K, size, CV_32FC1, maps.map_x, maps.map_y);
  return maps;
}

cv::Mat undistort_image(const cv::Mat& image, const UndistortionMaps& maps) {
  check_size(image, maps);
  cv::Mat out;
  cv::remap(image, out, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

cv::Mat undistort_in_linear_light(const cv::Mat& image8, const UndistortionMaps& maps, const CameraResponse& response) {
  check_size(image8, maps);
  cv::Mat undistorted;
  cv::remap(linearize(image8, response), undistorted, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(response(0, 0), response(1, 0), response(2, 0)));
  cv::Mat out(undistorted.size(), CV_8UC3);
  tbb::parallel_for(0, out.rows, [&](int r) {
    const auto* in = undistorted.ptr<cv::Vec3f>(r);
    auto* code = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < out.cols; ++c)
      for (int k = 0; k < 3; ++k) code[c][k] = nearest_code(response.exposure[std::size_t(k)], in[c][k]);
  });
  return out;
}

double resampling_variance(const UndistortionMaps& maps) {
  double sum = 0;
  std::int64_t n = 0;
  const int w = maps.map_x.cols, h = maps.map_x.rows;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const float x = maps.map_x.at<float>(r, c), y = maps.map_y.at<float>(r, c);
      if (!(x >= 0 && y >= 0 && x <= float(w - 1) && y <= float(h - 1))) continue;
      const double fx = x - std::floor(x), fy = y - std::floor(y);
      sum += 0.5 * (fx * (1 - fx) + fy * (1 - fy));
      ++n;
    }
  return n > 0 ? sum / double(n) : 0.0;
}

cv::Mat distort_image(const cv::Mat& pinhole_image, const CameraIntrinsics& pinhole_camera,
                      const CameraIntrinsics& distorted_camera) {
  if (!pinhole_camera.is_valid() || !distorted_camera.is_valid())
    throw InputError("distort_image: camera intrinsics are invalid; recalibrate the camera");
  if (pinhole_image.cols != pinhole_camera.width || pinhole_image.rows != pinhole_camera.height)
    throw InputError("pinhole image is " + size_text(pinhole_image.cols, pinhole_image.rows) + " but its camera is " +
                     size_text(pinhole_camera.width, pinhole_camera.height));
  const int w = distorted_camera.width, h = distorted_camera.height;
  cv::Mat pixels(w * h, 1, CV_64FC2);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) pixels.at<cv::Vec2d>(v * w + u) = {double(u), double(v)};
  // OpenCV's default 5 fixed-point iterations leave tenths of a pixel at the corners of
  // a typical webcam; iterate until the re-distorted point is within 1e-6 px.
  cv::Mat in_pinhole;
  cv::undistortPoints(pixels, in_pinhole, cv::Mat(distorted_camera.camera_matrix()),
                      distorted_camera.distortion_coefficients(), cv::noArray(),
                      cv::Mat(pinhole_camera.camera_matrix()),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6));
  cv::Mat map(h, w, CV_32FC2);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const cv::Vec2d p = in_pinhole.at<cv::Vec2d>(v * w + u);
      map.at<cv::Vec2f>(v, u) = {float(p[0]), float(p[1])};
    }
  cv::Mat out;
  cv::remap(pinhole_image, out, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

}  // namespace lumar::calib
