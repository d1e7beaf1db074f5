#include "lumar/lighting/shadows/object_shadows.h"

#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>
#include <string>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/lighting/shadows/occluder_mesh.h"
#include "lumar/lighting/shadows/shadow_lines.h"

namespace lumar {

namespace {

// Vertices per chunk: small enough that a cone misses most chunks of a receiver it
// touches, large enough that the chunk boxes cost little next to the vertices.
constexpr std::uint32_t kChunk = 32;
// Chunks per group: a cone is tested against a group's box before its chunks'.
constexpr std::uint32_t kGroup = 8;

// Spreads the low 10 bits of v three apart (Morton code).
std::uint32_t spread_bits(std::uint32_t v) {
  v &= 0x3FFu;
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// Whether the axis-aligned box [lo, hi] lies wholly outside one of the cone's planes.
bool box_outside(const ShadowCone& cone, const glm::vec3& lo, const glm::vec3& hi) {
  for (int k = 0; k < cone.plane_count(); ++k) {
    const glm::vec4& p = cone.plane(k);
    // The box corner that minimises dot(n, x).
    const glm::vec3 x(p.x > 0 ? lo.x : hi.x, p.y > 0 ? lo.y : hi.y, p.z > 0 ? lo.z : hi.z);
    if (glm::dot(glm::vec3(p), x) + p.w > ShadowCone::kMargin) return true;
  }
  return false;
}

}  // namespace

ObjectShadows::ObjectShadows(const Emitters& emitters) : samples_(emitters.samples), distant_(emitters.distant) {
  sample_stride_ = (samples_.size() + 3) / 4 * 4;
  sample_rows_.assign(9 * sample_stride_, 0.0f);
  for (std::size_t i = 0; i < sample_stride_; ++i) {
    float* row = &sample_rows_[i];
    const std::size_t S = sample_stride_;
    if (i >= samples_.size()) {  // padding: far away, facing nothing, no flux
      row[0] = row[S] = row[2 * S] = 1e6f;
      continue;
    }
    const EmitterPoint& e = samples_[i];
    for (int a = 0; a < 3; ++a) {
      row[std::size_t(a) * S] = e.position[a];
      row[std::size_t(3 + a) * S] = e.normal[a];
      row[std::size_t(6 + a) * S] = e.flux[a];
    }
  }
}

// The sum of emitter_irradiance over the samples (the same formula), four samples at a
// time (SSE) over the structure of arrays: it is most of an update's work when an object
// moves, since every shadowed vertex of it needs it.
glm::vec3 ObjectShadows::unshadowed(const glm::vec3& x, const glm::vec3& n) const {
  const std::size_t S = sample_stride_;
  const float* row = sample_rows_.data();
  const __m128 zero = _mm_setzero_ps(), nx = _mm_set1_ps(n.x), ny = _mm_set1_ps(n.y), nz = _mm_set1_ps(n.z);
  const __m128 x0 = _mm_set1_ps(x.x), x1 = _mm_set1_ps(x.y), x2 = _mm_set1_ps(x.z);
  const __m128 tiny = _mm_set1_ps(1e-8f), cap = _mm_set1_ps(1e-4f);
  __m128 r = zero, g = zero, b = zero;
  for (std::size_t i = 0; i < S; i += 4) {
    const auto at = [&](int k) { return _mm_loadu_ps(row + std::size_t(k) * S + i); };
    __m128 w;
    if (distant_) {
      w = _mm_max_ps(zero, _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, at(0)), _mm_mul_ps(ny, at(1))), _mm_mul_ps(nz, at(2))));
    } else {
      const __m128 dx = _mm_sub_ps(at(0), x0), dy = _mm_sub_ps(at(1), x1), dz = _mm_sub_ps(at(2), x2);
      const __m128 r2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      // cos_x cos_e / max(r^2, cap) = (n.d)(-n_e.d) / (r^2 max(r^2, cap)): no square root.
      const __m128 along_n = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, dx), _mm_mul_ps(ny, dy)), _mm_mul_ps(nz, dz));
      const __m128 along_e =
          _mm_sub_ps(zero, _mm_add_ps(_mm_add_ps(_mm_mul_ps(at(3), dx), _mm_mul_ps(at(4), dy)), _mm_mul_ps(at(5), dz)));
      const __m128 ok =
          _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(along_n, zero), _mm_cmpgt_ps(along_e, zero)), _mm_cmpgt_ps(r2, tiny));
      const __m128 q = _mm_div_ps(_mm_mul_ps(along_n, along_e), _mm_mul_ps(r2, _mm_max_ps(r2, cap)));
      w = _mm_and_ps(ok, q);
    }
    r = _mm_add_ps(r, _mm_mul_ps(w, at(6)));
    g = _mm_add_ps(g, _mm_mul_ps(w, at(7)));
    b = _mm_add_ps(b, _mm_mul_ps(w, at(8)));
  }
  alignas(16) float sum[3][4];
  _mm_store_ps(sum[0], r), _mm_store_ps(sum[1], g), _mm_store_ps(sum[2], b);
  return {sum[0][0] + sum[0][1] + sum[0][2] + sum[0][3], sum[1][0] + sum[1][1] + sum[1][2] + sum[1][3],
          sum[2][0] + sum[2][1] + sum[2][2] + sum[2][3]};
}

