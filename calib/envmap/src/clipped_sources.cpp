#include "lumar/envmap/clipped_sources.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "lumar/base/color.h"
#include "lumar/base/latlong.h"

namespace lumar::calib {

std::vector<ClippedSource> find_clipped_sources(const EnvironmentMap& map, const cv::Mat& clipped, int min_pixels) {
  std::vector<ClippedSource> out;
  if (clipped.empty() || cv::countNonZero(clipped) == 0) return out;
  cv::Mat labels;
  const int n = cv::connectedComponents(clipped != 0, labels, 8, CV_32S);
  std::vector<ClippedSource> sources(std::size_t(std::max(0, n)));
  std::vector<glm::dvec3> weighted(sources.size(), glm::dvec3(0.0));
  for (int r = 0; r < map.height; ++r) {
    const double omega = latlong_pixel_solid_angle(r, map.width, map.height);
    for (int c = 0; c < map.width; ++c) {
      const int label = labels.at<int>(r, c);
      if (label <= 0) continue;
      ClippedSource& s = sources[std::size_t(label)];
      const double L = luminance(map.texel(c, r));
      s.solid_angle += omega;
      s.recorded_power += L * omega;
      s.recorded_peak = std::max(s.recorded_peak, L);
      ++s.pixels;
      weighted[std::size_t(label)] +=
          (L * omega + 1e-12) * map.world_direction(latlong_pixel_direction(c, r, map.width, map.height));
    }
  }
  // Components touching both the left and the right edge are one source wrapped in azimuth;
  // they are rare and small, and reported as two.
  for (int label = 1; label < n; ++label) {
    ClippedSource& s = sources[std::size_t(label)];
    if (s.pixels < min_pixels) continue;
    s.direction = glm::normalize(weighted[std::size_t(label)]);
    s.azimuth_deg = glm::degrees(std::atan2(s.direction.z, s.direction.x));
    s.elevation_deg = glm::degrees(std::asin(std::clamp(s.direction.y, -1.0, 1.0)));
    out.push_back(s);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.recorded_power > b.recorded_power; });
  return out;
}

double clipped_power_share(const EnvironmentMap& map, const cv::Mat& clipped) {
  double all = 0, in_clipped = 0;
  for (int r = 0; r < map.height; ++r) {
    const double omega = latlong_pixel_solid_angle(r, map.width, map.height);
    for (int c = 0; c < map.width; ++c) {
      const double p = luminance(map.texel(c, r)) * omega;
      all += p;
      if (clipped.at<std::uint8_t>(r, c)) in_clipped += p;
    }
  }
  return all > 0 ? in_clipped / all : 0.0;
}

}  // namespace lumar::calib
