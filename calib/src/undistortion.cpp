#include "lumar/calib/undistortion.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

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
  if (image.size() != maps.map_x.size())
    throw InputError("image is " + size_text(image.cols, image.rows) + " but the camera calibration is for " +
                     size_text(maps.map_x.cols, maps.map_x.rows) +
                     "; use the calibration file made for this camera mode");
  cv::Mat out;
  cv::remap(image, out, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
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
