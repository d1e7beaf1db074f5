#include "test_geometry.h"

#include <cmath>
#include <numbers>
#include <random>

namespace lumar::test {

Mesh make_sphere(const glm::vec3& centre, float radius, int slices, int stacks) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = std::numbers::pi * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / slices;
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(centre + radius * n);
      m.normals.push_back(n);
    }
  }
  const auto index = [&](int i, int j) { return std::uint32_t(i * (slices + 1) + j); };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      m.indices.insert(m.indices.end(), {index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return m;
}

Mesh make_box(const glm::vec3& lo, const glm::vec3& hi, bool inward, int cells) {
  Mesh m;
  // Each face: outward normal axis/sign, a (cells + 1)² grid of corners.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      glm::vec3 n(0.0f);
      n[axis] = side ? 1.0f : -1.0f;
      const std::uint32_t base = std::uint32_t(m.positions.size());
      for (int i = 0; i <= cells; ++i)
        for (int j = 0; j <= cells; ++j) {
          glm::vec3 p;
          p[axis] = side ? hi[axis] : lo[axis];
          p[u] = lo[u] + (hi[u] - lo[u]) * float(i) / float(cells);
          p[v] = lo[v] + (hi[v] - lo[v]) * float(j) / float(cells);
          m.positions.push_back(p);
          m.normals.push_back(inward ? -n : n);
        }
      const auto at = [&](int i, int j) { return base + std::uint32_t(i * (cells + 1) + j); };
      for (int i = 0; i < cells; ++i)
        for (int j = 0; j < cells; ++j) {
          // Corners a-b-c-d run counter-clockwise seen from +axis; reverse them where the
          // front (the side the normal points to) faces the other way.
          const std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
          if ((side == 1) != inward)
            m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
          else
            m.indices.insert(m.indices.end(), {a, c, b, a, d, c});
        }
    }
  return m;
}

Mesh make_quad(const glm::vec3& centre, const glm::vec3& a, const glm::vec3& b, const glm::vec3& normal) {
  Mesh m;
  m.positions = {centre - a - b, centre + a - b, centre + a + b, centre - a + b};
  m.normals.assign(4, glm::normalize(normal));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

std::vector<glm::dvec3> random_normals(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<glm::dvec3> out;
  while (int(out.size()) < count) {
    const glm::dvec3 v(g(rng), g(rng), g(rng));
    if (glm::length(v) > 1e-6) out.push_back(glm::normalize(v));
  }
  return out;
}

EnvironmentMap dim_sky_with_sun() {
  EnvironmentMap map;
  map.width = 256, map.height = 128;
  map.rgb.assign(std::size_t(map.width) * map.height * 3, 0.2f);
  for (int r = 30; r < 33; ++r)
    for (int c = 40; c < 43; ++c)
      for (int k = 0; k < 3; ++k) map.rgb[(std::size_t(r) * map.width + c) * 3 + std::size_t(k)] = 4000.0f;
  return map;
}

}  // namespace lumar::test
