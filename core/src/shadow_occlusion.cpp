#include "lumar/core/shadow_occlusion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "lumar/core/error.h"

namespace lumar {

bool shaft_touches_sphere(const glm::vec3& a, float ra, const glm::vec3& b, float rb, const glm::vec3& o, float ro) {
  // Every segment from sphere A to sphere B lies within radius ra + t (rb - ra) of the
  // axis point a + t (b - a) (convex combination). Minimise the convex
  // g(u) = |o - axis(u)| - r(u) over the axis length u in [0, L] in closed form.
  const glm::vec3 ab = b - a;
  const float L = glm::length(ab);
  const glm::vec3 ao = o - a;
  if (L < 1e-6f) return glm::length(ao) <= std::max(ra, rb) + ro;
  const glm::vec3 axis = ab / L;
  const float s = glm::dot(ao, axis);
  const float q = std::sqrt(std::max(0.0f, glm::dot(ao, ao) - s * s));
  const float k = (rb - ra) / L;
  float u;
  if (k >= 1.0f) u = L;
  else if (k <= -1.0f) u = 0.0f;
  else u = std::clamp(s + k * q / std::sqrt(1.0f - k * k), 0.0f, L);
  const float g = std::sqrt((s - u) * (s - u) + q * q) - (ra + k * u);
  return g <= ro;
}

LineShadows::LineShadows(ShadowLines lines) : lines_(std::move(lines)) {
  attenuation_.assign(lines_.receiver_count(), glm::vec3(1.0f));
  ray_state_.assign(lines_.lines.size(), kEmpty);
}

namespace {

using Sphere = LineShadows::Sphere;

// A sphere tree over the mesh's triangles (median split of their centroids). Only its
// root (the bounding sphere) is used by the culling now: on the figurine, testing lines
// against deeper levels cost more than it saved (docs/shadows.md).
constexpr int kPartDepth = 3;
std::int32_t build_parts(const Mesh& m, std::vector<std::uint32_t>& tris, std::size_t b, std::size_t e, int depth,
                         std::vector<Sphere>& out) {
  const auto id = std::int32_t(out.size());
  out.emplace_back();
  glm::vec3 lo(1e30f), hi(-1e30f), clo(1e30f), chi(-1e30f);
  for (std::size_t k = b; k < e; ++k) {
    glm::vec3 c(0.0f);
    for (int v = 0; v < 3; ++v) {
      const glm::vec3& p = m.positions[m.indices[3 * tris[k] + v]];
      lo = glm::min(lo, p), hi = glm::max(hi, p), c += p / 3.0f;
    }
    clo = glm::min(clo, c), chi = glm::max(chi, c);
  }
  Sphere s;
  s.centre = 0.5f * (lo + hi);
  for (std::size_t k = b; k < e; ++k)
    for (int v = 0; v < 3; ++v)
      s.radius = std::max(s.radius, glm::length(m.positions[m.indices[3 * tris[k] + v]] - s.centre));
  s.radius = s.radius * 1.0001f + 1e-6f;
  out[std::size_t(id)] = s;
  if (depth == 0 || e - b < 8) return id;
  const glm::vec3 ext = chi - clo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const auto centroid = [&](std::uint32_t t) {
    return m.positions[m.indices[3 * t]][axis] + m.positions[m.indices[3 * t + 1]][axis] +
           m.positions[m.indices[3 * t + 2]][axis];
  };
  const std::size_t mid = (b + e) / 2;
  std::nth_element(tris.begin() + std::ptrdiff_t(b), tris.begin() + std::ptrdiff_t(mid), tris.begin() + std::ptrdiff_t(e),
                   [&](std::uint32_t x, std::uint32_t y) { return centroid(x) < centroid(y); });
  const std::int32_t left = build_parts(m, tris, b, mid, depth - 1, out);
  const std::int32_t right = build_parts(m, tris, mid, e, depth - 1, out);
  out[std::size_t(id)].child[0] = left;
  out[std::size_t(id)].child[1] = right;
  return id;
}

// Grid cells along the box's longest side; a finer grid rejects more lines but costs a
// longer walk per line.
constexpr int kGridCells = 32;

// Marks every voxel a triangle may touch (its box, then its plane against the voxel),
// dilated by a small margin so a line that grazes a voxel boundary in floating point
// still finds the voxel; empty voxels that the outside cannot reach and that a parity
// test finds inside the mesh become kInside.
void voxelize(const Mesh& m, const glm::vec3& lo, const glm::ivec3& n, const glm::vec3& cell,
              std::vector<std::uint8_t>& vox) {
  using V = LineShadows;
  vox.assign(std::size_t(n.x) * n.y * n.z, V::kEmpty);
  const auto index = [&](int x, int y, int z) { return (std::size_t(z) * n.y + y) * n.x + x; };
  const glm::vec3 margin = 0.02f * cell;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                    c = m.positions[m.indices[3 * t + 2]];
    const glm::vec3 tlo = glm::min(a, glm::min(b, c)) - margin, thi = glm::max(a, glm::max(b, c)) + margin;
    const glm::ivec3 i0 = glm::clamp(glm::ivec3(glm::floor((tlo - lo) / cell)), glm::ivec3(0), n - 1);
    const glm::ivec3 i1 = glm::clamp(glm::ivec3(glm::floor((thi - lo) / cell)), glm::ivec3(0), n - 1);
    const glm::vec3 normal = glm::cross(b - a, c - a);
    const glm::vec3 h = 0.5f * cell + margin;
    const float reach = glm::dot(glm::abs(normal), h);
    for (int z = i0.z; z <= i1.z; ++z)
      for (int y = i0.y; y <= i1.y; ++y)
        for (int x = i0.x; x <= i1.x; ++x) {
          const glm::vec3 centre = lo + (glm::vec3(x, y, z) + 0.5f) * cell;
          if (std::abs(glm::dot(normal, centre - a)) <= reach * 1.001f + 1e-12f) vox[index(x, y, z)] = V::kSurface;
        }
  }
  // Empty voxels reachable from the grid's border through empty voxels are outside.
  constexpr std::uint8_t kOutside = 3;
  std::vector<glm::ivec3> stack;
  const auto seed = [&](int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= n.x || y >= n.y || z >= n.z) return;
    std::uint8_t& v = vox[index(x, y, z)];
    if (v == V::kEmpty) {
      v = kOutside;
      stack.push_back({x, y, z});
    }
  };
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x)
        if (x == 0 || y == 0 || z == 0 || x == n.x - 1 || y == n.y - 1 || z == n.z - 1) seed(x, y, z);
  while (!stack.empty()) {
    const glm::ivec3 v = stack.back();
    stack.pop_back();
    seed(v.x - 1, v.y, v.z), seed(v.x + 1, v.y, v.z), seed(v.x, v.y - 1, v.z);
    seed(v.x, v.y + 1, v.z), seed(v.x, v.y, v.z - 1), seed(v.x, v.y, v.z + 1);
  }
  // Each remaining connected region of empty voxels lies on one side of the surface
  // (no triangle comes near it): it is inside if rays from it cross the mesh an odd
  // number of times in three directions (a mesh with holes fails this and is traced).
  RayScene model;
  model.add_static(m);
  model.commit();
  const auto inside = [&](const glm::vec3& x) {
    const glm::vec3 dirs[3] = {glm::normalize(glm::vec3(1.0f, 0.0123f, 0.0371f)),
                               glm::normalize(glm::vec3(-0.0213f, 1.0f, 0.0157f)),
                               glm::normalize(glm::vec3(0.0311f, -0.0193f, -1.0f))};
    for (const glm::vec3& d : dirs) {
      int crossings = 0;
      float t = 0.0f;
      while (crossings < 1000) {
        const auto hit = model.intersect(Ray{x, t, d, 1e30f});
        if (!hit) break;
        ++crossings;
        t = hit->t + 1e-5f * (1.0f + hit->t);
      }
      if (crossings % 2 == 0) return false;
    }
    return true;
  };
  std::vector<std::size_t> region;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        if (vox[index(x, y, z)] != V::kEmpty) continue;
        const bool in = inside(lo + (glm::vec3(x, y, z) + 0.5f) * cell);
        const std::uint8_t mark = in ? std::uint8_t(V::kInside) : kOutside;
        region.clear();
        vox[index(x, y, z)] = mark;
        stack.assign(1, {x, y, z});
        while (!stack.empty()) {
          const glm::ivec3 v = stack.back();
          stack.pop_back();
          const glm::ivec3 nb[6] = {v + glm::ivec3(1, 0, 0), v - glm::ivec3(1, 0, 0), v + glm::ivec3(0, 1, 0),
                                    v - glm::ivec3(0, 1, 0), v + glm::ivec3(0, 0, 1), v - glm::ivec3(0, 0, 1)};
          for (const glm::ivec3& w : nb) {
            if (glm::any(glm::lessThan(w, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(w, n))) continue;
            std::uint8_t& c = vox[index(w.x, w.y, w.z)];
            if (c == V::kEmpty) c = mark, stack.push_back(w);
          }
        }
      }
  for (std::uint8_t& v : vox)
    if (v == kOutside) v = V::kEmpty;
}

