#pragma once
// Light sources that a sweep saw clipped in every frame, the shortest exposure too (the
// sun, a bare lamp): the map holds only a lower bound of their radiance, so it under-
// states the light that casts the hardest shadows. Found here, to be reported, with the
// exposure that would hold them.
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/scene/envmap.h"

namespace lumar::calib {

struct ClippedSource {
  glm::dvec3 direction{0.0};    // world, unit: the power-weighted centre
  double azimuth_deg = 0.0;     // of that direction about +Y, from +X towards +Z
  double elevation_deg = 0.0;   // above the horizon
  double solid_angle = 0.0;     // steradians
  double recorded_power = 0.0;  // Σ luminance × Ω as the map holds it: a lower bound
  double recorded_peak = 0.0;   // the brightest clipped sample's luminance: a lower bound
  int pixels = 0;
};

// Connected regions of `clipped` (CV_8UC1, map size, non-zero where every frame
// clipped), brightest recorded power first; regions smaller than `min_pixels` are left
// out (a clipped speck of a specular highlight).
std::vector<ClippedSource> find_clipped_sources(const EnvironmentMap& map, const cv::Mat& clipped, int min_pixels = 1);

// Share of the map's power (Σ luminance × Ω) that its clipped pixels hold as recorded.
double clipped_power_share(const EnvironmentMap& map, const cv::Mat& clipped);

}  // namespace lumar::calib
