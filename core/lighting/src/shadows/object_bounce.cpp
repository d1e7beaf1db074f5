#include "lumar/lighting/shadows/object_bounce.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/scene/mesh.h"

namespace lumar {

namespace {

glm::vec3 corner(const Mesh& m, std::uint32_t t, int k) { return m.positions[m.indices[3 * t + std::uint32_t(k)]]; }
// Where triangle t faces, from its vertex normals (a scan's winding is not always
// consistent); not normalised.
glm::vec3 vertex_normal_sum(const Mesh& m, std::uint32_t t) {
  return m.normals[m.indices[3 * t]] + m.normals[m.indices[3 * t + 1]] + m.normals[m.indices[3 * t + 2]];
}

// Form factor from a point (origin) with unit normal n to a triangle a, b, c (relative
// to the point), clipped to the point's upper half-space: Lambert's contour integral,
// 1/(2π) Σ over edges of the angle the edge subtends × the cosine of its plane's normal
// with n. The triangle's winding may be either way round.
float triangle_form_factor(const glm::vec3& n, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  // Clip to n·v >= 0 (Sutherland–Hodgman on a triangle: at most 4 corners).
  std::array<glm::vec3, 4> poly;
  int count = 0;
  const std::array<glm::vec3, 3> in{a, b, c};
  for (int i = 0; i < 3; ++i) {
    const glm::vec3 &p = in[std::size_t(i)], &q = in[std::size_t((i + 1) % 3)];
    const float dp = glm::dot(n, p), dq = glm::dot(n, q);
    if (dp >= 0) poly[std::size_t(count++)] = p;
    if ((dp >= 0) != (dq >= 0)) poly[std::size_t(count++)] = p + (q - p) * (dp / (dp - dq));
  }
  if (count < 3) return 0.0f;
  float sum = 0;
  for (int i = 0; i < count; ++i) {
    const glm::vec3 u = poly[std::size_t(i)], v = poly[std::size_t((i + 1) % count)];
    const float lu = glm::length(u), lv = glm::length(v);
    if (lu < 1e-12f || lv < 1e-12f) continue;
    const glm::vec3 cross = glm::cross(u, v);
    const float lc = glm::length(cross);
    if (lc < 1e-20f) continue;
    const float angle = std::atan2(lc, glm::dot(u, v));
    sum += angle * glm::dot(n, cross / lc);
  }
  return std::abs(sum) / float(2.0 * kPi);
}

}  // namespace

SurfaceClusters surface_clusters(const Mesh& mesh, int count, int children) {
  SurfaceClusters out;
  const std::size_t triangles = mesh.triangle_count();
  if (count <= 0 || triangles == 0) return out;
  // Each triangle as a point in 6-D: its centre, and its normal (from the vertex normals:
  // a scan's winding is not always consistent) scaled to a quarter of the mesh's size,
  // so that a cut separates a box's faces before it halves them.
  const auto [lo, hi] = mesh.bounds();
  const float normal_scale = 0.25f * glm::length(hi - lo);
  std::vector<std::array<float, 6>> key(triangles);
  std::vector<double> area(triangles);
  std::vector<std::uint32_t>& order = out.order;
  for (std::uint32_t t = 0; t < triangles; ++t) {
    const glm::vec3 a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
    const glm::vec3 centre = (a + b + c) / 3.0f;
    glm::vec3 n = vertex_normal_sum(mesh, t);
    if (glm::length(n) > 0) n = glm::normalize(n) * normal_scale;
    key[t] = {centre.x, centre.y, centre.z, n.x, n.y, n.z};
    area[t] = 0.5 * glm::length(glm::cross(glm::dvec3(b - a), glm::dvec3(c - a)));
    order.push_back(t);
  }
  // Median cuts by area: the largest run is split along its widest coordinate, at the
  // point that halves its area or at a clear gap, until there are `count` runs (the
  // clusters) and then count × children (their children: a split only reorders within
  // its run, so every child lies inside one cluster), or none can be split.
  struct Run {
    std::uint32_t first, count;
    double area;
    bool operator<(const Run& o) const { return area < o.area; }
  };
  auto run_of = [&](std::uint32_t first, std::uint32_t n) {
    double sum = 0;
    for (std::uint32_t i = first; i < first + n; ++i) sum += area[order[i]];
    return Run{first, n, sum};
  };
  std::vector<Run> done, heap{run_of(0, std::uint32_t(triangles))};
  auto split_until = [&](std::size_t runs) {
    while (!heap.empty() && heap.size() + done.size() < runs) {
      std::pop_heap(heap.begin(), heap.end());
      const Run r = heap.back();
      heap.pop_back();
      if (r.count < 2 || !(r.area > 0)) {
        done.push_back(r);
        continue;
      }
      std::array<float, 6> kmin, kmax;
      kmin.fill(1e30f), kmax.fill(-1e30f);
      for (std::uint32_t i = r.first; i < r.first + r.count; ++i)
        for (std::size_t d = 0; d < 6; ++d)
          kmin[d] = std::min(kmin[d], key[order[i]][d]), kmax[d] = std::max(kmax[d], key[order[i]][d]);
      std::size_t axis = 0;
      for (std::size_t d = 1; d < 6; ++d)
        if (kmax[d] - kmin[d] > kmax[axis] - kmin[axis]) axis = d;
      const auto begin = order.begin() + r.first, end = begin + r.count;
      std::stable_sort(begin, end, [&](std::uint32_t x, std::uint32_t y) { return key[x][axis] < key[y][axis]; });
      // The cut: halve the area, unless there is a gap (a box's edge between two faces'
      // normals): a cut there costs less imbalance than the gap's share of the range.
      const float range = std::max(kmax[axis] - kmin[axis], 1e-30f);
      double running = 0, best = 1e30;
      std::uint32_t cut = 1;
      for (std::uint32_t i = 0; i + 1 < r.count; ++i) {
        running += area[order[r.first + i]];
        const float gap = key[order[r.first + i + 1]][axis] - key[order[r.first + i]][axis];
        const double cost = std::abs(2.0 * running - r.area) / r.area - 2.0 * gap / range;
        if (cost < best) best = cost, cut = i + 1;
      }
      for (const Run& half : {run_of(r.first, cut), run_of(r.first + cut, r.count - cut)}) {
        heap.push_back(half);
        std::push_heap(heap.begin(), heap.end());
      }
    }
  };
  auto clusters_of = [&]() {
    std::vector<Run> runs = done;
    runs.insert(runs.end(), heap.begin(), heap.end());
    std::sort(runs.begin(), runs.end(), [](const Run& x, const Run& y) { return x.first < y.first; });
    std::vector<SurfaceCluster> list;
    for (const Run& r : runs) {
      SurfaceCluster c;
      c.first = r.first, c.count = r.count, c.area = float(r.area);
      glm::dvec3 centre(0.0), normal(0.0);
      for (std::uint32_t i = r.first; i < r.first + r.count; ++i) {
        const std::uint32_t t = order[i];
        centre += area[t] * glm::dvec3(corner(mesh, t, 0) + corner(mesh, t, 1) + corner(mesh, t, 2)) / 3.0;
        normal += area[t] * glm::dvec3(vertex_normal_sum(mesh, t));
      }
      c.centre = r.area > 0 ? glm::vec3(centre / r.area) : corner(mesh, order[r.first], 0);
      c.normal = glm::length(normal) > 0 ? glm::vec3(glm::normalize(normal)) : glm::vec3(0.0f);
      for (std::uint32_t i = r.first; i < r.first + r.count; ++i)
        for (int k = 0; k < 3; ++k) c.radius = std::max(c.radius, glm::length(corner(mesh, order[i], k) - c.centre));
      list.push_back(c);
    }
    return list;
  };
  split_until(std::size_t(count));
  out.clusters = clusters_of();
  split_until(std::size_t(count) * std::size_t(std::max(children, 1)));
  out.children = clusters_of();
  // Each cluster's children: a run of them, in order of their first triangle.
  std::size_t child = 0;
  for (SurfaceCluster& c : out.clusters) {
    c.first_child = std::uint32_t(child);
    while (child < out.children.size() && out.children[child].first < c.first + c.count) ++child;
    c.child_count = std::uint32_t(child) - c.first_child;
  }
  return out;
}

ObjectBounce::ObjectBounce(std::vector<glm::vec3> positions, std::vector<glm::vec3> normals,
                           std::vector<glm::vec3> unshadowed, const BounceSettings& settings)
    : positions_(std::move(positions)),
      normals_(std::move(normals)),
      unshadowed_(std::move(unshadowed)),
      settings_(settings) {
  if (normals_.size() != positions_.size() || unshadowed_.size() != positions_.size())
    throw InputError("bounce: receiver positions, normals and irradiance differ in count");
  if (settings_.clusters < 1) throw InputError("bounce: at least one surface cluster per object");
  bounce_.assign(positions_.size(), glm::vec3(0.0f));
  ratio_.assign(positions_.size(), glm::vec3(0.0f));
  dark_floor_ = dark_floor(unshadowed_);
}

glm::vec3 ObjectBounce::dark_floor(const std::vector<glm::vec3>& unshadowed) {
  glm::vec3 out(0.0f);
  if (unshadowed.empty()) return out;
  std::vector<float> channel(unshadowed.size());
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < unshadowed.size(); ++i) channel[i] = unshadowed[i][c];
    const auto middle = channel.begin() + std::ptrdiff_t(channel.size() / 2);
    std::nth_element(channel.begin(), middle, channel.end());
    out[c] = kDarkReceiverShare * *middle;
  }
  return out;
}