// Empty-space skipping: a voxel at clearance d has only empty voxels within d - 1 of it
// (Chebyshev), so a line may jump d - 1 voxels along every axis at once.
std::vector<std::uint8_t> clearance_of(const std::vector<std::uint8_t>& vox, const glm::ivec3& n) {
  const auto index = [&](int x, int y, int z) { return (std::size_t(z) * n.y + y) * n.x + x; };
  std::vector<std::uint8_t> d(vox.size());
  for (std::size_t k = 0; k < vox.size(); ++k) d[k] = vox[k] == LineShadows::kEmpty ? 255 : 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          std::uint8_t& c = d[index(x, y, z)];
          if (c == 0) continue;
          int best = c;
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const int X = x + dx, Y = y + dy, Z = z + dz;
                if (X < 0 || Y < 0 || Z < 0 || X >= n.x || Y >= n.y || Z >= n.z) continue;
                best = std::min(best, d[index(X, Y, Z)] + 1);
              }
          if (best < c) c = std::uint8_t(best), changed = true;
        }
  }
  return d;
}

}  // namespace

void LineShadows::place(Object& o, const glm::dmat4& T) {
  o.T_world_model = T;
  // Largest scale of the (similarity) transform: keeps the spheres conservative.
  const double scale = std::max({glm::length(glm::dvec3(T[0])), glm::length(glm::dvec3(T[1])),
                                 glm::length(glm::dvec3(T[2]))});
  o.parts.resize(o.model_parts.size());
  for (std::size_t i = 0; i < o.parts.size(); ++i) {
    const Sphere& m = o.model_parts[i];
    o.parts[i] = m;
    o.parts[i].centre = glm::vec3(T * glm::dvec4(glm::dvec3(m.centre), 1.0));
    o.parts[i].radius = float(m.radius * scale) * 1.0001f + 1e-6f;
  }
  o.bound = o.parts.empty() ? Sphere{} : o.parts[0];
  o.T_model_world = glm::mat4(glm::inverse(T));
}

