#include "lumar/lighting/shadows/shadow_occlusion.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>

#include "cpu_clones.h"
#include "lumar/base/error.h"
#include "lumar/lighting/shadows/occluder_mesh.h"
#include "lumar/lighting/shadows/shadow_cone.h"

namespace lumar {

namespace {

// CPU time of the calling thread: the breakdown stays meaningful on a loaded machine.
double thread_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

}  // namespace

LineShadows::LineShadows(ShadowLines lines) : lines_(std::move(lines)) {
  attenuation_.assign(lines_.receiver_count(), glm::vec3(1.0f));
  const ReceiverGrids& grids = lines_.grids;
  // Structure of arrays, padded: four receivers are tested against a cone at once.
  for (auto* v : {&ordered_u_, &ordered_v_}) v->assign(grids.order.size() + 4, 0.0f);
  for (const ReceiverGrid& g : grids.grids) {
    const std::uint32_t from = grids.bucket_first[g.first_bucket];
    const std::uint32_t to = grids.bucket_first[g.first_bucket + std::uint32_t(g.nu * g.nv)];
    for (std::uint32_t k = from; k < to; ++k) {
      const glm::vec3 d = lines_.origins[grids.order[k]] - g.origin;
      ordered_u_[k] = glm::dot(d, g.u_axis), ordered_v_[k] = glm::dot(d, g.v_axis);
    }
  }
  std::vector<std::uint32_t> position(lines_.receiver_count(), 0);  // a receiver's place in grid order
  for (std::size_t k = 0; k < grids.order.size(); ++k) {
    position[grids.order[k]] = std::uint32_t(k);
  }
  chunks_ = (grids.order.size() + 63) / 64;
  hits_.assign(chunks_, 0);
  const std::size_t samples = lines_.samples.size();
  chunk_mask_.assign(samples * chunks_, 0);
  chunk_first_.assign(samples * chunks_, 0);
  for (std::size_t s = 0; s < samples; ++s) {
    std::uint32_t li = lines_.sample_first[s];
    for (std::size_t ch = 0; ch < chunks_; ++ch) {
      chunk_first_[s * chunks_ + ch] = li;
      while (li < lines_.sample_first[s + 1] && position[lines_.lines[li].receiver] / 64 == ch) {
        chunk_mask_[s * chunks_ + ch] |= std::uint64_t(1) << (position[lines_.lines[li].receiver] % 64);
        ++li;
      }
    }
  }
}

LineShadows::~LineShadows() = default;

void LineShadows::place(Object& o, const glm::dmat4& T) {
  o.T_world_model = T;
  o.T_model_world = glm::mat4(glm::inverse(T));
  const auto to_world = [&](const glm::vec3& p) { return glm::vec3(T * glm::dvec4(glm::dvec3(p), 1.0)); };
  if (!o.mesh) return;
  const auto& pieces = o.mesh->pieces();
  o.parts.resize(pieces.size());
  for (std::size_t p = 0; p < pieces.size(); ++p)
    for (int k = 0; k < 8; ++k) o.parts[p][std::size_t(k)] = to_world(pieces[p][std::size_t(k)]);
}

int LineShadows::add_object(const Mesh& model, const glm::dmat4& T_world_model) {
  Object o;
  if (model.triangle_count() > 0) o.mesh = std::make_shared<OccluderMesh>(model);
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
  dirty_ = true;
}

void LineShadows::set_culling(bool on) {
  if (on != culling_) dirty_ = true;
  culling_ = on;
}

namespace {

// A cone's footprint on a receiver grid: per cone plane, the half-plane a u + b v + c <= 0
// of grid points (u, v) that lie inside that plane at some height of the grid's slab
// (with room for float error), so it holds every receiver inside the cone.
struct Footprint {
  int n = 0;
  float a[ShadowCone::kMaxPlanes], b[ShadowCone::kMaxPlanes], c[ShadowCone::kMaxPlanes];
  Footprint(const ShadowCone& cone, const ReceiverGrid& g) : n(cone.plane_count()) {
    constexpr float kSlack = 1e-4f;  // metres: float error of the grid coordinates
    for (int k = 0; k < n; ++k) {
      const glm::vec4& p = cone.plane(k);
      const glm::vec3 nrm(p);
      const float hn = glm::dot(nrm, g.normal);
      a[k] = glm::dot(nrm, g.u_axis), b[k] = glm::dot(nrm, g.v_axis);
      c[k] = glm::dot(nrm, g.origin) + p.w + std::min(hn * g.h_min, hn * g.h_max) - ShadowCone::kMargin -
             kSlack * (std::abs(a[k]) + std::abs(b[k]) + std::abs(hn));
    }
  }
};

// The buckets of a footprint, row by row: f(j, i0, i1) for the buckets i0..i1 of row j
// that it may touch. Returns the number of rows scanned.
template <class F>
[[gnu::always_inline]] inline std::size_t scan_footprint(const Footprint& fp, const ReceiverGrid& g, F&& f) {
  // Over a row's band of v, a half-plane bounds u on one side by a linear function of
  // the row index j: u <= or >= alpha + beta j. Precomputed, a row costs two operations
  // per plane.
  float up_alpha[ShadowCone::kMaxPlanes], up_beta[ShadowCone::kMaxPlanes];
  float down_alpha[ShadowCone::kMaxPlanes], down_beta[ShadowCone::kMaxPlanes];
  int ups = 0, downs = 0;
  const float u_lo = g.u0, u_hi = g.u0 + float(g.nu) * g.cell;
  float v_lo = g.v0, v_hi = g.v0 + float(g.nv) * g.cell;
  for (int k = 0; k < fp.n; ++k) {
    const float a = fp.a[k], b = fp.b[k], c = fp.c[k];
    // The rows: the half-plane over the grid's whole u range bounds v.
    const float amin = std::min(a * u_lo, a * u_hi);
    if (b > 0.0f)
      v_hi = std::min(v_hi, (-c - amin) / b);
    else if (b < 0.0f)
      v_lo = std::max(v_lo, (-c - amin) / b);
    else if (amin + c > 0.0f)
      return 0;
    if (a == 0.0f) continue;  // bounds v only: done above
    // Row j spans v0 + [j, j + 1] cell; the smallest b v over it is at its low end for b > 0.
    const float v_at = g.v0 + (b < 0.0f ? g.cell : 0.0f);
    const float alpha = (-c - b * v_at) / a, beta = -b * g.cell / a;
    if (a > 0.0f)
      up_alpha[ups] = alpha, up_beta[ups++] = beta;
    else
      down_alpha[downs] = alpha, down_beta[downs++] = beta;
  }
  if (!(v_lo <= v_hi)) return 0;
  const int j0 = std::clamp(int(std::floor((v_lo - g.v0) / g.cell)), 0, g.nv - 1);
  const int j1 = std::clamp(int(std::floor((v_hi - g.v0) / g.cell)), 0, g.nv - 1);
  const float inv_cell = 1.0f / g.cell;
  for (int j = j0; j <= j1; ++j) {
    const float fj = float(j);
    float lo = u_lo, hi = u_hi;
    for (int k = 0; k < ups; ++k) hi = std::min(hi, up_alpha[k] + up_beta[k] * fj);
    for (int k = 0; k < downs; ++k) lo = std::max(lo, down_alpha[k] + down_beta[k] * fj);
    if (!(lo <= hi)) continue;
    const int i0 = std::clamp(int(std::floor((lo - g.u0) * inv_cell)), 0, g.nu - 1);
    const int i1 = std::clamp(int(std::floor((hi - g.u0) * inv_cell)), 0, g.nu - 1);
    f(j, i0, i1);
  }
  return std::size_t(j1 - j0 + 1);
}

// Set bits (inline: without -mpopcnt, std::popcount is a library call).
std::uint32_t ones(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return std::uint32_t((x * 0x0101010101010101ull) >> 56);
}

// Which of four receivers (bits 0-3) lie inside the outer footprint: the half-planes
// once, four lanes at a time.
using Float4 = float __attribute__((vector_size(16)));
using Int4 = std::int32_t __attribute__((vector_size(16)));
[[gnu::always_inline]] inline unsigned inside4(const Footprint& fp, const float* us, const float* vs) {
  Float4 u, v;
  std::memcpy(&u, us, sizeof u), std::memcpy(&v, vs, sizeof v);
  Int4 in = {-1, -1, -1, -1};
  for (int k = 0; k < fp.n; ++k) in &= u * fp.a[k] + v * fp.b[k] + fp.c[k] <= 0.0f;
  return unsigned(in[0] & 1) | unsigned(in[1] & 2) | unsigned(in[2] & 4) | unsigned(in[3] & 8);
}

}  // namespace

// The candidates among one sample's lines for one object: the receivers in the
// footprints of the pieces' cones that lie inside a cone, and that have a line to it.
LUMAR_AVX2_CLONES void LineShadows::cull(const Object& o, std::uint32_t sample) {
  const glm::vec3& e = lines_.samples[sample].position;
  const ReceiverGrids& grids = lines_.grids;
  std::size_t rows = 0, tested = 0;  // locals: the loop below stays in registers
  for (std::size_t p = 0; p < o.parts.size(); ++p) {
    const ShadowCone cone(o.parts[p], e, lines_.distant);
    for (const ReceiverGrid& g : grids.grids) {
      const Footprint fp(cone, g);
      rows += scan_footprint(fp, g, [&](int j, int i0, int i1) {
        const std::uint32_t b = g.first_bucket + std::uint32_t(j * g.nu);
        const std::uint32_t k1 = grids.bucket_first[b + std::uint32_t(i1) + 1];
        const std::uint32_t k0 = grids.bucket_first[b + std::uint32_t(i0)];
        tested += k1 - k0;
        for (std::uint32_t k = k0; k < k1; k += 4) {
          const std::uint64_t in =
              inside4(fp, &ordered_u_[k], &ordered_v_[k]) & (k1 - k >= 4 ? 15u : (1u << (k1 - k)) - 1u);
          if (in == 0) continue;
          // Four bits into the sample's receiver bitset (they may straddle two words).
          const std::uint32_t w = k >> 6, shift = k & 63;
          if (hits_[w] == 0) hit_chunks_.push_back(w);
          hits_[w] |= in << shift;
          if (shift > 60 && (in >> (64 - shift)) != 0) {
            if (hits_[w + 1] == 0) hit_chunks_.push_back(w + 1);
            hits_[w + 1] |= in >> (64 - shift);
          }
        }
      });
    }
  }
  stats_.rows_scanned += rows, stats_.receivers_tested += tested;
  // Receivers -> this sample's lines: the k-th present receiver of a chunk is line first + k.
  std::sort(hit_chunks_.begin(), hit_chunks_.end());
  for (const std::uint32_t ch : hit_chunks_) {
    const std::size_t c = std::size_t(sample) * chunks_ + ch;
    const std::uint64_t present = chunk_mask_[c];
    for (std::uint64_t m = hits_[ch] & present; m != 0; m &= m - 1) {
      const int bit = std::countr_zero(m);
      const std::uint32_t line = chunk_first_[c] + ones(present & ((std::uint64_t(1) << bit) - 1));
      candidates_.push_back({line, grids.order[ch * 64 + std::uint32_t(bit)], sample});
    }
    hits_[ch] = 0;
  }
  hit_chunks_.clear();
}

// Candidates tested in model space. A line blocked at the last update walks from the
// triangle that blocked it (while the figurine moves a few millimetres a frame, 84 % of
// the blocked lines are proven so, each at about a third of a blocked Embree ray's cost);
// the others are traced one ray at a time: Embree's single-ray traversal beat its packets
// and streams on these candidates (docs/shadows.md lists what was tried).
void LineShadows::trace(Object& o) {
  const float t_far = shadow_ray_t_far(lines_.distant);
  o.next_blocked.clear();
  // After a jump, a walk would fail at every line and only add to Embree's cost.
  if (!OccluderMesh::within_walk_reach(o.mesh->whole(), o.T_world_model, o.T_blocked)) o.blocked.clear();
  o.T_blocked = o.T_world_model;
  auto last = o.blocked.begin();        // both lists ascend by line: a merge
  constexpr std::ptrdiff_t kAhead = 8;  // blockers prefetched this many entries ahead
  std::size_t near = 0;
  for (const Candidate& c : candidates_) {
    const glm::vec3& p = o.origin_model[c.receiver];
    const glm::vec3& s = o.sample_model[c.sample];
    const glm::vec3 d = lines_.distant ? s : s - p;
    while (last != o.blocked.end() && last->line < c.line) ++last;
    if (o.blocked.end() - last > kAhead) o.mesh->prefetch(last[kAhead].triangle);
    std::uint32_t triangle =
        last != o.blocked.end() && last->line == c.line ? last->triangle : OccluderMesh::kNoTriangle;
    bool blocked = o.mesh->blocked_near(p, d, t_far, triangle);
    near += blocked;
    if (!blocked) blocked = o.mesh->occluded(p, d, t_far, &triangle);
    if (blocked) {
      blocked_lines_.push_back(c.line);
      o.next_blocked.push_back({c.line, triangle});
    }
  }
  o.blocked.swap(o.next_blocked);
  stats_.lines_walked += near;
}

// The baseline: every line (not yet blocked by another object) against the mesh, as
// one coherent ray stream; the same rays as trace(), so both find the same lines blocked.
void LineShadows::trace_all(const Object& o) {
  const float t_far = shadow_ray_t_far(lines_.distant);
  constexpr std::size_t kChunk = 256;
  OccluderMesh::StreamRay chunk[kChunk];
  std::uint32_t which[kChunk];
  std::size_t n = 0;
  const auto flush = [&] {
    o.mesh->occluded(chunk, n);
    for (std::size_t k = 0; k < n; ++k)
      if (chunk[k].t_far < 0.0f) all_blocked_[which[k]] = 1;
    n = 0;
  };
  for (std::uint32_t li = 0; li < lines_.lines.size(); ++li) {
    if (all_blocked_[li]) continue;
    const ShadowLine& l = lines_.lines[li];
    const glm::vec3& p = o.origin_model[l.receiver];
    const glm::vec3& s = o.sample_model[l.sample];
    OccluderMesh::StreamRay& r = chunk[n];
    r = OccluderMesh::StreamRay{};
    r.origin = p, r.dir = lines_.distant ? s : s - p, r.t_far = t_far;
    which[n++] = li;
    if (n == kChunk) flush();
  }
  if (n > 0) flush();
  stats_.rays_traced += lines_.lines.size();
}

bool LineShadows::update() {
  stats_ = ShadowFrameStats{};
  if (!dirty_) return false;
  dirty_ = false;
  stats_.recomputed = true;
  std::fill(attenuation_.begin(), attenuation_.end(), glm::vec3(1.0f));
  blocked_lines_.clear();
  traced_lines_.clear();
  if (objects_.empty() || lines_.lines.empty()) return true;

  double cull_ms = 0, trace_ms = 0;
  if (!culling_) all_blocked_.assign(lines_.lines.size(), 0);
  for (Object& o : objects_) {
    if (!o.mesh) continue;
    const double t0 = thread_ms();
    // This frame's line ends in model space: transformed once, not once per line.
    o.origin_model.resize(lines_.origins.size());
    for (std::size_t i = 0; i < lines_.origins.size(); ++i)
      o.origin_model[i] = glm::vec3(o.T_model_world * glm::vec4(lines_.origins[i], 1.0f));
    o.sample_model.resize(lines_.samples.size());
    const glm::mat3 R(o.T_model_world);
    for (std::size_t k = 0; k < lines_.samples.size(); ++k) {
      const glm::vec3& x = lines_.samples[k].position;
      o.sample_model[k] =
          lines_.distant ? kDistantLineLength * (R * x) : glm::vec3(o.T_model_world * glm::vec4(x, 1.0f));
    }
    if (!culling_) {
      trace_all(o);
      trace_ms += thread_ms() - t0;
      continue;
    }
    candidates_.clear();
    for (std::uint32_t s = 0; s < lines_.samples.size(); ++s) cull(o, s);
    stats_.rays_traced += candidates_.size();
    const double t1 = thread_ms();
    trace(o);
    for (const Candidate& c : candidates_) traced_lines_.push_back(c.line);
    cull_ms += t1 - t0;
    trace_ms += thread_ms() - t1;
  }
  if (!culling_) {
    for (std::uint32_t li = 0; li < all_blocked_.size(); ++li)
      if (all_blocked_[li]) blocked_lines_.push_back(li);
  } else if (objects_.size() > 1) {  // a line behind two objects counts once
    std::sort(blocked_lines_.begin(), blocked_lines_.end());
    blocked_lines_.erase(std::unique(blocked_lines_.begin(), blocked_lines_.end()), blocked_lines_.end());
  }
  stats_.cull_ms = cull_ms, stats_.trace_ms = trace_ms;
  stats_.lines_blocked = blocked_lines_.size();
  sum_attenuation();
  return true;
}

void LineShadows::sum_attenuation() {
  attenuation_.assign(lines_.receiver_count(), glm::vec3(1.0f));
  const bool relit = !receiver_scale_.empty();
  for (const std::uint32_t li : blocked_lines_) {
    const ShadowLine& l = lines_.lines[li];
    attenuation_[l.receiver] -= relit ? l.fraction * sample_scale_[l.sample] / receiver_scale_[l.receiver] : l.fraction;
  }
  for (glm::vec3& a : attenuation_) a = glm::clamp(a, glm::vec3(0.0f), glm::vec3(1.0f));
}

void LineShadows::relight(const std::vector<glm::vec3>& sample_scale) {
  if (sample_scale.size() != lines_.samples.size())
    throw RuntimeError("LineShadows::relight: " + std::to_string(sample_scale.size()) + " factors for " +
                       std::to_string(lines_.samples.size()) + " emitter samples");
  const std::size_t R = lines_.receiver_count();
  if (built_unshadowed_.empty()) {
    built_unshadowed_ = lines_.unshadowed;
    fraction_sum_.assign(R, glm::vec3(0.0f));
    for (const ShadowLine& l : lines_.lines) fraction_sum_[l.receiver] += l.fraction;
  }
  // Per receiver, S = Σ f k / Σ f over its lines (by sample, so k is read once per run):
  // its E_without scales by S, and a line's share becomes f k / S.
  std::vector<glm::vec3> weighted(R, glm::vec3(0.0f));
  for (std::uint32_t s = 0; s + 1 < lines_.sample_first.size(); ++s) {
    const glm::vec3 k = sample_scale[s];
    for (std::uint32_t i = lines_.sample_first[s]; i < lines_.sample_first[s + 1]; ++i)
      weighted[lines_.lines[i].receiver] += lines_.lines[i].fraction * k;
  }
  sample_scale_ = sample_scale;
  receiver_scale_.assign(R, glm::vec3(1.0f));
  for (std::size_t r = 0; r < R; ++r)
    for (int c = 0; c < 3; ++c) {
      if (fraction_sum_[r][c] > 0) receiver_scale_[r][c] = weighted[r][c] / fraction_sum_[r][c];
      // All its light out: no share left to block (and no division by zero).
      if (!(receiver_scale_[r][c] > 0)) receiver_scale_[r][c] = std::numeric_limits<float>::infinity();
    }
  for (std::size_t r = 0; r < R; ++r)
    for (int c = 0; c < 3; ++c)
      lines_.unshadowed[r][c] =
          std::isinf(receiver_scale_[r][c]) ? 0.0f : built_unshadowed_[r][c] * receiver_scale_[r][c];
  sum_attenuation();
}

}  // namespace lumar