ObjectShadows::~ObjectShadows() = default;

void ObjectShadows::place(Object& o, const glm::dmat4& T) {
  o.T_world_model = T;
  o.T_model_world = glm::mat4(glm::inverse(T));
  const auto to_world = [&](const glm::vec3& p) { return glm::vec3(T * glm::dvec4(glm::dvec3(p), 1.0)); };
  if (o.mesh) {
    for (int k = 0; k < 8; ++k) o.box[std::size_t(k)] = to_world(o.mesh->whole()[std::size_t(k)]);
    const auto& pieces = o.mesh->pieces();
    o.parts.resize(pieces.size());
    for (std::size_t p = 0; p < pieces.size(); ++p)
      for (int k = 0; k < 8; ++k) o.parts[p][std::size_t(k)] = to_world(pieces[p][std::size_t(k)]);
  }
  // Same arithmetic as transformed() (mesh.h), so callers can reproduce the points.
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(T)));
  const std::size_t n = o.order.size();
  o.position.resize(n), o.normal.resize(n), o.origin.resize(n), o.without.resize(n);
  o.without_known.assign(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t v = o.order[k];
    o.position[k] = to_world(o.model_positions[v]);
    o.normal[k] = glm::vec3(glm::normalize(normal_matrix * glm::dvec3(o.model_normals[v])));
    o.origin[k] = shadow_ray_origin(o.position[k], o.normal[k]);
  }
  for (Chunk& c : o.chunks) {
    c.lo = glm::vec3(1e30f), c.hi = glm::vec3(-1e30f);
    for (std::uint32_t k = c.begin; k < c.end; ++k)
      c.lo = glm::min(c.lo, o.origin[k]), c.hi = glm::max(c.hi, o.origin[k]);
  }
  o.lo = glm::vec3(1e30f), o.hi = glm::vec3(-1e30f);
  for (Chunk& g : o.groups) {
    g.lo = glm::vec3(1e30f), g.hi = glm::vec3(-1e30f);
    for (std::uint32_t c = g.begin; c < g.end; ++c)
      g.lo = glm::min(g.lo, o.chunks[c].lo), g.hi = glm::max(g.hi, o.chunks[c].hi);
    o.lo = glm::min(o.lo, g.lo), o.hi = glm::max(o.hi, g.hi);
  }
}

int ObjectShadows::add_object(const Mesh& model, const glm::dmat4& T_world_model) {
  if (model.normals.size() != model.positions.size())
    throw InputError("ObjectShadows::add_object: the mesh needs one normal per vertex; load it with load_mesh");
  Object o;
  o.model_positions = model.positions;
  o.model_normals = model.normals;
  o.attenuation.assign(model.positions.size(), glm::vec3(1.0f));
  const auto [lo, hi] = model.bounds();
  // Spatial order (Morton code in the model box), so that chunks are compact.
  const std::size_t n = model.positions.size();
  std::vector<std::uint32_t> code(n);
  const glm::vec3 scale = 1023.0f / glm::max(hi - lo, glm::vec3(1e-12f));
  for (std::size_t i = 0; i < n; ++i) {
    const glm::uvec3 q(glm::clamp((model.positions[i] - lo) * scale, glm::vec3(0.0f), glm::vec3(1023.0f)));
    code[i] = spread_bits(q.x) | (spread_bits(q.y) << 1) | (spread_bits(q.z) << 2);
  }
  o.order.resize(n);
  std::iota(o.order.begin(), o.order.end(), 0u);
  std::stable_sort(o.order.begin(), o.order.end(), [&](std::uint32_t a, std::uint32_t b) { return code[a] < code[b]; });
  for (std::uint32_t b = 0; b < n; b += kChunk)
    o.chunks.push_back({b, std::uint32_t(std::min<std::size_t>(n, b + kChunk))});
  for (std::uint32_t b = 0; b < o.chunks.size(); b += kGroup)
    o.groups.push_back({b, std::uint32_t(std::min<std::size_t>(o.chunks.size(), b + kGroup))});
  if (model.triangle_count() > 0) o.mesh = std::make_shared<OccluderMesh>(model);
  place(o, T_world_model);
  objects_.push_back(std::move(o));
  dirty_ = true;
  return int(objects_.size()) - 1;
}

