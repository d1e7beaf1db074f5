#pragma once
// Directions for the Monte Carlo references (irradiance_reference, composite_reference):
// one frame, one cosine-weighted mapping and one seed rule, so both draw alike.
#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>

#include "lumar/base/constants.h"

namespace lumar {

// An orthonormal frame (t, b, n) around unit n (Duff et al. 2017).
inline void orthonormal_basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  const double s = n.z >= 0.0 ? 1.0 : -1.0;
  const double a = -1.0 / (s + n.z), c = n.x * n.y * a;
  t = {1.0 + s * n.x * n.x * a, s * c, -s * n.x};
  b = {c, s + n.y * n.y * a, -n.y};
}

// The cosine-weighted direction around n for (u1, u2) in [0, 1)²: pdf cos/π.
inline glm::dvec3 cosine_direction(const glm::dvec3& n, const glm::dvec3& t, const glm::dvec3& b, double u1,
                                   double u2) {
  const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  return glm::normalize(t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(1.0 - u1));
}

// The uniform direction within the cone around unit axis a (frame t, b, a) of
// cos(half-angle) cos_max, for (u1, u2) in [0, 1)²: pdf 1 / (2π (1 − cos_max)).
inline glm::dvec3 cone_direction(const glm::dvec3& a, const glm::dvec3& t, const glm::dvec3& b, double cos_max,
                                 double u1, double u2) {
  const double c = 1.0 - u1 * (1.0 - cos_max), s = std::sqrt(std::max(0.0, 1.0 - c * c)), phi = 2.0 * kPi * u2;
  return glm::normalize(t * (s * std::cos(phi)) + b * (s * std::sin(phi)) + a * c);
}

// A seed from a query point and normal, so that a reference gives the same answer for
// the same query in any order and on any thread.
inline std::uint32_t query_seed(const glm::dvec3& p, const glm::dvec3& n) {
  return std::uint32_t(std::hash<double>{}(p.x * 1e3 + p.y * 7e3 + p.z * 13e3 + n.x * 3 + n.y * 5 + n.z * 11));
}

}  // namespace lumar