int LineShadows::add_object(const Mesh& model, const glm::dmat4& T_world_model) {
  Object o;
  std::vector<std::uint32_t> tris(model.triangle_count());
  for (std::uint32_t t = 0; t < tris.size(); ++t) tris[t] = t;
  if (!tris.empty()) build_parts(model, tris, 0, tris.size(), kPartDepth, o.model_parts);
  std::tie(o.model_min, o.model_max) = model.bounds();
  const glm::vec3 ext0 = o.model_max - o.model_min;
  const float longest = std::max({ext0.x, ext0.y, ext0.z, 1e-6f});
  // A margin: every border voxel reaches past the mesh, so an empty one is outside.
  const glm::vec3 pad = 0.05f * longest / float(kGridCells) + 1e-4f * ext0 + 1e-6f;
  o.model_min -= pad, o.model_max += pad;
  const glm::vec3 ext = o.model_max - o.model_min;
  for (int a = 0; a < 3; ++a) {
    o.cells[a] = std::clamp(int(std::ceil(float(kGridCells) * ext[a] / longest)), 1, kGridCells + 2);
    o.cell_size[a] = ext[a] / float(o.cells[a]);
  }
  if (model.triangle_count() > 0) {
    voxelize(model, o.model_min, o.cells, o.cell_size, o.voxels);
    o.clearance = clearance_of(o.voxels, o.cells);
  }
  o.instance = occluders_.add_instance(model, T_world_model);
  place(o, T_world_model);
  objects_.push_back(std::move(o));
  dirty_ = true;
  return int(objects_.size()) - 1;
}

