#pragma once
// Radial vignetting as recorded in sessions (capture::Radiometry): video gain
// 1 + a r^2 + b r^4, r = distance of a pixel centre from the principal point (cx, cy),
// in pixels with OpenCV's convention (pixel centres at integer coordinates), divided by
// the image's half-diagonal.
#include <opencv2/core.hpp>

namespace lumar::calib {

struct VignettingFit {
  double a = 0.0, b = 0.0;
  double level = 0.0;         // fitted flat-field value at the principal point
  double residual_rms = 0.0;  // of the inliers, relative to level
  int inliers = 0, samples = 0;
};

// Least-squares fit of level * (1 + a r^2 + b r^4) to a linear flat-field image (float,
// 1 or 3 channels, averaged to grey), robust to noise and to outliers (dust, hot pixels)
// by block averaging and iterative 3-sigma rejection. Throws InputError on an empty or
// non-float image or a principal point outside it.
VignettingFit estimate_vignetting(const cv::Mat& linear_flat_field, double cx, double cy);

// The gain 1 + a r^2 + b r^4 at every pixel (CV_32FC1, same size as `size`).
cv::Mat vignetting_gain(cv::Size size, double a, double b, double cx, double cy);

// Divides a linear float image (1 or 3 channels) by the vignetting gain; returns a new image.
cv::Mat correct_vignetting(const cv::Mat& linear_image, double a, double b, double cx, double cy);

}  // namespace lumar::calib
