#pragma once
// Undistortion of camera images, and its inverse (adding a lens's distortion to a
// pinhole rendering, used by the synthetic renderer). Camera model in lumar/base/camera.h.
#include <opencv2/core.hpp>

#include "lumar/base/camera.h"
#include "lumar/calib/camera_response.h"

namespace lumar::calib {

// Which pinhole camera the undistorted image is made for (always the input's size).
enum class UndistortedCamera {
  SameMatrix,   // the calibrated K itself: the renderer projects with the calibrated K
  CropToValid,  // cv::getOptimalNewCameraMatrix, alpha = 0: every output pixel is valid
                // (to OpenCV's estimate: the outermost may look ~1 px outside)
  KeepAll,      // cv::getOptimalNewCameraMatrix, alpha = 1: every input pixel is kept
};

struct UndistortionMaps {
  cv::Mat map_x, map_y;     // CV_32FC1, output size: source pixel in the distorted image
  CameraIntrinsics output;  // pinhole camera of the undistorted image (no distortion)
};

UndistortionMaps make_undistortion_maps(const CameraIntrinsics& distorted,
                                        UndistortedCamera output = UndistortedCamera::SameMatrix);

// Bilinear remap; pixels that look outside the distorted image become 0. Throws
// InputError when the image size differs from the calibration's.
cv::Mat undistort_image(const cv::Mat& image, const UndistortionMaps& maps);

// The same remap of a camera's 8-bit BGR image in linear light (docs/conventions.md):
// each code decoded through `response`, the light interpolated, the result encoded back
// to the nearest code. Outside the distorted image is code 0. The composite's background
// is undistorted so; undistort_image's mixing of codes would darken every bright/dark edge.
cv::Mat undistort_in_linear_light(const cv::Mat& image8, const UndistortionMaps& maps, const CameraResponse& response);

// The blur a bilinear remap through `maps` adds, as a variance in px² per axis, averaged
// over the output pixels that sample the image: at a source offset with fractional part f
// it mixes (1 − f, f) of two pixels, a variance of f(1 − f); 1/6 where f is uniform.
double resampling_variance(const UndistortionMaps& maps);

// The image `distorted_camera` would see, made from a pinhole image of the same scene
// taken from the same centre (pinhole_camera may be larger, e.g. supersampled, with
// its own K). Output size is distorted_camera's; bilinear; outside the pinhole image
// becomes 0. Any depth and channel count cv::remap accepts (8-bit, float, ...).
cv::Mat distort_image(const cv::Mat& pinhole_image, const CameraIntrinsics& pinhole_camera,
                      const CameraIntrinsics& distorted_camera);

}  // namespace lumar::calib
