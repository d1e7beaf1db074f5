#include "shadow_test_util.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumar/base/latlong.h"

namespace lumar::test {

Mesh make_ground(float h, float y) {
  Mesh m;
  m.positions = {{-h, y, -h}, {-h, y, h}, {h, y, h}, {h, y, -h}};
  m.normals.assign(4, glm::vec3(0, 1, 0));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

void floor_grid(float cx, float cz, float half, int n, float height, std::vector<glm::vec3>& positions,
                std::vector<glm::vec3>& normals) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      positions.push_back({cx - half + 2 * half * (i + 0.5f) / n, height, cz - half + 2 * half * (j + 0.5f) / n});
      normals.push_back({0, 1, 0});
    }
}

EnvironmentMap make_sun_sky(int width, double elevation_deg, double azimuth_deg, double radius_deg,
                            float sun_radiance) {
  EnvironmentMap map;
  map.width = width;
  map.height = width / 2;
  map.rgb.resize(std::size_t(map.width) * map.height * 3);
  const double el = elevation_deg * std::numbers::pi / 180, az = azimuth_deg * std::numbers::pi / 180;
  const glm::dvec3 sun(std::cos(el) * std::cos(az), std::sin(el), std::cos(el) * std::sin(az));
  const double cos_r = std::cos(radius_deg * std::numbers::pi / 180);
  // Supersample each pixel 4x4 so the disc's edge is anti-aliased.
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      glm::dvec3 sum(0.0);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const glm::dvec3 d = latlong_direction(c + (a + 0.5) / 4, r + (b + 0.5) / 4, map.width, map.height);
          glm::dvec3 L = d.y > 0 ? glm::dvec3(0.35, 0.5, 0.8) * (0.6 + 0.4 * d.y) : glm::dvec3(0.12, 0.1, 0.08);
          if (glm::dot(d, sun) >= cos_r) L = glm::dvec3(sun_radiance, 0.95 * sun_radiance, 0.85 * sun_radiance);
          sum += L / 16.0;
        }
      float* p = &map.rgb[(std::size_t(r) * map.width + c) * 3];
      p[0] = float(sum.x), p[1] = float(sum.y), p[2] = float(sum.z);
    }
  return map;
}

ShadowError shadow_error(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& ref) {
  ShadowError e;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = std::abs(double(a[i][c]) - ref[i][c]);
      if (ref[i][c] < 0.98)
        e.mean_shadowed += d, ++e.shadowed;
      else
        e.mean_lit += d, ++e.lit;
    }
  if (e.shadowed) e.mean_shadowed /= double(e.shadowed);
  if (e.lit) e.mean_lit /= double(e.lit);
  return e;
}

}  // namespace lumar::test
