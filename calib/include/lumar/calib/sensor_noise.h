#pragma once
// Camera noise: per channel, the variance of a pixel as a function of its linear value
// (read noise plus shot noise), measured from ordinary video frames. The renderer adds
// noise of the same level to virtual objects so that they do not look cleaner than the
// video around them.
#include <array>
#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/calib/camera_response.h"

namespace lumar::calib {

// Noise of the camera in the linear units of a CameraResponse (camera_response.h), per
// channel in the images' order (BGR). Without the 8-bit rounding of the video.
struct SensorNoise {
  std::array<double, 3> read_variance{};           // variance at zero signal
  std::array<double, 3> shot_gain{};               // variance added per unit of linear signal
  std::size_t patches = 0;                         // flat patches the fit used (8x8 blocks; fewest of the channels)
  double sigma(int channel, double linear) const;  // sqrt(read_variance + shot_gain * max(linear, 0))
};

// Estimates it from CV_8UC3 frames (any number >= 1, of any sizes): linearises them, and
// in every 8x8 block of each channel without a clipped code (0 or 255) measures the mean and
// the variance of a 4-neighbour high-pass (which removes planes). Texture only adds
// variance, so per log-spaced bin of block means it takes a bias-corrected 10th percentile,
// less the 8-bit rounding's variance, and fits read + gain * mean to the bins by weighted
// least squares (both >= 0), leaving out bins far above the fit. Noise correlated between
// neighbouring pixels (demosaicing, denoising, compression) reads low.
// Throws lumar::InputError for no frames, a frame that is not CV_8UC3, or frames with too
// few usable flat patches (fewer than 2 brightness levels with 20 unclipped blocks each).
SensorNoise estimate_sensor_noise(const std::vector<cv::Mat>& frames_bgr8, const CameraResponse& response);

}  // namespace lumar::calib