void LineShadows::set_object_pose(int id, const glm::dmat4& T_world_model) {
  if (id < 0 || id >= int(objects_.size()))
    throw RuntimeError("LineShadows::set_object_pose: no object " + std::to_string(id));
  Object& o = objects_[std::size_t(id)];
  if (o.T_world_model == T_world_model) return;
  place(o, T_world_model);
  occluders_.set_instance_transform(o.instance, T_world_model);
  dirty_ = true;
}

void LineShadows::set_culling(bool on) {
  if (on != culling_) dirty_ = true;
  culling_ = on;
}

bool LineShadows::shaft_hits(const ShadowTreeNode& r, const ShadowTreeNode& e) const {
  glm::vec3 b;
  float rb;
  if (lines_.distant) {
    // Ends x + D d: within r.radius + D e.radius of r.centre + D e.centre.
    b = r.centre + kDistantLineLength * e.centre;
    rb = r.radius + kDistantLineLength * e.radius;
  } else {
    b = e.centre, rb = e.radius;
  }
  // Whole bounding spheres only: cheap, and most pairs are far from every object.
  for (const Object& o : objects_)
    if (!o.parts.empty() && shaft_touches_sphere(r.centre, r.radius, b, rb, o.bound.centre, o.bound.radius))
      return true;
  return false;
}