int ObjectBounce::add_object(const Mesh& model, const glm::vec3& albedo, const glm::dmat4& T_world_model) {
  if (model.normals.size() != model.positions.size()) throw InputError("bounce: the mesh needs one normal per vertex");
  Object o;
  o.model = model;
  o.albedo = albedo;
  o.T_world_model = T_world_model;
  o.surface = surface_clusters(model, settings_.clusters);
  const auto [lo, hi] = model.bounds();
  o.middle = 0.5f * (lo + hi);
  o.radius = 0.5f * glm::length(hi - lo);
  const std::size_t triangles = model.triangle_count();
  o.triangle_centre.resize(triangles), o.triangle_facing.resize(triangles);
  o.triangle_area.resize(triangles), o.triangle_radius.resize(triangles);
  for (std::uint32_t t = 0; t < triangles; ++t) {
    const glm::vec3 a = corner(model, t, 0), b = corner(model, t, 1), c = corner(model, t, 2);
    const glm::vec3 centre = (a + b + c) / 3.0f;
    const glm::vec3 f = vertex_normal_sum(model, t);
    o.triangle_centre[t] = centre;
    o.triangle_facing[t] = glm::length(f) > 0 ? glm::normalize(f) : f;
    o.triangle_area[t] = 0.5f * glm::length(glm::cross(b - a, c - a));
    o.triangle_radius[t] = std::max({glm::length(a - centre), glm::length(b - centre), glm::length(c - centre)});
  }
  shade_clusters(o, {});
  o.received.assign(model.positions.size(), glm::vec3(0.0f));
  objects_.push_back(std::move(o));
  dirty_ = true;
  return int(objects_.size()) - 1;
}