void ObjectShadows::set_object_pose(int id, const glm::dmat4& T_world_model) {
  if (id < 0 || id >= int(objects_.size()))
    throw RuntimeError("ObjectShadows::set_object_pose: no object " + std::to_string(id) +
                       "; use an id add_object returned");
  Object& o = objects_[std::size_t(id)];
  if (o.T_world_model == T_world_model) return;
  place(o, T_world_model);
  dirty_ = true;
}

const std::vector<glm::vec3>& ObjectShadows::vertex_attenuation(int id) const {
  if (id < 0 || id >= int(objects_.size()))
    throw RuntimeError("ObjectShadows::vertex_attenuation: no object " + std::to_string(id) +
                       "; use an id add_object returned");
  return objects_[std::size_t(id)].attenuation;
}

void ObjectShadows::build_cones() {
  cones_.resize(objects_.size());
  for (std::size_t b = 0; b < objects_.size(); ++b) {
    const Object& o = objects_[b];
    cones_[b].clear();
    if (!o.mesh) continue;
    cones_[b].reserve(samples_.size() * (1 + o.parts.size()));
    for (const EmitterPoint& e : samples_) {
      cones_[b].emplace_back(o.box, e.position, distant_);
      for (const auto& part : o.parts) cones_[b].emplace_back(part, e.position, distant_);
    }
  }
}

