#pragma once
// How much the camera blurs (lens, sensor, resampling), estimated from its own footage,
// so that rendered objects can be blurred alike: at the image's sharpest edges, the
// gradient's drop when the image is blurred again by a known Gaussian (Zhuo & Sim 2011,
// "Defocus map estimation from a single image"). For a step edge blurred by sigma, a
// second blur by s0 lowers the peak gradient by R = sqrt(sigma^2 + s0^2) / sigma, so
// sigma = s0 / sqrt(R^2 - 1).
#include <opencv2/core.hpp>

namespace lumar::calib {

struct CameraBlur {
  double sigma_px = 0;    // Gaussian standard deviation, pixels of the image given
  std::size_t edges = 0;  // edge pixels the estimate rests on
};

// From one CV_8UC3 or CV_8UC1 image (undistorted, as the composite shows it). The scene's
// own soft edges only add blur, so the estimate is a low quantile of the edge pixels'
// values: the sharpest edges are the camera's. Throws InputError for an empty or non-8-bit
// image, or one with too few strong edges to tell (a blank wall).
CameraBlur estimate_camera_blur(const cv::Mat& image);

}  // namespace lumar::calib