namespace {
template <class Objects>
auto& object_at(Objects& objects, int id) {
  if (id < 0 || std::size_t(id) >= objects.size()) throw RuntimeError("bounce: no object " + std::to_string(id));
  return objects[std::size_t(id)];
}
}  // namespace

void ObjectBounce::set_object_pose(int id, const glm::dmat4& T_world_model) {
  Object& o = object_at(objects_, id);
  if (o.T_world_model == T_world_model) return;
  o.T_world_model = T_world_model;
  dirty_ = true;
}

void ObjectBounce::set_object_occlusion(int id, std::span<const VertexOcclusion> occlusion) {
  Object& o = object_at(objects_, id);
  if (!occlusion.empty() && occlusion.size() != o.model.positions.size())
    throw InputError("bounce: " + std::to_string(occlusion.size()) + " self-occlusion values for " +
                     std::to_string(o.model.positions.size()) + " vertices");
  shade_clusters(o, occlusion);
  dirty_ = true;
}

void ObjectBounce::shade_clusters(Object& o, std::span<const VertexOcclusion> occlusion) {
  const Mesh& m = o.model;
  const std::vector<SurfaceCluster>& clusters = o.surface.clusters;
  o.cluster_bent.assign(clusters.size(), glm::vec3(0.0f));
  o.cluster_open.assign(clusters.size(), 1.0f);
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    const SurfaceCluster& c = clusters[k];
    glm::vec3 bent(0.0f);
    float open = 0, weight = 0;
    for (std::uint32_t i = c.first; i < c.first + c.count; ++i) {
      const std::uint32_t t = o.surface.order[i];
      const float w = o.triangle_area[t];
      for (int j = 0; j < 3; ++j) {
        const std::uint32_t v = m.indices[3 * t + std::uint32_t(j)];
        bent += w * (occlusion.empty() ? m.normals[v] : occlusion[v].bent_normal);
        open += w * (occlusion.empty() ? 1.0f : occlusion[v].open);
        weight += w;
      }
    }
    o.cluster_bent[k] = glm::length(bent) > 0 ? glm::normalize(bent) : c.normal;
    o.cluster_open[k] = weight > 0 ? open / weight : 1.0f;
  }
}

