#include "lumar/base/latlong.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lumar {

glm::dvec3 latlong_direction(double u, double v, int width, int height) {
  const double phi = 2.0 * std::numbers::pi * u / width;
  const double theta = std::numbers::pi * v / height;
  const double st = std::sin(theta);
  return {st * std::cos(phi), std::cos(theta), st * std::sin(phi)};
}

glm::dvec2 latlong_coordinates(const glm::dvec3& direction, int width, int height) {
  const glm::dvec3 d = glm::normalize(direction);
  double phi = std::atan2(d.z, d.x);
  if (phi < 0) phi += 2.0 * std::numbers::pi;
  const double theta = std::acos(std::clamp(d.y, -1.0, 1.0));
  double u = phi / (2.0 * std::numbers::pi) * width;
  if (u >= width) u -= width;
  return {u, theta / std::numbers::pi * height};
}

double latlong_pixel_solid_angle(int row, int width, int height) {
  const double t0 = std::numbers::pi * row / height, t1 = std::numbers::pi * (row + 1) / height;
  return (std::cos(t0) - std::cos(t1)) * 2.0 * std::numbers::pi / width;
}

}  // namespace lumar
