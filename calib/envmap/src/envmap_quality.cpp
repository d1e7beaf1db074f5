#include "lumar/envmap/envmap_quality.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"

namespace lumar::calib {

namespace {
double luminance(const float* p) { return lumar::luminance({p[0], p[1], p[2]}); }
}  // namespace

EnvironmentMap downsample_map(const EnvironmentMap& map, int width) {
  if (width <= 0 || map.width % width != 0 || width % 2 != 0)
    throw InputError("envmap: cannot down-sample a " + std::to_string(map.width) + "-wide map to " +
                     std::to_string(width));
  const int f = map.width / width, height = width / 2;
  EnvironmentMap out = map;
  out.width = width;
  out.height = height;
  out.rgb.assign(std::size_t(width) * height * 3, 0.f);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      double sum[3] = {0, 0, 0}, wsum = 0;
      for (int rr = r * f; rr < (r + 1) * f; ++rr) {
        const double w = latlong_pixel_solid_angle(rr, map.width, map.height);
        for (int cc = c * f; cc < (c + 1) * f; ++cc) {
          const float* p = &map.rgb[(std::size_t(rr) * map.width + cc) * 3];
          for (int k = 0; k < 3; ++k) sum[k] += w * p[k];
          wsum += w;
        }
      }
      for (int k = 0; k < 3; ++k) out.rgb[(std::size_t(r) * width + c) * 3 + k] = float(sum[k] / wsum);
    }
  return out;
}

double median_relative_luminance_error(const EnvironmentMap& a, const EnvironmentMap& b, const cv::Mat& mask) {
  if (a.width != b.width || a.height != b.height) throw InputError("envmap: maps of different sizes");
  cv::Mat m;
  if (!mask.empty()) mask.convertTo(m, CV_32F);
  std::vector<double> errors;
  for (int r = 0; r < a.height; ++r)
    for (int c = 0; c < a.width; ++c) {
      if (!m.empty() && m.at<float>(r, c) == 0.f) continue;
      const std::size_t i = (std::size_t(r) * a.width + c) * 3;
      const double yb = luminance(&b.rgb[i]), ya = luminance(&a.rgb[i]);
      errors.push_back(std::abs(ya - yb) / std::max(yb, 1e-9));
    }
  if (errors.empty()) return 0.0;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

glm::dvec3 irradiance_direct(const EnvironmentMap& map, const glm::dvec3& world_normal) {
  const glm::dvec3 n = glm::normalize(map.map_direction(world_normal));
  glm::dvec3 e(0.0);
  for (int r = 0; r < map.height; ++r) {
    const double dw = latlong_pixel_solid_angle(r, map.width, map.height);
    for (int c = 0; c < map.width; ++c) {
      const double cosine = glm::dot(n, latlong_pixel_direction(c, r, map.width, map.height));
      if (cosine <= 0) continue;
      e += glm::dvec3(map.texel(c, r)) * (cosine * dw);
    }
  }
  return e;
}

std::vector<glm::dvec3> fibonacci_directions(int count) {
  std::vector<glm::dvec3> out;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < count; ++k) {
    const double y = 1.0 - 2.0 * (k + 0.5) / count, r = std::sqrt(std::max(0.0, 1.0 - y * y));
    out.emplace_back(r * std::cos(golden * k), y, r * std::sin(golden * k));
  }
  return out;
}

double sphere_coverage(const cv::Mat& coverage_count) {
  if (coverage_count.empty()) return 0.0;
  double seen = 0;
  for (int r = 0; r < coverage_count.rows; ++r) {
    const double w = latlong_pixel_solid_angle(r, coverage_count.cols, coverage_count.rows);
    seen += w * cv::countNonZero(coverage_count.row(r));
  }
  return seen / (4.0 * kPi);
}

}  // namespace lumar::calib