void ObjectBounce::set_object_enabled(int id, bool on) {
  Object& o = object_at(objects_, id);
  if (o.enabled == on) return;
  o.enabled = on;
  dirty_ = true;
}

void ObjectBounce::set_object_albedo(int id, const glm::vec3& albedo) {
  Object& o = object_at(objects_, id);
  if (o.albedo == albedo) return;
  o.albedo = albedo;
  dirty_ = true;
}

void ObjectBounce::relight(std::vector<glm::vec3> unshadowed) {
  if (unshadowed.size() != positions_.size())
    throw RuntimeError("ObjectBounce::relight: " + std::to_string(unshadowed.size()) + " values for " +
                       std::to_string(positions_.size()) + " receivers");
  unshadowed_ = std::move(unshadowed);
  dark_floor_ = dark_floor(unshadowed_);
  dirty_ = true;
}

bool ObjectBounce::update(const Irradiance& irradiance) {
  stats_.recomputed = false;
  if (!dirty_) return false;
  const auto t0 = std::chrono::steady_clock::now();
  stats_ = {};
  stats_.recomputed = true;
  std::fill(bounce_.begin(), bounce_.end(), glm::vec3(0.0f));
  for (Object& o : objects_)
    if (o.enabled && !o.surface.clusters.empty()) light_clusters(o, irradiance);
  for (const Object& o : objects_)
    if (o.enabled && !o.surface.clusters.empty()) add_object_bounce(o, positions_, normals_, bounce_);
  // Onto each other: every object's vertices, posed, receive from the others.
  const auto t1 = std::chrono::steady_clock::now();
  for (std::size_t b = 0; b < objects_.size(); ++b) {
    Object& to = objects_[b];
    std::fill(to.received.begin(), to.received.end(), glm::vec3(0.0f));
    if (objects_.size() < 2) continue;
    const Mesh posed = transformed(to.model, to.T_world_model);
    for (std::size_t a = 0; a < objects_.size(); ++a)
      if (a != b && objects_[a].enabled && !objects_[a].surface.clusters.empty())
        add_object_bounce(objects_[a], posed.positions, posed.normals, to.received);
  }
  stats_.onto_objects_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  for (std::size_t i = 0; i < positions_.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float without = std::max(unshadowed_[i][c], dark_floor_[c]);
      ratio_[i][c] = without > 0 ? bounce_[i][c] / without : 0.0f;
    }
    stats_.receivers_reached += bounce_[i] != glm::vec3(0.0f);
  }
  dirty_ = false;
  stats_.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

const std::vector<glm::vec3>& ObjectBounce::object_bounce(int id) const {
  if (id < 0 || id >= int(objects_.size())) throw RuntimeError("bounce: no object " + std::to_string(id));
  return objects_[std::size_t(id)].received;
}

// The volume's evaluation per cluster is most of a frame's cost outside the receivers'
// loop: once per update, in parallel.
void ObjectBounce::light_clusters(Object& o, const Irradiance& irradiance) {
  const glm::dmat3 linear(o.T_world_model);
  const glm::mat3 rotate(linear / std::cbrt(std::abs(glm::determinant(linear))));
  const glm::mat4 Tf(o.T_world_model);
  const glm::vec3 albedo_over_pi = o.albedo / float(kPi);
  o.cluster_radiance.resize(o.surface.clusters.size());
  tbb::parallel_for(std::size_t(0), o.surface.clusters.size(), [&](std::size_t k) {
    const glm::vec3 centre = glm::vec3(Tf * glm::vec4(o.surface.clusters[k].centre, 1.0f));
    const float open = o.cluster_open[k];
    o.cluster_radiance[k] = albedo_over_pi * open * irradiance(centre, rotate * o.cluster_bent[k]) * open;
  });
}

