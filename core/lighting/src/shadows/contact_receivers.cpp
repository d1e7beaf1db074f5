#include "lumar/lighting/shadows/contact_receivers.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/error.h"
#include "lumar/lighting/shadows/shadow_receivers.h"

namespace lumar {

namespace {

int thinnest_axis(const SceneBox& b) {
  const glm::dvec3 e = b.max - b.min;
  return e.x <= e.y && e.x <= e.z ? 0 : (e.y <= e.z ? 1 : 2);
}

bool overlap(const SceneBox& a, const SceneBox& b) {
  for (int k = 0; k < 3; ++k)
    if (a.max[k] < b.min[k] || b.max[k] < a.min[k]) return false;
  return true;
}

}  // namespace

std::vector<SceneBox> contact_regions(const std::vector<SceneBox>& receiver_regions,
                                      const std::vector<const Mesh*>& models,
                                      const std::vector<glm::dmat4>& T_world_model, double reach) {
  if (models.size() != T_world_model.size()) throw RuntimeError("contact_regions: one pose per model is needed");
  std::vector<SceneBox> boxes;
  for (const SceneBox& region : receiver_regions) {
    const int a = thinnest_axis(region), u = (a + 1) % 3, v = (a + 2) % 3;
    const double surface = 0.5 * (region.min[a] + region.max[a]);
    for (std::size_t m = 0; m < models.size(); ++m) {
      glm::dvec3 lo(1e300), hi(-1e300);
      bool touches = false;
      for (const glm::vec3& q : models[m]->positions) {
        const glm::dvec3 p(T_world_model[m] * glm::dvec4(glm::dvec3(q), 1.0));
        if (std::abs(p[a] - surface) > reach || p[u] < region.min[u] || p[u] > region.max[u] || p[v] < region.min[v] ||
            p[v] > region.max[v])
          continue;
        lo = glm::min(lo, p), hi = glm::max(hi, p), touches = true;
      }
      if (!touches) continue;
      SceneBox b = region;
      for (const int k : {u, v}) {
        b.min[k] = std::max(region.min[k], lo[k] - reach);
        b.max[k] = std::min(region.max[k], hi[k] + reach);
      }
      boxes.push_back(b);
    }
  }
  // Merge until no two overlap: a point covered twice would get its correction twice.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < boxes.size() && !merged; ++j)
        if (overlap(boxes[i], boxes[j])) {
          boxes[i].min = glm::min(boxes[i].min, boxes[j].min);
          boxes[i].max = glm::max(boxes[i].max, boxes[j].max);
          boxes.erase(boxes.begin() + std::ptrdiff_t(j));
          merged = true;
        }
  }
  return boxes;
}

ContactPatch build_contact_patch(const RayScene& proxy, const Mesh& coarse, const std::vector<SceneBox>& regions,
                                 const ContactSettings& settings) {
  if (!(settings.spacing > 0) || settings.max_vertices < 4)
    throw InputError("contact receivers: the spacing must be positive and at least 4 vertices allowed");
  ContactPatch patch;
  double area = 0;
  for (const SceneBox& b : regions) {
    glm::dvec3 e = b.max - b.min;
    std::sort(&e[0], &e[0] + 3);
    area += e[1] * e[2];
  }
  if (regions.empty() || !(area > 0)) return patch;
  const int target = int(std::min<double>(settings.max_vertices, area / (settings.spacing * settings.spacing)));
  patch.receivers = build_receivers(proxy, regions, std::max(4, target));
  const Mesh& fine = patch.receivers;
  patch.coarse_corners.assign(fine.positions.size(), {0, 0, 0});
  patch.coarse_weights.assign(fine.positions.size(), glm::vec3(0.0f));
  if (fine.positions.empty()) return patch;

  // The coarse triangles near the patch, then each patch vertex against them: the
  // triangle whose plane it lies on (within 1 cm) and whose inside it is.
  constexpr float kSlack = 0.01f;
  auto [lo, hi] = fine.bounds();
  lo -= glm::vec3(kSlack), hi += glm::vec3(kSlack);
  std::vector<std::uint32_t> near;
  for (std::uint32_t t = 0; 3 * t + 2 < coarse.indices.size(); ++t) {
    glm::vec3 a(1e30f), b(-1e30f);
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = coarse.positions[coarse.indices[3 * t + k]];
      a = glm::min(a, p), b = glm::max(b, p);
    }
    if (glm::all(glm::lessThanEqual(a, hi)) && glm::all(glm::lessThanEqual(lo, b))) near.push_back(t);
  }
  for (std::size_t i = 0; i < fine.positions.size(); ++i) {
    const glm::vec3& p = fine.positions[i];
    for (const std::uint32_t t : near) {
      const std::uint32_t c[3] = {coarse.indices[3 * t], coarse.indices[3 * t + 1], coarse.indices[3 * t + 2]};
      const glm::vec3 a = coarse.positions[c[0]], e1 = coarse.positions[c[1]] - a, e2 = coarse.positions[c[2]] - a;
      const glm::vec3 n = glm::cross(e1, e2);
      const float n2 = glm::dot(n, n);
      if (!(n2 > 0)) continue;
      const glm::vec3 d = p - a;
      if (std::abs(glm::dot(d, n)) > kSlack * std::sqrt(n2)) continue;
      const float w1 = glm::dot(glm::cross(d, e2), n) / n2, w2 = glm::dot(glm::cross(e1, d), n) / n2;
      constexpr float kEdge = -1e-4f;
      if (w1 < kEdge || w2 < kEdge || 1.0f - w1 - w2 < kEdge) continue;
      patch.coarse_corners[i] = {c[0], c[1], c[2]};
      patch.coarse_weights[i] = glm::vec3(1.0f - w1 - w2, w1, w2);
      break;
    }
  }
  return patch;
}

std::vector<glm::vec3> ContactPatch::correction(const std::vector<glm::vec3>& patch_attenuation,
                                                const std::vector<glm::vec3>& coarse_attenuation) const {
  if (patch_attenuation.size() != receivers.positions.size())
    throw RuntimeError("contact receivers: one attenuation per patch vertex is needed");
  std::vector<glm::vec3> out(patch_attenuation.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    glm::vec3 interpolated(0.0f);
    const glm::vec3& w = coarse_weights[i];
    for (int k = 0; k < 3; ++k)
      if (w[k] != 0.0f) interpolated += w[k] * coarse_attenuation.at(coarse_corners[i][std::size_t(k)]);
    if (w == glm::vec3(0.0f)) interpolated = glm::vec3(1.0f);  // no coarse shadow drawn here
    for (int c = 0; c < 3; ++c) out[i][c] = interpolated[c] > 1e-3f ? patch_attenuation[i][c] / interpolated[c] : 1.0f;
  }
  return out;
}

}  // namespace lumar
