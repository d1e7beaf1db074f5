#pragma once
// Octahedral maps of directions (DDGI, Majercik et al. 2019): a unit direction folds to
// a point of [-1, 1]^2; an N x N map stores texel (i, j) at the centre
// ((i + ½)/N · 2 − 1, (j + ½)/N · 2 − 1). In an atlas each probe owns an (N+2)^2 block:
// the map plus a one-texel border that repeats the opposite edges (DDGI's layout), so
// bilinear filtering inside a block is seamless across the octahedron's folds.
// The GLSL in core/render/src/irradiance_textures.cpp does the same arithmetic.
#include <cmath>
#include <glm/glm.hpp>

namespace lumar {

inline double sign_not_zero(double v) { return v >= 0.0 ? 1.0 : -1.0; }

inline glm::dvec2 octahedral_encode(const glm::dvec3& d) {
  const double l1 = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
  glm::dvec2 e(d.x / l1, d.z / l1);
  if (d.y < 0.0) e = glm::dvec2((1.0 - std::abs(e.y)) * sign_not_zero(e.x), (1.0 - std::abs(e.x)) * sign_not_zero(e.y));
  return e;
}

inline glm::dvec3 octahedral_decode(const glm::dvec2& e) {
  glm::dvec3 v(e.x, 1.0 - std::abs(e.x) - std::abs(e.y), e.y);
  if (v.y < 0.0) {
    const double x = v.x, z = v.z;
    v.x = (1.0 - std::abs(z)) * sign_not_zero(x);
    v.z = (1.0 - std::abs(x)) * sign_not_zero(z);
  }
  return glm::normalize(v);
}

inline glm::dvec3 octahedral_texel_direction(int i, int j, int n) {
  return octahedral_decode({(i + 0.5) / n * 2.0 - 1.0, (j + 0.5) / n * 2.0 - 1.0});
}

// Interior texel (i, j) of an N x N map to its block coordinates, with the border rule:
// block texel (x, y), x, y in [0, N+1], shows interior texel border_source(x, y).
inline glm::ivec2 octahedral_border_source(int x, int y, int n) {
  int i = x - 1, j = y - 1;
  if (y == 0 || y == n + 1) {
    i = n - 1 - i;
    j = (y == 0) ? 0 : n - 1;
  }
  if (x == 0 || x == n + 1) {
    j = n - 1 - (y - 1);
    if (y == 0 || y == n + 1) j = (y == 0) ? n - 1 : 0;
    i = (x == 0) ? 0 : n - 1;
    if (y == 0 || y == n + 1) i = (x == 0) ? n - 1 : 0;
  }
  return {i, j};
}

}  // namespace lumar