void ObjectBounce::add_object_bounce(const Object& o, std::span<const glm::vec3> positions,
                                     std::span<const glm::vec3> normals, std::span<glm::vec3> out) {
  const glm::dmat4& T = o.T_world_model;
  const glm::dmat3 linear(T);
  const double scale = std::cbrt(std::abs(glm::determinant(linear)));
  const glm::mat3 rotate(linear / scale);
  const glm::mat4 Tf(T);
  const float area_scale = float(scale * scale);
  const Mesh& m = o.model;
  const glm::vec3 middle = glm::vec3(Tf * glm::vec4(o.middle, 1.0f));
  const float reach = float(settings_.reach * scale) * std::max(o.radius, 1e-6f);

  // The clusters, posed, as a structure of arrays padded to a multiple of 4 for the
  // receivers' loop: centre, normal, radiance × open (the share of the light that leaves
  // past the object) × area, and the squared distance below which it is summed by parts.
  const std::vector<SurfaceCluster>& clusters = o.surface.clusters;
  const std::vector<std::uint32_t>& order = o.surface.order;
  const std::size_t n = clusters.size(), padded = (n + 3) / 4 * 4;
  std::vector<float> px(padded, 0.0f), py(padded, 0.0f), pz(padded, 0.0f), nx(padded, 0.0f), ny(padded, 0.0f),
      nz(padded, 0.0f), fr(padded, 0.0f), fg(padded, 0.0f), fb(padded, 0.0f), near2(padded, 0.0f);
  const std::vector<glm::vec3>& radiance = o.cluster_radiance;
  for (std::size_t k = 0; k < n; ++k) {
    const SurfaceCluster& c = clusters[k];
    const glm::vec3 centre = glm::vec3(Tf * glm::vec4(c.centre, 1.0f));
    const glm::vec3 flux = radiance[k] * c.area * area_scale;
    const glm::vec3 geometric = rotate * c.normal;
    px[k] = centre.x, py[k] = centre.y, pz[k] = centre.z;
    nx[k] = geometric.x, ny[k] = geometric.y, nz[k] = geometric.z;
    fr[k] = flux.r, fg[k] = flux.g, fb[k] = flux.b;
    const float near = float(settings_.near_radii) * c.radius * float(scale);
    near2[k] = near * near;
  }
  // Padding: no flux, never near.
  for (std::size_t k = n; k < padded; ++k) near2[k] = -1.0f;
  const float near_radii2 = float(settings_.near_radii * settings_.near_radii) * float(scale * scale);
  // The triangles' centres and facing, posed (near clusters visit them many times).
  const std::size_t triangles = m.triangle_count();
  std::vector<glm::vec3> triangle_centre(triangles), triangle_facing(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    triangle_centre[t] = glm::vec3(Tf * glm::vec4(o.triangle_centre[t], 1.0f));
    triangle_facing[t] = rotate * o.triangle_facing[t];
  }

  // Receivers apart, each writing its own sum: the same result on any number of threads.
  struct Counts {
    std::size_t pairs = 0, near_pairs = 0;
  };
  tbb::combinable<Counts> counts;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, positions.size(), 16),
      [&](const auto& range) {
        Counts& count = counts.local();
        std::vector<std::uint32_t> near;
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const glm::vec3 x = positions[i], nrm = normals[i];
          if (glm::length(x - middle) > reach) continue;
          near.clear();
          // Far clusters as points, four at a time: A cos θ_c cos θ_x / r², the cosines being
          // dot products over r, both clamped at 0 (facing is the visibility).
          const __m128 xx = _mm_set1_ps(x.x), xy = _mm_set1_ps(x.y), xz = _mm_set1_ps(x.z);
          const __m128 mx = _mm_set1_ps(nrm.x), my = _mm_set1_ps(nrm.y), mz = _mm_set1_ps(nrm.z);
          const __m128 zero = _mm_setzero_ps(), tiny = _mm_set1_ps(1e-30f);
          __m128 sr = zero, sg = zero, sb = zero;
          for (std::size_t k = 0; k < padded; k += 4) {
            const __m128 dx = _mm_sub_ps(_mm_loadu_ps(&px[k]), xx), dy = _mm_sub_ps(_mm_loadu_ps(&py[k]), xy),
                         dz = _mm_sub_ps(_mm_loadu_ps(&pz[k]), xz);
            const __m128 r2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const __m128 cos_x = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, mx), _mm_mul_ps(dy, my)), _mm_mul_ps(dz, mz));
            const __m128 cos_c =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, _mm_loadu_ps(&nx[k])), _mm_mul_ps(dy, _mm_loadu_ps(&ny[k]))),
                           _mm_mul_ps(dz, _mm_loadu_ps(&nz[k])));
            const __m128 is_near = _mm_cmplt_ps(r2, _mm_loadu_ps(&near2[k]));
            if (const int bits = _mm_movemask_ps(is_near))
              for (int j = 0; j < 4; ++j)
                if (bits & (1 << j)) near.push_back(std::uint32_t(k) + std::uint32_t(j));
            // cos_c is the outgoing cosine's negative (d points from the receiver to the cluster).
            const __m128 g = _mm_andnot_ps(
                is_near, _mm_div_ps(_mm_mul_ps(_mm_max_ps(cos_x, zero), _mm_max_ps(_mm_sub_ps(zero, cos_c), zero)),
                                    _mm_add_ps(_mm_mul_ps(r2, r2), tiny)));
            sr = _mm_add_ps(sr, _mm_mul_ps(g, _mm_loadu_ps(&fr[k])));
            sg = _mm_add_ps(sg, _mm_mul_ps(g, _mm_loadu_ps(&fg[k])));
            sb = _mm_add_ps(sb, _mm_mul_ps(g, _mm_loadu_ps(&fb[k])));
          }
          alignas(16) float r4[4], g4[4], b4[4];
          _mm_store_ps(r4, sr), _mm_store_ps(g4, sg), _mm_store_ps(b4, sb);
          glm::vec3 E(r4[0] + r4[1] + r4[2] + r4[3], g4[0] + g4[1] + g4[2] + g4[3], b4[0] + b4[1] + b4[2] + b4[3]);
          // Near clusters by their children, and near children by their triangles: each a
          // point, or, when the receiver is within a few of its radii, its exact form factor
          // (E = L π F).
          for (std::uint32_t k : near) {
            const SurfaceCluster& c = clusters[k];
            float sum = 0;
            for (std::uint32_t j = c.first_child; j < c.first_child + c.child_count; ++j) {
              const SurfaceCluster& patch = o.surface.children[j];
              const glm::vec3 d = glm::vec3(Tf * glm::vec4(patch.centre, 1.0f)) - x;
              const float r2 = glm::dot(d, d);
              if (r2 >= near_radii2 * patch.radius * patch.radius) {
                sum += patch.area * area_scale * std::max(glm::dot(d, nrm), 0.0f) *
                       std::max(-glm::dot(d, rotate * patch.normal), 0.0f) / (r2 * r2 + 1e-30f);
                continue;
              }
              for (std::uint32_t q = patch.first; q < patch.first + patch.count; ++q) {
                const std::uint32_t t = order[q];
                const glm::vec3 dt = triangle_centre[t] - x;
                const float cos_t = -glm::dot(dt, triangle_facing[t]);
                if (cos_t <= 0) continue;  // turned away: a closed surface shows its front
                const float rt2 = glm::dot(dt, dt);
                if (rt2 >= near_radii2 * o.triangle_radius[t] * o.triangle_radius[t]) {
                  sum += o.triangle_area[t] * area_scale * std::max(glm::dot(dt, nrm), 0.0f) * cos_t / (rt2 * rt2);
                } else {
                  const auto corner_from_x = [&](int k) {
                    return glm::vec3(Tf * glm::vec4(m.positions[m.indices[3 * t + std::uint32_t(k)]], 1.0f)) - x;
                  };
                  sum += float(kPi) * triangle_form_factor(nrm, corner_from_x(0), corner_from_x(1), corner_from_x(2));
                }
              }
            }
            E += sum * radiance[k];
          }
          out[i] += E;
          count.pairs += n - near.size();
          count.near_pairs += near.size();
        }
      },
      tbb::simple_partitioner());
  counts.combine_each([&](const Counts& c) {
    stats_.pairs += c.pairs;
    stats_.near_pairs += c.near_pairs;
  });
}

ObjectBounce::Irradiance object_irradiance(const IrradianceVolume* volume, const SH9& sh) {
  if (volume)
    return [volume](const glm::vec3& p, const glm::vec3& n) {
      return glm::vec3(volume->evaluate(glm::dvec3(p), glm::dvec3(n)));
    };
  return [sh](const glm::vec3&, const glm::vec3& n) { return glm::vec3(sh9_irradiance(sh, glm::dvec3(n))); };
}

std::vector<glm::vec3> with_bounce(std::vector<glm::vec3> attenuation, const ObjectBounce& bounce) {
  for (std::size_t i = 0; i < attenuation.size(); ++i) attenuation[i] += bounce.ratio()[i];
  return attenuation;
}

}  // namespace lumar
