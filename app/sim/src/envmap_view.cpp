#include "lumar/sim/envmap_view.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <opencv2/calib3d.hpp>

#include "lumar/base/color.h"
#include "lumar/base/error.h"

namespace lumar::sim {

EnvmapViewRenderer::EnvmapViewRenderer(const CameraIntrinsics& camera, int supersample)
    : camera_(camera), supersample_(supersample) {
  if (!camera.is_valid()) throw InputError("envmap view: invalid camera intrinsics");
  if (supersample < 1 || supersample > 4) throw InputError("envmap view: supersample must be 1..4");
  const int s = supersample;
  std::vector<cv::Point2d> pixels;
  pixels.reserve(std::size_t(camera.width) * camera.height * s * s);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) pixels.emplace_back(x - 0.5 + (i + 0.5) / s, y - 0.5 + (j + 0.5) / s);
  std::vector<cv::Point2d> normalized;
  // Many iterations: the stitcher inverts this with the exact forward model, so a loose
  // undistortion would show up as a lens error no refinement could remove.
  cv::undistortPoints(pixels, normalized, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(),
                      cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 60, 1e-12));
  rays_.resize(normalized.size());
  for (std::size_t k = 0; k < normalized.size(); ++k)
    rays_[k] = glm::vec3(glm::normalize(glm::dvec3(normalized[k].x, normalized[k].y, 1.0)));
}

cv::Mat EnvmapViewRenderer::render(const EnvironmentMap& map, const glm::dquat& R_world_camera) const {
  cv::Mat out(camera_.height, camera_.width, CV_32FC3);
  const glm::dmat3 R = glm::mat3_cast(R_world_camera);
  const int n = supersample_ * supersample_;
  tbb::parallel_for(0, camera_.height, [&](int y) {
    cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < camera_.width; ++x) {
      glm::vec3 sum(0.f);
      const glm::vec3* rays = &rays_[(std::size_t(y) * camera_.width + x) * n];
      for (int k = 0; k < n; ++k) sum += map.radiance(R * glm::dvec3(rays[k]));
      sum /= float(n);
      row[x] = {sum.b, sum.g, sum.r};
    }
  });
  return out;
}

cv::Mat expose_8bit(const cv::Mat& radiance_bgr, const CameraIntrinsics& camera, const SensorModel& s, double exposure,
                    cv::RNG& rng) {
  const double half_diagonal = 0.5 * std::hypot(camera.width, camera.height);
  cv::Mat out(radiance_bgr.size(), CV_8UC3);
  for (int y = 0; y < out.rows; ++y) {
    const cv::Vec3f* in = radiance_bgr.ptr<cv::Vec3f>(y);
    cv::Vec3b* o = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.cols; ++x) {
      const double r2 = (std::pow(x - camera.cx, 2) + std::pow(y - camera.cy, 2)) / (half_diagonal * half_diagonal);
      const double gain = exposure * (1.0 + s.vignetting_a * r2 + s.vignetting_b * r2 * r2);
      for (int c = 0; c < 3; ++c) {
        const double signal = std::max(0.0, double(in[x][c]) * gain);
        const double sigma = std::sqrt(s.shot_noise_gain * std::min(signal, 1.0) + s.read_noise * s.read_noise);
        const double v = signal + rng.gaussian(sigma);
        o[x][c] = cv::saturate_cast<uchar>(std::lround(linear_to_srgb(float(v)) * 255.0f));
      }
    }
  }
  return out;
}

}  // namespace lumar::sim