// Object a (index self) receiving from every other object.
void ObjectShadows::shade(Object& a, std::size_t self) {
  std::fill(a.attenuation.begin(), a.attenuation.end(), glm::vec3(1.0f));
  const float t_far = shadow_ray_t_far(distant_);
  // Per (occluder, sample): whether its whole cone misses a's box (then nothing to do).
  const std::size_t S = samples_.size();
  std::vector<std::uint8_t> near(objects_.size() * S, 0);
  for (std::size_t bi = 0; bi < objects_.size(); ++bi) {
    if (bi == self || !objects_[bi].mesh) continue;
    const std::size_t stride = 1 + objects_[bi].parts.size();
    for (std::size_t s = 0; s < S; ++s) near[bi * S + s] = !box_outside(cones_[bi][s * stride], a.lo, a.hi);
  }
  // Per occluder: whether the last update's blockers may start walks, i.e. whether a's
  // box moved at most kWalkReach across the occluder's mesh since.
  a.blocked.resize(a.groups.size());
  a.occluder_from_model.resize(objects_.size(), glm::dmat4(0.0));
  std::vector<std::uint8_t> walk(objects_.size(), 0);
  std::array<glm::vec3, 8> model_box;  // a's box in its model space
  for (std::size_t k = 0; k < 8; ++k)
    model_box[k] = glm::vec3(glm::inverse(a.T_world_model) * glm::dvec4(glm::dvec3(a.box[k]), 1.0));
  for (std::size_t bi = 0; bi < objects_.size(); ++bi) {
    const glm::dmat4& T_b = objects_[bi].T_world_model;
    // Measured in the world (the occluder's units may differ): where a's box is now, and
    // where it would be had it kept its place on the occluder since the last update.
    walk[bi] = OccluderMesh::within_walk_reach(model_box, a.T_world_model, T_b * a.occluder_from_model[bi]);
    a.occluder_from_model[bi] = glm::inverse(T_b) * a.T_world_model;
  }
  std::atomic<std::size_t> tested{0}, traced{0}, blocked_lines{0}, walked{0}, shadowed{0};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, a.groups.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
        std::size_t n_tested = 0, n_traced = 0, n_blocked = 0, n_walked = 0, n_shadowed = 0;
        std::vector<Object::Blocked> next;
        // Per vertex of the group: blocked irradiance, last sample blocked (+1), any candidate.
        constexpr std::uint32_t kMax = kChunk * kGroup;
        glm::vec3 blocked[kMax];
        std::uint32_t stamp[kMax];
        bool candidate[kMax];
        std::uint8_t parts_in[64];
        for (std::size_t gi = range.begin(); gi != range.end(); ++gi) {
          const Chunk& g = a.groups[gi];
          const std::uint32_t first = a.chunks[g.begin].begin, count = a.chunks[g.end - 1].end - first;
          std::fill_n(blocked, count, glm::vec3(0.0f));
          std::fill_n(stamp, count, 0u);
          std::fill_n(candidate, count, false);
          // Last update's blocked lines, merged with this one's in visiting order.
          const std::vector<Object::Blocked>& last = a.blocked[gi];
          std::size_t li = 0;
          next.clear();
          for (std::uint32_t s = 0; s < S; ++s) {
            const EmitterPoint& e = samples_[s];
            for (std::size_t bi = 0; bi < objects_.size(); ++bi) {
              if (!near[bi * S + s]) continue;
              const Object& b = objects_[bi];
              const std::size_t stride = 1 + b.parts.size();
              const ShadowCone* cones = &cones_[bi][s * stride];
              if (box_outside(cones[0], g.lo, g.hi)) continue;
              const glm::mat3 R(b.T_model_world);
              const glm::vec3 distant_model = kDistantLineLength * (R * e.position);
              for (std::uint32_t ci = g.begin; ci < g.end; ++ci) {
                const Chunk& c = a.chunks[ci];
                if (box_outside(cones[0], c.lo, c.hi)) continue;
                // The pieces whose cones reach this chunk.
                int n_parts = 0;
                for (std::size_t p = 1; p < stride; ++p)
                  if (!box_outside(cones[p], c.lo, c.hi)) parts_in[n_parts++] = std::uint8_t(p);
                if (n_parts == 0) continue;
                n_tested += c.end - c.begin;
                for (std::uint32_t k = c.begin; k < c.end; ++k) {
                  const std::uint32_t j = k - first;
                  if (stamp[j] == s + 1) continue;  // already blocked by another object
                  bool inside = false;
                  for (int q = 0; q < n_parts && !inside; ++q) inside = cones[parts_in[q]].contains(a.origin[k]);
                  if (!inside) continue;
                  candidate[j] = true;
                  const glm::vec3 E = emitter_irradiance(e, distant_, a.position[k], a.normal[k]);
                  if (!(max_channel(E) > 0)) continue;
                  // The same line as in world space: affine maps keep the parameter t.
                  const glm::vec3 p = glm::vec3(b.T_model_world * glm::vec4(a.origin[k], 1.0f));
                  const glm::vec3 d =
                      distant_ ? distant_model : R * (emitter_line_end(e, distant_, a.origin[k]) - a.origin[k]);
                  ++n_traced;
                  const auto before = [&](const Object::Blocked& x) {
                    return x.sample != s ? x.sample < s : x.occluder != bi ? x.occluder < bi : x.vertex < k;
                  };
                  while (li < last.size() && before(last[li])) ++li;
                  std::uint32_t triangle = OccluderMesh::kNoTriangle;
                  if (walk[bi] && li < last.size() && last[li].sample == s && last[li].occluder == bi &&
                      last[li].vertex == k)
                    triangle = last[li].triangle;
                  bool hit = b.mesh->blocked_near(p, d, t_far, triangle);
                  n_walked += hit;
                  if (!hit) hit = b.mesh->occluded(p, d, t_far, &triangle);
                  if (hit) {
                    stamp[j] = s + 1, blocked[j] += E, ++n_blocked;
                    next.push_back({s, std::uint32_t(bi), k, triangle});
                  }
                }
              }
            }
          }
          a.blocked[gi].swap(next);
          // Only vertices with a blocked line need their unshadowed irradiance.
          for (std::uint32_t j = 0; j < count; ++j) {
            if (!candidate[j] || !(max_channel(blocked[j]) > 0)) continue;
            const std::uint32_t k = first + j;
            // Depends on a's own pose only: kept until a moves.
            if (!a.without_known[k]) a.without[k] = unshadowed(a.position[k], a.normal[k]), a.without_known[k] = 1;
            const glm::vec3& without = a.without[k];
            glm::vec3 ratio(1.0f);
            for (int ch = 0; ch < 3; ++ch)
              if (without[ch] > 0) ratio[ch] = std::clamp((without[ch] - blocked[j][ch]) / without[ch], 0.0f, 1.0f);
            a.attenuation[a.order[k]] = ratio;
            if (ratio.r < 1.0f || ratio.g < 1.0f || ratio.b < 1.0f) ++n_shadowed;
          }
        }
        tested += n_tested, traced += n_traced, blocked_lines += n_blocked, walked += n_walked;
        shadowed += n_shadowed;
      });
  stats_.lines_tested += tested, stats_.rays_traced += traced;
  stats_.lines_blocked += blocked_lines, stats_.lines_walked += walked, stats_.vertices_shadowed += shadowed;
}

bool ObjectShadows::update() {
  stats_ = ObjectShadowStats{};
  if (!dirty_) return false;
  dirty_ = false;
  stats_.recomputed = true;
  const auto t0 = std::chrono::steady_clock::now();
  if (objects_.size() < 2) {
    for (Object& o : objects_) std::fill(o.attenuation.begin(), o.attenuation.end(), glm::vec3(1.0f));
  } else {
    build_cones();
    for (std::size_t i = 0; i < objects_.size(); ++i) shade(objects_[i], i);
  }
  stats_.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

}  // namespace lumar
