#include "lumar/calib/camera_blur.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

constexpr double kReblur = 1.0;            // s0, pixels
constexpr std::size_t kFewestEdges = 200;  // fewer edge pixels: nothing to tell
constexpr double kQuantile = 0.25;         // of the per-pixel estimates: the sharp edges
// What the measurement itself adds to the edge's variance, px²: Sobel's central
// difference (a box two pixels wide, 1/3) and the sampled peak falling between pixels.
// Measured on edges of known blur (CameraBlur.FindsTheGaussianThatBlurredTheImage): 0.5.
constexpr double kMeasurementVariance = 0.5;

cv::Mat gradient_magnitude(const cv::Mat& grey) {
  cv::Mat gx, gy, magnitude;
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3);
  cv::magnitude(gx, gy, magnitude);
  return magnitude;
}

}  // namespace

CameraBlur estimate_camera_blur(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw InputError("camera blur: need a non-empty 8-bit grey or BGR image");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  cv::Mat grey_f;
  grey.convertTo(grey_f, CV_32F);
  cv::Mat again;
  cv::GaussianBlur(grey_f, again, cv::Size(0, 0), kReblur);
  const cv::Mat g = gradient_magnitude(grey_f), g_again = gradient_magnitude(again);
  // Strong edges only, where the ratio is well above the noise: Canny's thin edges with
  // a contrast of at least 24 levels, kept off the image border.
  cv::Mat edges;
  cv::Canny(grey, edges, 40, 100);
  std::vector<double> sigmas;
  for (int r = 4; r < grey.rows - 4; ++r)
    for (int c = 4; c < grey.cols - 4; ++c) {
      if (!edges.at<std::uint8_t>(r, c)) continue;
      const double a = g.at<float>(r, c), b = g_again.at<float>(r, c);
      if (a < 24.0 * 4.0 || b <= 0) continue;  // Sobel's gain is 4 per level of step
      const double ratio = a / b;
      if (ratio <= 1.0 + 1e-3) continue;  // flatter than any blur allows: texture, not a step
      const double seen = kReblur / std::sqrt(ratio * ratio - 1.0);
      sigmas.push_back(std::sqrt(std::max(0.0, seen * seen - kMeasurementVariance)));
    }
  if (sigmas.size() < kFewestEdges)
    throw InputError("camera blur: only " + std::to_string(sigmas.size()) +
                     " pixels of strong edges in the image (need " + std::to_string(kFewestEdges) +
                     "); point the camera at something with sharp edges, or give --blur-sigma");
  auto at = sigmas.begin() + std::ptrdiff_t(kQuantile * double(sigmas.size() - 1));
  std::nth_element(sigmas.begin(), at, sigmas.end());
  return {*at, sigmas.size()};
}

}  // namespace lumar::calib
