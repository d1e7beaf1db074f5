#pragma once
// Directions spread evenly over the unit sphere (a Fibonacci sphere): `count` points on
// rings from +y (world up, conventions.md) down to -y, each turned by the golden angle from
// the last. Used where a fixed set must look every way alike: the irradiance probes' rays,
// the solid wrap's inside test.
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/base/constants.h"

namespace lumar {

inline std::vector<glm::dvec3> fibonacci_directions(int count) {
  std::vector<glm::dvec3> out(std::size_t(std::max(count, 1)));
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int j = 0; j < int(out.size()); ++j) {
    const double y = 1.0 - (2.0 * j + 1.0) / double(out.size());
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    out[std::size_t(j)] = {r * std::cos(golden * j), y, r * std::sin(golden * j)};
  }
  return out;
}

}  // namespace lumar
