#pragma once
// Undistortion of camera images, and its inverse (adding a lens's distortion to a
// pinhole rendering, used by the synthetic renderer). Camera model in lumar/base/camera.h.
#include <opencv2/core.hpp>

#include "lumar/base/camera.h"

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

// The image `distorted_camera` would see, made from a pinhole image of the same scene
// taken from the same centre (pinhole_camera may be larger, e.g. supersampled, with
// its own K). Output size is distorted_camera's; bilinear; outside the pinhole image
// becomes 0. Any depth and channel count cv::remap accepts (8-bit, float, ...).
cv::Mat distort_image(const cv::Mat& pinhole_image, const CameraIntrinsics& pinhole_camera,
                      const CameraIntrinsics& distorted_camera);

}  // namespace lumar::calib
