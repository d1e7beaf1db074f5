#include "lumar/calib/camera_response.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/photo.hpp>
#include <string>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/base/output_file.h"

namespace lumar::calib {
namespace {

void check_bracket(const std::vector<cv::Mat>& images, const std::vector<double>& times) {
  if (images.size() < 2)
    throw InputError("exposure bracket: " + std::to_string(images.size()) +
                     " image(s) given; give at least 2 exposures of the same scene");
  if (images.size() != times.size())
    throw InputError("exposure bracket: " + std::to_string(images.size()) + " images but " +
                     std::to_string(times.size()) + " exposure times; give one time per image");
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].empty() || images[i].type() != CV_8UC3)
      throw InputError("exposure bracket: image " + std::to_string(i) +
                       " is empty or not 8-bit 3-channel; give 8-bit colour images");
    if (images[i].size() != images[0].size())
      throw InputError("exposure bracket: image " + std::to_string(i) + " is " + std::to_string(images[i].cols) + "x" +
                       std::to_string(images[i].rows) + " but image 0 is " + std::to_string(images[0].cols) + "x" +
                       std::to_string(images[0].rows) + "; give images of one size");
    if (!(times[i] > 0.0) || !std::isfinite(times[i]))
      throw InputError("exposure bracket: exposure time " + std::to_string(i) + " is " + std::to_string(times[i]) +
                       "; give positive exposure times in seconds");
  }
}

// Debevec's hat: full trust mid-range, none at the clipped ends.
float hat(int z) { return float(std::min(z, 255 - z)); }

}  // namespace

CameraResponse srgb_response(double gain) {
  if (!(gain > 0.0) || !std::isfinite(gain))
    throw InputError("camera response: gain " + std::to_string(gain) + " must be positive");
  CameraResponse r;
  for (int v = 0; v < 256; ++v) {
    const float e = float(double(srgb_to_linear(float(v) / 255.f)) / gain);
    for (auto& channel : r.exposure) channel[size_t(v)] = e;
  }
  return r;
}

CameraResponse recover_response_debevec(const std::vector<cv::Mat>& images, const std::vector<double>& exposure_times,
                                        int samples, float smoothness) {
  check_bracket(images, exposure_times);
  std::vector<float> times(exposure_times.begin(), exposure_times.end());
  cv::Mat curve;
  // Grid sampling (random = false) keeps the result reproducible.
  cv::createCalibrateDebevec(samples, smoothness, false)->process(images, curve, times);
  CameraResponse r;
  for (int c = 0; c < 3; ++c) {
    const float mid = curve.at<cv::Vec3f>(128)[c];
    for (int v = 0; v < 256; ++v) r.exposure[size_t(c)][size_t(v)] = curve.at<cv::Vec3f>(v)[c] / mid;
  }
  return r;
}

cv::Mat merge_hdr(const std::vector<cv::Mat>& images, const std::vector<double>& exposure_times,
                  const CameraResponse& response) {
  check_bracket(images, exposure_times);
  const size_t shortest =
      size_t(std::min_element(exposure_times.begin(), exposure_times.end()) - exposure_times.begin());
  const size_t longest =
      size_t(std::max_element(exposure_times.begin(), exposure_times.end()) - exposure_times.begin());
  cv::Mat out(images[0].size(), CV_32FC3);
  cv::parallel_for_(cv::Range(0, out.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      cv::Vec3f* dst = out.ptr<cv::Vec3f>(y);
      for (int x = 0; x < out.cols; ++x) {
        for (int c = 0; c < 3; ++c) {
          double sum = 0.0, weights = 0.0;
          for (size_t i = 0; i < images.size(); ++i) {
            const int z = images[i].ptr<cv::Vec3b>(y)[x][c];
            const double w = hat(z);
            sum += w * response(c, z) / exposure_times[i];
            weights += w;
          }
          if (weights > 0.0) {
            dst[x][c] = float(sum / weights);
          } else {
            // Clipped everywhere: the best bound is the exposure closest to unclipped.
            const size_t i = images[shortest].ptr<cv::Vec3b>(y)[x][c] >= 128 ? shortest : longest;
            dst[x][c] = float(response(c, images[i].ptr<cv::Vec3b>(y)[x][c]) / exposure_times[i]);
          }
        }
      }
    }
  });
  return out;
}

cv::Mat linearize(const cv::Mat& image8, const CameraResponse& response) {
  if (image8.empty() || image8.type() != CV_8UC3)
    throw InputError("linearize: image is empty or not 8-bit 3-channel; give an 8-bit colour image");
  cv::Mat lut(1, 256, CV_32FC3);
  for (int v = 0; v < 256; ++v) lut.at<cv::Vec3f>(v) = {response(0, v), response(1, v), response(2, v)};
  cv::Mat out;
  cv::LUT(image8, lut, out);
  return out;
}

CameraResponse load_camera_response(const std::filesystem::path& path) {
  const std::string name = path.string();
  const nlohmann::json j = read_json_file(path, "camera response file");
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (!j.is_object() || format == j.end() || *format != "lumar-camera-response")
    throw InputError(name + ": not a camera response file (\"format\" must be \"lumar-camera-response\")");
  const auto channels = j.find("channels");
  if (channels == j.end() || !channels->is_array() || channels->size() != 3)
    throw InputError(name + ": \"channels\" must be an array of 3 tables of 256 numbers");
  CameraResponse r;
  for (size_t c = 0; c < 3; ++c) {
    const auto& table = (*channels)[c];
    if (!table.is_array() || table.size() != 256)
      throw InputError(name + ": channel " + std::to_string(c) + " must hold 256 numbers");
    for (size_t v = 0; v < 256; ++v) {
      if (!table[v].is_number())
        throw InputError(name + ": channel " + std::to_string(c) + " value " + std::to_string(v) + " is not a number");
      const double e = table[v].get<double>();
      if (!std::isfinite(e) || e < 0.0 || (v > 0 && e < r.exposure[c][v - 1]))
        throw InputError(name + ": channel " + std::to_string(c) + " value " + std::to_string(v) +
                         " is negative, not finite or decreasing; a response must be non-decreasing");
      r.exposure[c][v] = float(e);
    }
  }
  return r;
}

void save_camera_response(const std::filesystem::path& path, const CameraResponse& response) {
  nlohmann::json j;
  j["format"] = "lumar-camera-response";
  j["version"] = 1;
  j["channels"] = nlohmann::json::array();
  for (const auto& channel : response.exposure) j["channels"].push_back(channel);
  write_file_atomically(path, j.dump() + "\n");
}

std::optional<CameraResponse> calibrated_response(const capture::Radiometry& radiometry,
                                                  const std::filesystem::path& recording) {
  if (radiometry.response.empty() || radiometry.response == "srgb") return std::nullopt;
  return load_camera_response(recording / radiometry.response);  // an absolute path stays absolute
}

}  // namespace lumar::calib
