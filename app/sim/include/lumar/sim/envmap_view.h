#pragma once
// What a calibrated camera sitting at a map's capture point sees of the map alone (the
// map at infinity, so only the camera's rotation matters), and how its sensor records
// that radiance as 8-bit video. Used to synthesise sweeps whose truth is known.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/scene/envmap.h"

namespace lumar::sim {

class EnvmapViewRenderer {
 public:
  // `camera` with its lens distortion; `supersample` rays per pixel side (box filter).
  // Throws InputError for an invalid camera or supersample outside 1..4.
  explicit EnvmapViewRenderer(const CameraIntrinsics& camera, int supersample = 1);

  // Linear radiance (CV_32FC3, BGR, the camera's size) seen with rotation R_world_camera
  // (OpenCV camera axes); the map's azimuth offset is honoured.
  cv::Mat render(const EnvironmentMap& map, const glm::dquat& R_world_camera) const;

  const CameraIntrinsics& camera() const { return camera_; }

 private:
  CameraIntrinsics camera_;
  int supersample_;
  std::vector<glm::vec3> rays_;  // unit camera-frame rays, supersample^2 per pixel
};

// The sensor between radiance and 8-bit video (sRGB response with gain `exposure`,
// vignetting gain 1 + a r^2 + b r^4 with r over the half-diagonal, Gaussian shot and
// read noise in linear units, clipping, rounding).
struct SensorModel {
  double read_noise = 0.002;        // linear standard deviation
  double shot_noise_gain = 0.0004;  // variance per unit of linear signal
  double vignetting_a = -0.30, vignetting_b = 0.05;
};

// Radiance (CV_32FC3 BGR, scene units) to the CV_8UC3 frame the camera records with
// `exposure` (video linear value per unit radiance). Draws noise from `rng` pixel by
// pixel, channel by channel.
cv::Mat expose_8bit(const cv::Mat& radiance_bgr, const CameraIntrinsics& camera, const SensorModel& sensor,
                    double exposure, cv::RNG& rng);

}  // namespace lumar::sim
