#pragma once
// Camera response: what relative linear exposure (scene radiance x exposure time, up to
// one scale) produced each 8-bit video value, per channel. Recovered from bracketed
// exposures (Debevec-Malik), or the documented default: the sRGB transfer curve with a
// gain (see lumar/base/color.h). Channels are in the images' own order (BGR for images
// read by OpenCV).
#include <array>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "lumar/capture/session.h"

namespace lumar::calib {

struct CameraResponse {
  // exposure[channel][value]: relative linear exposure giving that 8-bit value.
  std::array<std::array<float, 256>, 3> exposure{};

  float operator()(int channel, int value) const { return exposure[size_t(channel)][size_t(value)]; }
};

// The default until a camera is calibrated: srgb_to_linear(value / 255) / gain, where
// gain is video linear value per unit of scene radiance (Radiometry::exposure).
CameraResponse srgb_response(double gain = 1.0);

// Debevec-Malik recovery (cv::CalibrateDebevec) from a bracket of CV_8UC3 images of a
// static scene, exposure_times in seconds. Normalised so that value 128 maps to 1 in
// every channel. Defaults tuned on a synthetic bracket (5 exposures 2 stops apart, 8-bit
// noise): smoothness 20 beat 10 and 30+ on both the curve and the merge. Throws
// InputError on fewer than 2 images, images of different sizes or types, non-CV_8UC3
// images, or exposure times that are not positive and finite.
CameraResponse recover_response_debevec(const std::vector<cv::Mat>& images, const std::vector<double>& exposure_times,
                                        int samples = 200, float smoothness = 20.f);

// HDR merge of a bracket into relative scene radiance (CV_32FC3): per pixel and channel a
// weighted mean of exposure / time with a hat weight that ignores clipped values (0, 255).
// Pixels clipped in every exposure take the shortest (if bright) or longest (if black)
// exposure. Same input checks as recover_response_debevec.
cv::Mat merge_hdr(const std::vector<cv::Mat>& images, const std::vector<double>& exposure_times,
                  const CameraResponse& response);

// Maps a CV_8UC3 image through the response to relative linear exposure (CV_32FC3).
cv::Mat linearize(const cv::Mat& image8, const CameraResponse& response);

// JSON: {"format": "lumar-camera-response", "version": 1, "channels": [[256 numbers] x 3]}.
// Throws InputError naming the file when it is missing, malformed, or a table is not
// 256 finite, non-negative, non-decreasing values.
CameraResponse load_camera_response(const std::filesystem::path& path);

// The response a recording's session names: nullopt for "srgb" (the documented default,
// srgb_response), else the response file, a path relative to the recording's folder
// (absolute paths stay absolute). InputError naming the file when it cannot be read.
std::optional<CameraResponse> calibrated_response(const capture::Radiometry& radiometry,
                                                  const std::filesystem::path& recording);
// Writes atomically (temporary file, then rename).
void save_camera_response(const std::filesystem::path& path, const CameraResponse& response);

}  // namespace lumar::calib
