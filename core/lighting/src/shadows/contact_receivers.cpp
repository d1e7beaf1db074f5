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

// Where the patch's vertices `which` lie in the coarse receiver mesh: the coarse
// triangles near them, then each vertex against those, the triangle whose plane it lies
// on (within 1 cm) and whose inside it is; weights all 0 where none holds it.
void locate_in(ContactPatch& patch, const Mesh& coarse, const std::vector<std::size_t>& which) {
  const Mesh& fine = patch.receivers;
  for (const std::size_t i : which) patch.coarse_corners[i] = {0, 0, 0}, patch.coarse_weights[i] = glm::vec3(0.0f);
  constexpr float kSlack = 0.01f;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const std::size_t i : which) lo = glm::min(lo, fine.positions[i]), hi = glm::max(hi, fine.positions[i]);
  lo -= glm::vec3(kSlack), hi += glm::vec3(kSlack);
  // The near triangles in a grid of cells as large as their mean box, each in every cell
  // its box (widened by the slack) meets: a vertex then tries a few, not all.
  std::vector<std::uint32_t> near;
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  glm::vec3 mean_size(0.0f);
  for (std::uint32_t t = 0; 3 * t + 2 < coarse.indices.size(); ++t) {
    glm::vec3 a(1e30f), b(-1e30f);
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = coarse.positions[coarse.indices[3 * t + k]];
      a = glm::min(a, p), b = glm::max(b, p);
    }
    if (!glm::all(glm::lessThanEqual(a, hi)) || !glm::all(glm::lessThanEqual(lo, b))) continue;
    near.push_back(t), boxes.emplace_back(a - glm::vec3(kSlack), b + glm::vec3(kSlack));
    mean_size += b - a;
  }
  if (near.empty()) return;
  const float cell = std::max({mean_size.x, mean_size.y, mean_size.z}) / float(near.size()) + kSlack;
  const glm::ivec3 dims = glm::clamp(glm::ivec3((hi - lo) / cell) + 1, 1, 256);
  const auto cell_of = [&](const glm::vec3& p) {
    return glm::clamp(glm::ivec3((p - lo) / cell), glm::ivec3(0), dims - 1);
  };
  std::vector<std::vector<std::uint32_t>> grid(std::size_t(dims.x) * dims.y * dims.z);
  const auto index = [&](const glm::ivec3& c) { return (std::size_t(c.z) * dims.y + c.y) * dims.x + c.x; };
  for (std::size_t j = 0; j < near.size(); ++j) {
    const glm::ivec3 a = cell_of(boxes[j].first), b = cell_of(boxes[j].second);
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) grid[index({x, y, z})].push_back(near[j]);
  }
  for (const std::size_t i : which) {
    const glm::vec3& p = fine.positions[i];
    for (const std::uint32_t t : grid[index(cell_of(p))]) {
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
}

}  // namespace

std::vector<ContactRegion> contact_regions(const std::vector<SceneBox>& receiver_regions,
                                           const std::vector<const Mesh*>& models,
                                           const std::vector<glm::dmat4>& T_world_model, double reach) {
  if (models.size() != T_world_model.size()) throw RuntimeError("contact_regions: one pose per model is needed");
  std::vector<ContactRegion> regions;
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
      regions.push_back({b, int(m)});
    }
  }
  // Merge until no two overlap: a point covered twice would get its correction twice.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < regions.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < regions.size() && !merged; ++j)
        if (overlap(regions[i].box, regions[j].box)) {
          SceneBox& b = regions[i].box;
          b.min = glm::min(b.min, regions[j].box.min);
          b.max = glm::max(b.max, regions[j].box.max);
          if (regions[i].object != regions[j].object) regions[i].object = -1;
          regions.erase(regions.begin() + std::ptrdiff_t(j));
          merged = true;
        }
  }
  return regions;
}

