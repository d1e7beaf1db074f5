#include "lumar/lighting/shadows/shadow_receivers.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/error.h"

namespace lumar {

std::vector<SceneBox> default_receiver_regions(const Scene& scene, const Mesh& room_world, double margin) {
  if (room_world.triangle_count() == 0) return {};
  const auto [lo, hi] = room_world.bounds();
  SceneBox b;
  b.min = glm::max(scene.movement_min - glm::dvec3(margin), glm::dvec3(lo));
  b.max = glm::min(scene.movement_max + glm::dvec3(margin), glm::dvec3(hi));
  b.min.y = lo.y - 0.01;
  b.max.y = lo.y + 0.01;
  if (b.min.x > b.max.x || b.min.z > b.max.z) return {};
  return {b};
}

Mesh build_receivers(const RayScene& proxy, const std::vector<SceneBox>& regions, int target_vertices) {
  if (target_vertices < 4) throw InputError("build_receivers: need at least 4 receiver vertices");
  Mesh out;
  if (proxy.empty() || regions.empty()) return out;
  double area = 0;
  for (const SceneBox& b : regions) {
    glm::dvec3 e = b.max - b.min;
    std::sort(&e[0], &e[0] + 3);
    area += e[1] * e[2];
  }
  if (!(area > 0)) return out;
  const double spacing = std::sqrt(area / target_vertices);

  for (const SceneBox& b : regions) {
    const glm::dvec3 e = b.max - b.min;
    const int a = e.x <= e.y && e.x <= e.z ? 0 : (e.y <= e.z ? 1 : 2);  // thinnest: cast along it
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const int nu = std::max(2, int(std::lround(e[u] / spacing)) + 1);
    const int nv = std::max(2, int(std::lround(e[v] / spacing)) + 1);
    std::vector<std::int64_t> index(std::size_t(nu) * nv, -1);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        glm::dvec3 p;
        p[u] = b.min[u] + e[u] * i / (nu - 1);
        p[v] = b.min[v] + e[v] * j / (nv - 1);
        p[a] = b.max[a];
        glm::vec3 dir(0.0f);
        dir[a] = -1.0f;
        const auto hit = proxy.intersect(Ray{glm::vec3(p), 0.0f, dir, float(e[a])});
        if (!hit) continue;
        index[std::size_t(i) * nv + j] = std::int64_t(out.positions.size());
        out.positions.push_back(glm::vec3(p) + hit->t * dir);
        out.normals.push_back(hit->normal);
      }
    for (int i = 0; i + 1 < nu; ++i)
      for (int j = 0; j + 1 < nv; ++j) {
        const std::int64_t q[4] = {index[std::size_t(i) * nv + j], index[std::size_t(i + 1) * nv + j],
                                   index[std::size_t(i + 1) * nv + j + 1], index[std::size_t(i) * nv + j + 1]};
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[3] < 0) continue;
        // Counter-clockwise seen from the side the normal points to.
        const glm::vec3 n = out.normals[std::size_t(q[0])];
        const glm::vec3 c = glm::cross(out.positions[std::size_t(q[1])] - out.positions[std::size_t(q[0])],
                                       out.positions[std::size_t(q[2])] - out.positions[std::size_t(q[0])]);
        const bool flip = glm::dot(c, n) < 0;
        const std::uint32_t t[6] = {std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2]),
                                    std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])};
        if (flip)
          out.indices.insert(out.indices.end(), {t[0], t[2], t[1], t[3], t[5], t[4]});
        else
          out.indices.insert(out.indices.end(), t, t + 6);
      }
  }
  return out;
}

}  // namespace lumar
