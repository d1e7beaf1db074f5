#pragma once
// Stitches a lat-long HDR environment map from 8-bit video frames taken by a camera
// rotating about the map's capture point. Per frame the map pixels inside the frame's
// footprint are resampled by inverse mapping: map direction -> camera ray -> lens
// distortion -> source pixel, bilinear (so no splat holes), through the camera response
// to linear, divided by vignetting and exposure. Blend weights favour the image centre
// and well-exposed values, and grow with exposure squared (noise in radiance goes with
// 1 / exposure); saturated and near-black samples get no weight, and only where nothing
// better saw a pixel does it keep the brightest clipped sample (a lower bound) or the
// darkest black one, so frames of different exposure merge into HDR. The camera image is
// box-filtered down to the map's pixel size before it is sampled. Frames may be added
// one at a time (live sweep) and the current map read at any moment.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/calib/camera_response.h"
#include "lumar/scene/envmap.h"

namespace lumar::calib {

struct StitchSettings {
  int width = 1024;                               // map width; height = width / 2
  CameraIntrinsics camera;                        // calibrated, with distortion
  CameraResponse response = srgb_response(1.0);   // 8-bit value -> linear video value
  double vignetting_a = 0.0, vignetting_b = 0.0;  // gain 1 + a r^2 + b r^4 (r over half-diagonal)
  glm::dvec3 capture_position{0.0};
  double azimuth_offset_deg = 0.0;
  int saturated_value = 250;  // any channel at or above: clipped
  int dark_value = 2;         // every channel at or below: too dark to trust
  double edge_weight = 0.05;  // centre weight at the image corners (1 at the centre)
  bool prefilter = true;      // sample a box-filtered level matching the map's pixel size
};

class EnvmapStitcher {
 public:
  // Throws InputError for a width that is not a positive even number or an invalid camera.
  explicit EnvmapStitcher(const StitchSettings& settings);

  // Adds one frame (CV_8UC3 BGR, the camera's size; else InputError) seen with
  // R_world_camera (OpenCV camera axes) and `exposure` (video linear value per unit
  // radiance). Parallel inside; call from one thread at a time.
  void add_frame(const cv::Mat& image_bgr8, const glm::dquat& R_world_camera, double exposure);

  // The map so far: weighted mean radiance, 0 where nothing was seen.
  EnvironmentMap current_map() const;
  // Sum of blend weights per map pixel (CV_32FC1, height x width).
  cv::Mat weights() const;
  // How many frames saw each map pixel (CV_16UC1, saturating).
  cv::Mat coverage() const;
  // Pixels every frame saw clipped, the shortest exposure included (CV_8UC1, 255): the
  // map holds only a lower bound there (current_map shows the brightest clipped sample).
  cv::Mat clipped() const;
  // Pixels measured only from samples within kNearBlackCode of black (CV_8UC1, 255).
  // There the sensor's noise, which an 8-bit image clips at black, biases the mean up: a
  // studio sweep's darkest regions came out 40 % too bright until an exposure 4 stops
  // longer lifted them (docs/envmap.md).
  cv::Mat near_black() const;
  static constexpr float kNearBlackCode = 16.f;
  int frames_added() const { return frames_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const StitchSettings& settings() const { return settings_; }

 private:
  StitchSettings settings_;
  int width_, height_;
  std::vector<float> directions_;  // unit map-frame direction per map pixel (x, y, z)
  std::vector<float> row_theta_;   // polar angle of each row's centres
  std::vector<float> accum_;       // per pixel: weighted R, G, B, weight
  std::vector<std::uint16_t> count_;
  std::vector<float> peak_code_;  // per pixel: the brightest unclipped sample's 8-bit code
  // Where no sample was well exposed: the brightest clipped sample (a lower bound, from
  // the shortest exposure) or else the darkest near-black one (an upper bound).
  std::vector<float> fallback_;                  // R, G, B per pixel
  std::vector<std::uint8_t> fallback_kind_;      // 0 none, 1 dark, 2 clipped
  std::array<std::array<float, 256>, 3> lut_{};  // BGR channel -> linear
  double max_ray_r2_ = 0;                        // largest squared normalised radius of a ray inside the image
  double cone_half_angle_ = 0;                   // angle from the optical axis that holds every image ray
  // One level of the frame's box pyramid: linear RGB, trust in [0, 1], clipped flag.
  struct Level {
    int width = 0, height = 0;
    std::vector<float> rgb, weight, code;  // code: the brightest channel's 8-bit value
    std::vector<std::uint8_t> clipped;
  };
  void prepare_levels(const cv::Mat& image, double exposure);
  std::vector<Level> levels_;  // scratch, reused from frame to frame
  int level_ = 0;              // which level is sampled
  int frames_ = 0;
  double reference_exposure_ = 1.0;
};

}  // namespace lumar::calib