LineShadows::Voxel LineShadows::classify_line(const Object& o, const glm::vec3& p, const glm::vec3& q,
                                              float t_far) const {
  // Most lines that reach here still miss the mesh's bounding sphere: no division needed.
  const Sphere& b = o.model_parts[0];
  {
    const glm::vec3 pc = b.centre - p;
    const float qq = glm::dot(q, q), w = glm::dot(pc, q), r2 = b.radius * b.radius;
    float d2;  // squared distance from the centre to the segment, times qq where w is inside
    if (w <= 0.0f) d2 = glm::dot(pc, pc) - r2;
    else if (w >= qq) d2 = glm::dot(pc - q, pc - q) - r2;
    else d2 = glm::dot(pc, pc) * qq - w * w - r2 * qq;
    if (d2 > 0.0f) return kEmpty;
  }
  // The segment p + t q, t in [0, t_far], clipped to the grid's box (model space)...
  float t0 = 0.0f, t1 = t_far;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(q[a]) < 1e-20f) {
      if (p[a] < o.model_min[a] || p[a] > o.model_max[a]) return kEmpty;
      continue;
    }
    const float inv = 1.0f / q[a];
    float ta = (o.model_min[a] - p[a]) * inv, tb = (o.model_max[a] - p[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    if (t0 > t1) return kEmpty;
  }
  // ...then walked voxel by voxel (Amanatides & Woo 1987), jumping through empty space.
  glm::ivec3 i, step;
  glm::vec3 t_max, t_delta;
  for (int a = 0; a < 3; ++a) {
    step[a] = q[a] > 0.0f ? 1 : (q[a] < 0.0f ? -1 : 0);
    t_delta[a] = step[a] != 0 ? o.cell_size[a] / std::abs(q[a]) : 1e30f;
  }
  const float min_delta = std::min({t_delta.x, t_delta.y, t_delta.z});
  const int stride[3] = {1, o.cells.x, o.cells.x * o.cells.y};
  const auto enter = [&](float t) {
    const glm::vec3 e = p + t * q;
    int idx = 0;
    for (int a = 0; a < 3; ++a) {
      i[a] = std::clamp(int(std::floor((e[a] - o.model_min[a]) / o.cell_size[a])), 0, o.cells[a] - 1);
      t_max[a] = step[a] == 0 ? 1e30f
                              : (o.model_min[a] + float(i[a] + (step[a] > 0 ? 1 : 0)) * o.cell_size[a] - p[a]) / q[a];
      idx += i[a] * stride[a];
    }
    return idx;
  };
  float t = t0;
  int idx = enter(t);
  Voxel seen = kEmpty;
  for (;;) {
    const auto v = Voxel(o.voxels[std::size_t(idx)]);
    if (v == kInside) return kInside;
    if (v == kSurface) seen = kSurface;
    const int d = o.clearance[std::size_t(idx)];
    if (d >= 3) {
      t += float(d - 1) * min_delta;
      if (t > t1) break;
      idx = enter(t);
      continue;
    }
    const int a = t_max.x < t_max.y ? (t_max.x < t_max.z ? 0 : 2) : (t_max.y < t_max.z ? 1 : 2);
    if (t_max[a] > t1) break;
    t = t_max[a];
    i[a] += step[a];
    if (i[a] < 0 || i[a] >= o.cells[a]) break;
    idx += step[a] * stride[a];
    t_max[a] += t_delta[a];
  }
  return seen;
}

