#include "lumar/envmap/sweep_path.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

namespace lumar::calib {

glm::dquat sweep_rotation(double s, const SweepPath& path) {
  s = std::clamp(s, 0.0, 1.0);
  const double az = 2.0 * glm::pi<double>() * path.turns * s;
  const double el = glm::radians(path.elevation_min_deg + (path.elevation_max_deg - path.elevation_min_deg) * s);
  const glm::dvec3 forward(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 down = glm::cross(forward, right);
  const glm::dquat level = glm::normalize(glm::quat_cast(glm::dmat3(right, down, forward)));
  const double roll = glm::radians(path.roll_wobble_deg) * std::sin(2.0 * glm::pi<double>() * 7.0 * s);
  return glm::normalize(level * glm::angleAxis(roll, glm::dvec3(0, 0, 1)));
}

}  // namespace lumar::calib
