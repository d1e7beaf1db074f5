#pragma once
// How close a reconstructed environment map is to a reference: the measures that the
// stitching tests, benchmark and docs report.
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "lumar/scene/envmap.h"

namespace lumar::calib {

// Box-filtered (area-weighted within each output pixel) down-sampling to `width`
// (a divisor of map.width); keeps capture position and azimuth offset.
EnvironmentMap downsample_map(const EnvironmentMap& map, int width);

// Median over pixels with mask != 0 (CV_8UC1 or CV_16UC1, map size; empty = all) of
// |Y(a) - Y(b)| / Y(b), Y = Rec. 709 luminance; maps of equal size.
double median_relative_luminance_error(const EnvironmentMap& a, const EnvironmentMap& b,
                                       const cv::Mat& mask = cv::Mat());

// Irradiance E(n) = sum over texels of L * max(0, n . d) * solid angle, brute force,
// in world directions (the map's azimuth offset applied).
glm::dvec3 irradiance_direct(const EnvironmentMap& map, const glm::dvec3& world_normal);

// The share of the sphere's solid angle that a coverage count (CV_16UC1, a lat-long
// map's size; envmap_stitcher.h) saw at least once: 0 to 1.
double sphere_coverage(const cv::Mat& coverage_count);

// `count` unit directions spread evenly over the sphere (Fibonacci lattice).
std::vector<glm::dvec3> fibonacci_directions(int count);

}  // namespace lumar::calib