bool LineShadows::update() {
  stats_ = ShadowFrameStats{};
  if (!dirty_) return false;
  dirty_ = false;
  stats_.recomputed = true;
  std::fill(attenuation_.begin(), attenuation_.end(), glm::vec3(1.0f));
  if (objects_.empty() || lines_.lines.empty()) return true;
  occluders_.commit();

  const auto t0 = std::chrono::steady_clock::now();
  rays_.clear();
  ray_lines_.clear();
  const float t_far = shadow_ray_t_far(lines_.distant);
  const auto add_ray = [&](std::uint32_t li) {
    const ShadowLine& l = lines_.lines[li];
    const glm::vec3 from = lines_.origins[l.receiver];
    rays_.push_back(Ray{from, 0.0f, lines_.line_end(l) - from, t_far});
    ray_lines_.push_back(li);
  };
  inside_lines_.clear();
  // Line ends in each object's model space, once per frame: a distant line's model-space
  // direction does not depend on the receiver.
  for (Object& o : objects_) {
    o.sample_model.resize(lines_.samples.size());
    const glm::mat3 R(o.T_model_world);
    for (std::size_t k = 0; k < lines_.samples.size(); ++k) {
      const glm::vec3& x = lines_.samples[k].position;
      o.sample_model[k] = lines_.distant ? kDistantLineLength * (R * x) : glm::vec3(o.T_model_world * glm::vec4(x, 1.0f));
    }
  }

  if (!culling_) {
    for (std::uint32_t li = 0; li < lines_.lines.size(); ++li) add_ray(li);
    stats_.lines_tested = lines_.lines.size();
  } else if (!lines_.receiver_tree.empty() && !lines_.emitter_tree.empty()) {
    const auto& rt = lines_.receiver_tree;
    const auto& et = lines_.emitter_tree;
    stack_.clear();
    stack_.push_back({0, 0});
    while (!stack_.empty()) {
      const auto [ri, ei] = stack_.back();
      stack_.pop_back();
      const ShadowTreeNode& r = rt[std::size_t(ri)];
      const ShadowTreeNode& e = et[std::size_t(ei)];
      ++stats_.shafts_tested;
      if (!shaft_hits(r, e)) continue;
      const bool r_leaf = r.leaf >= 0, e_leaf = e.leaf >= 0;
      if (r_leaf && e_leaf) {
        const std::size_t block = std::size_t(r.leaf) * lines_.patch_count + std::size_t(e.leaf);
        const std::uint32_t first = lines_.block_first[block], last = lines_.block_first[block + 1];
        // One receiver's lines to this patch: one more shaft (a point to the patch's
        // sphere) before testing them one by one.
        for (std::uint32_t run = first; run < last;) {
          const std::uint32_t receiver = lines_.lines[run].receiver;
          std::uint32_t run_end = run + 1;
          while (run_end < last && lines_.lines[run_end].receiver == receiver) ++run_end;
          const glm::vec3 from = lines_.origins[receiver];
          ShadowTreeNode point;
          point.centre = from;
          const bool touched = shaft_hits(point, e);
          if (touched) {
            stats_.lines_tested += run_end - run;
            for (const Object& o : objects_) {
              if (o.voxels.empty()) continue;
              const glm::vec3 p = glm::vec3(o.T_model_world * glm::vec4(from, 1.0f));
              for (std::uint32_t li = run; li < run_end; ++li) {
                const glm::vec3& s = o.sample_model[lines_.lines[li].sample];
                const Voxel v = classify_line(o, p, lines_.distant ? s : s - p, t_far);
                // A line may pass several objects: record it once, blocked first.
                if (v == kInside) ray_state_[li] = kInside;
                else if (v == kSurface && ray_state_[li] == kEmpty) ray_state_[li] = kSurface;
              }
            }
            for (std::uint32_t li = run; li < run_end; ++li) {
              if (ray_state_[li] == kInside) inside_lines_.push_back(li);
              else if (ray_state_[li] == kSurface) add_ray(li);
              ray_state_[li] = kEmpty;
            }
          }
          run = run_end;
        }
        continue;
      }
      // Split the node with the larger sphere (relative to the line length for distant emitters).
      const float r_size = r.radius;
      const float e_size = lines_.distant ? kDistantLineLength * e.radius : e.radius;
      if (e_leaf || (!r_leaf && r_size >= e_size)) {
        stack_.push_back({r.child[0], ei});
        stack_.push_back({r.child[1], ei});
      } else {
        stack_.push_back({ri, e.child[0]});
        stack_.push_back({ri, e.child[1]});
      }
    }
  }

  stats_.rays_traced = rays_.size();
  stats_.lines_inside = inside_lines_.size();
  const auto t1 = std::chrono::steady_clock::now();
  blocked_.assign(rays_.size(), 0);
  // Lines of one block leave nearby receivers towards one patch: coherent.
  occluders_.occluded(rays_, blocked_, true);
  const auto t2 = std::chrono::steady_clock::now();
  stats_.cull_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  stats_.trace_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  for (std::size_t k = 0; k < rays_.size(); ++k) {
    if (!blocked_[k]) continue;
    const ShadowLine& l = lines_.lines[ray_lines_[k]];
    attenuation_[l.receiver] -= l.fraction;
    ++stats_.lines_blocked;
  }
  for (const std::uint32_t li : inside_lines_) {
    const ShadowLine& l = lines_.lines[li];
    attenuation_[l.receiver] -= l.fraction;
    ++stats_.lines_blocked;
  }
  for (glm::vec3& a : attenuation_) a = glm::clamp(a, glm::vec3(0.0f), glm::vec3(1.0f));
  return true;
}

}  // namespace lumar