ContactPatch build_contact_patch(const RayScene& proxy, const Mesh& coarse, const std::vector<ContactRegion>& regions,
                                 const ContactSettings& settings) {
  if (!(settings.spacing > 0) || settings.max_vertices < 4)
    throw InputError("contact receivers: the spacing must be positive and at least 4 vertices allowed");
  ContactPatch patch;
  double area = 0;
  std::vector<SceneBox> boxes;
  for (const ContactRegion& region : regions) {
    const SceneBox& b = boxes.emplace_back(region.box);
    glm::dvec3 e = b.max - b.min;
    std::sort(&e[0], &e[0] + 3);
    area += e[1] * e[2];
  }
  if (regions.empty() || !(area > 0)) return patch;
  const int target = int(std::min<double>(settings.max_vertices, area / (settings.spacing * settings.spacing)));
  patch.receivers = build_receivers(proxy, boxes, std::max(4, target));
  const Mesh& fine = patch.receivers;
  patch.owner.assign(fine.positions.size(), -1);
  if (fine.positions.empty()) return patch;
  // The owner: the region the vertex lies over (regions do not overlap; along the
  // region's thin axis the vertex was dropped onto the proxy, within the slab).
  std::vector<std::size_t> region_of(fine.positions.size(), 0);
  for (std::size_t i = 0; i < fine.positions.size(); ++i) {
    const glm::dvec3 p(fine.positions[i]);
    double nearest = 1e300;
    for (std::size_t r = 0; r < regions.size(); ++r) {
      const double d = glm::length(glm::clamp(p, regions[r].box.min, regions[r].box.max) - p);
      if (d < nearest) nearest = d, region_of[i] = r, patch.owner[i] = regions[r].object;
    }
  }

  // Per region: the coarse triangles near each region's vertices, not near all of them.
  patch.coarse_corners.assign(fine.positions.size(), {0, 0, 0});
  patch.coarse_weights.assign(fine.positions.size(), glm::vec3(0.0f));
  std::vector<std::vector<std::size_t>> by_region(regions.size());
  for (std::size_t i = 0; i < fine.positions.size(); ++i) by_region[region_of[i]].push_back(i);
  for (const auto& which : by_region) locate_in(patch, coarse, which);
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

ContactPatch ContactPatch::carried(std::span<const glm::dmat4> moved, const Mesh& coarse, double tolerance,
                                   double max_turn_rad) const {
  ContactPatch out;
  out.owner = owner;
  out.coarse_corners = coarse_corners, out.coarse_weights = coarse_weights;
  Mesh& carried = out.receivers;
  carried.positions = receivers.positions, carried.normals = receivers.normals;
  const double min_cos = std::cos(max_turn_rad);
  // A merged region's vertices stay only while no object moved: its objects no longer
  // stand where it was built.
  const bool any_moved =
      std::any_of(moved.begin(), moved.end(), [](const glm::dmat4& d) { return d != glm::dmat4(1.0); });
  std::vector<char> kept(carried.positions.size(), 0);
  std::vector<std::vector<std::size_t>> moved_vertices(moved.size());  // per object: to locate again
  for (std::size_t i = 0; i < carried.positions.size(); ++i) {
    const int k = owner.at(i);
    const glm::dmat4 m = k >= 0 && std::size_t(k) < moved.size() ? moved[std::size_t(k)] : glm::dmat4(1.0);
    if (k < 0 && any_moved) continue;
    const glm::dvec3 p(receivers.positions[i]), n(receivers.normals[i]);
    const glm::dvec3 q(m * glm::dvec4(p, 1.0));
    const glm::dvec3 turned = glm::normalize(glm::dmat3(m) * n);  // a rigid move: no inverse transpose
    if (glm::dot(turned, n) < min_cos || std::abs(glm::dot(q - p, n)) > tolerance) continue;
    carried.positions[i] = glm::vec3(q), carried.normals[i] = glm::vec3(turned);
    kept[i] = 1;
    if (m != glm::dmat4(1.0)) moved_vertices[std::size_t(k)].push_back(i);
  }
  for (std::size_t t = 0; 3 * t + 2 < receivers.indices.size(); ++t) {
    const std::uint32_t* c = &receivers.indices[3 * t];
    if (kept[c[0]] && kept[c[1]] && kept[c[2]]) carried.indices.insert(carried.indices.end(), c, c + 3);
  }
  for (const auto& which : moved_vertices) locate_in(out, coarse, which);
  return out;
}

std::vector<glm::vec3> carried_correction(const std::vector<glm::vec3>& now, const std::vector<glm::vec3>& built,
                                          float width) {
  if (now.size() != built.size()) throw RuntimeError("contact receivers: one built correction per vertex is needed");
  if (!(width > 0)) throw InputError("contact receivers: the carried correction's blend width must be positive");
  std::vector<glm::vec3> out(now.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float w = std::min(1.0f, std::abs(1.0f - built[i].g) / width);
    out[i] = (1.0f - w) * built[i] + w * now[i];
  }
  return out;
}

}  // namespace lumar
