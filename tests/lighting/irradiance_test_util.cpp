#include "irradiance_test_util.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "lumar/base/latlong.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/room_radiance.h"

namespace lumar::test {

ErrorStats luminance_errors(const std::vector<glm::dvec3>& value, const std::vector<glm::dvec3>& reference) {
  std::vector<double> e(value.size());
  ErrorStats s;
  for (std::size_t i = 0; i < value.size(); ++i) {
    e[i] = std::abs(luminance(value[i]) - luminance(reference[i])) / std::max(luminance(reference[i]), 1e-12);
    s.mean += e[i] / double(value.size());
    s.max = std::max(s.max, e[i]);
  }
  std::sort(e.begin(), e.end());
  s.p99 = e[std::min(e.size() - 1, std::size_t(std::ceil(0.99 * double(e.size()))) - 1)];
  return s;
}

void append_box(Mesh& mesh, const glm::vec3& lo, const glm::vec3& hi, bool inward) {
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  // Counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}};
  const glm::vec3 normals[6] = {{0, 0, -1}, {0, 0, 1}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}};
  for (int f = 0; f < 6; ++f) {
    const auto base = std::uint32_t(mesh.positions.size());
    for (int k = 0; k < 4; ++k) {
      mesh.positions.push_back(c[quads[f][k]]);
      mesh.normals.push_back(inward ? -normals[f] : normals[f]);
    }
    const std::uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; ++k) mesh.indices.push_back(base + (inward ? tri[5 - k] : tri[k]));
  }
}

DividedRoom make_divided_room() {
  DividedRoom room;
  append_box(room.proxy, {-3, 0, -2}, {3, 3, 2}, true);
  append_box(room.proxy, {-2.2f, 0, 0.4f}, {-1.4f, 0.8f, 1.2f}, false);  // table
  append_box(room.proxy, {-0.05f, 0, -2}, {0.05f, 3, 1}, false);         // wall
  append_box(room.proxy, {-0.05f, 2, 1}, {0.05f, 3, 2}, false);          // above the doorway
  room.box_min = {-2.6, 0.0, -1.6};
  room.box_max = {2.6, 1.6, 1.6};

  // What a camera at the capture point sees: the proxy, coloured by surface.
  EnvironmentMap& map = room.map;
  map.width = 512;
  map.height = 256;
  map.capture_position = {-1.5, 1.5, -0.5};
  map.rgb.resize(std::size_t(map.width) * map.height * 3);
  RayScene rays;
  rays.add_static(room.proxy);
  rays.commit();
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, map.width, map.height);
      Ray ray;
      ray.origin = glm::vec3(map.capture_position);
      ray.direction = glm::vec3(d);
      glm::vec3 L(0.05f, 0.05f, 0.05f);
      if (const auto hit = rays.intersect(ray)) {
        const glm::dvec3 x = map.capture_position + d * double(hit->t);
        if (x.x < -2.999 && x.y > 1.2 && x.y < 2.0 && x.z > -0.9 && x.z < -0.3)
          L = {28.0f, 30.0f, 34.0f};
        else if (x.y > 2.999 && glm::length(glm::dvec2(x.x + 1.0, x.z + 0.2)) < 0.06)
          L = {2200.0f, 2000.0f, 1700.0f};
        else if (x.y < 0.001)
          L = {0.04f, 0.03f, 0.02f};
        else if (x.y > 2.999)
          L = {0.08f, 0.08f, 0.08f};
        else
          L = {0.05f + 0.02f * float(x.z > 0), 0.05f, 0.045f};
      }
      float* p = &map.rgb[(std::size_t(r) * map.width + c) * 3];
      p[0] = L.r, p[1] = L.g, p[2] = L.b;
    }
  return room;
}

}  // namespace lumar::test
