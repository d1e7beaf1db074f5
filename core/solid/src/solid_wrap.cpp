#include "lumar/solid/solid_wrap.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/alpha_wrap_3.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include "lumar/base/error.h"
#include "lumar/base/sphere_directions.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using TriangleOracle = CGAL::Alpha_wraps_3::internal::Triangle_soup_oracle<Kernel>;
using Oracle = CGAL::Alpha_wraps_3::internal::Point_set_oracle<Kernel, TriangleOracle>;

// Evenly spread directions: the inside test looks every way. Their rings run along z
// here, as when the shipped solids were made (any axis would do, but another gives other
// near-ties at grid points, and other bytes).
std::vector<glm::vec3> sphere_directions(int n) {
  std::vector<glm::vec3> out;
  for (const glm::dvec3& d : fibonacci_directions(n)) out.emplace_back(float(d.x), float(d.z), float(d.y));
  return out;
}

// Grid points, `spacing` apart over the mesh's box, that lie inside it by its winding
// number: the mean, over rays in every direction, of the signed count of the surfaces
// each crosses (+1 leaving through a back face, -1 entering through a front face). A
// closed surface gives 1 inside and 0 outside along every ray. An open one gives, just
// inside a hole, 1 less the hole's share of the view and, just outside, that share (a ray
// through the hole leaves once): 1/2 is the flat cap across the hole. Jacobson et al.
// 2013, "Robust inside-outside segmentation using generalized winding numbers", by rays.
std::vector<Kernel::Point_3> inside_points(const Mesh& mesh, double spacing, const SolidWrapSettings& s) {
  RayScene scene;
  scene.add_static(mesh);
  scene.commit();
  const auto [lo, hi] = mesh.bounds();
  const float step_past = float(1e-6 * glm::length(glm::dvec3(hi) - glm::dvec3(lo)));
  const glm::ivec3 n = glm::ivec3(glm::ceil((glm::dvec3(hi) - glm::dvec3(lo)) / spacing)) + 1;
  const std::vector<glm::vec3> directions = sphere_directions(s.rays_per_point);
  std::vector<std::vector<Kernel::Point_3>> per_slab(std::size_t(n.z));
  tbb::parallel_for(0, n.z, [&](int z) {
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const glm::vec3 p = glm::vec3(glm::dvec3(lo) + glm::dvec3(x, y, z) * spacing);
        int crossings = 0;
        for (const glm::vec3& d : directions) {
          float t = 0.f;
          for (int k = 0; k < 256; ++k) {  // a bound, far above any real surface's count
            const auto hit = scene.intersect(Ray{.origin = p, .t_near = t, .direction = d});
            if (!hit) break;
            crossings += hit->back_face ? 1 : -1;
            t = hit->t + step_past;
          }
        }
        if (crossings >= s.winding_number * s.rays_per_point) per_slab[std::size_t(z)].emplace_back(p.x, p.y, p.z);
      }
  });
  std::vector<Kernel::Point_3> points;
  for (const auto& slab : per_slab) points.insert(points.end(), slab.begin(), slab.end());
  return points;
}

// Without the closed parts that enclose less than `min_volume`: a lone point taken for
// inside is wrapped as a bubble, and an edge collapse can pinch off a flat sliver; both are
// detail the wrap's ball cannot stand for.
Mesh without_small_parts(const Mesh& mesh, double min_volume) {
  std::vector<std::uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto root = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    parent[root(mesh.indices[i])] = root(mesh.indices[i + 1]);
    parent[root(mesh.indices[i + 1])] = root(mesh.indices[i + 2]);
  }
  std::map<std::uint32_t, double> volume;  // per part: the divergence theorem over its triangles
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    const glm::dvec3 a = mesh.positions[mesh.indices[i]], b = mesh.positions[mesh.indices[i + 1]],
                     c = mesh.positions[mesh.indices[i + 2]];
    volume[root(mesh.indices[i])] += glm::dot(a, glm::cross(b, c)) / 6;
  }
  Mesh out;
  std::vector<std::int64_t> index(mesh.positions.size(), -1);
  for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) {
    if (const auto it = volume.find(root(v)); it == volume.end() || it->second < min_volume) continue;
    index[v] = std::int64_t(out.positions.size());
    out.positions.push_back(mesh.positions[v]);
  }
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3)
    if (index[mesh.indices[i]] >= 0)
      for (int k = 0; k < 3; ++k) out.indices.push_back(std::uint32_t(index[mesh.indices[i + std::size_t(k)]]));
  return out;
}

}  // namespace

Mesh wrap_solid(const Mesh& mesh, const SolidWrapSettings& s, SolidWrapReport* report,
                const std::function<void(const std::string&)>& progress) {
  if (mesh.triangle_count() == 0) throw InputError("solid wrap: the mesh has no triangles");
  // Below 1/400 the inside test's grid (a point per alpha) grows past 400³ points.
  if (!(s.alpha >= 1.0 / 400 && s.alpha <= 0.5) || !(s.offset > 0 && s.offset < s.alpha))
    throw InputError(
        "solid wrap: alpha must be from 0.0025 to 0.5 and offset in (0, alpha), as shares of the diagonal");
  if (s.rays_per_point < 4 || !(s.winding_number > 0 && s.winding_number < 1))
    throw InputError("solid wrap: at least 4 rays per point and a winding number in (0, 1)");
  const auto say = [&](const std::string& what) {
    if (progress) progress(what);
  };
  const auto [lo, hi] = mesh.bounds();
  const double diagonal = glm::length(glm::dvec3(hi) - glm::dvec3(lo));
  const double alpha = s.alpha * diagonal, offset = s.offset * diagonal;

  say("finding the inside");
  const std::vector<Kernel::Point_3> inside = inside_points(mesh, alpha, s);

  say("wrapping");
  std::vector<Kernel::Point_3> points;
  points.reserve(mesh.positions.size());
  for (const glm::vec3& p : mesh.positions) points.emplace_back(p.x, p.y, p.z);
  std::vector<std::array<std::size_t, 3>> faces;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
    faces.push_back({mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]});
  Oracle oracle(TriangleOracle(alpha, Kernel()));
  oracle.add_triangle_soup(points, faces);
  if (!inside.empty()) oracle.add_point_set(inside);
  SurfaceMesh wrap;
  CGAL::Alpha_wraps_3::internal::Alpha_wrap_3<Oracle> wrapper(oracle);
  wrapper(alpha, offset, wrap);
  if (report) *report = {.inside_points = inside.size(), .wrapped_triangles = wrap.number_of_faces()};

  if (s.max_triangles > 0 && wrap.number_of_faces() > s.max_triangles) {
    say("simplifying");
    // A closed triangle mesh has 3/2 edges per face.
    CGAL::Surface_mesh_simplification::Count_stop_predicate<SurfaceMesh> stop(s.max_triangles * 3 / 2);
    CGAL::Surface_mesh_simplification::edge_collapse(wrap, stop);
    wrap.collect_garbage();
  }

  Mesh out;
  for (const auto v : wrap.vertices()) {
    const Kernel::Point_3& p = wrap.point(v);
    out.positions.emplace_back(float(p.x()), float(p.y()), float(p.z()));
  }
  for (const auto f : wrap.faces())
    for (const auto v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) out.indices.push_back(std::uint32_t(v));
  out = without_small_parts(out, alpha * alpha * alpha);
  out.normals = area_weighted_normals(out.positions, out.indices);
  return out;
}

}  // namespace lumar
