#include "lumar/lighting/shadows/occluder_mesh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <numeric>
#include <opencv2/core.hpp>
#include <string>

#include "cpu_clones.h"
#include "embree_device.h"
#include "lumar/base/error.h"

namespace lumar {

namespace {

// The mesh is cut into 2^kPartDepth pieces, each bounded by its own box: the union of
// their shadow cones hugs a figurine far better than one box. Each cut is the one (any
// axis, any triangle, at least a quarter of the triangles on each side) that minimises
// the two halves' summed box area. On the figurine (bench_shadows, 1 M lines): median
// cuts along the longest side, 8 pieces 47 k candidates per frame; area-minimising cuts,
// 8 pieces 30 k, 16 pieces 27 k, 64 pieces 22 k, but each doubling cost more in cones
// and footprints than it saved in rays (docs/shadows.md).
constexpr int kPartDepth = 3;
constexpr std::size_t kMinShare = 4;
constexpr int kSplitSteps = 16;

// A box around points (conservative): PCA axes, extents from the points' projections,
// widened by a hair so that floating-point transforms keep every point inside.
std::array<glm::vec3, 8> bounding_box(const std::vector<glm::vec3>& points) {
  glm::dvec3 mean(0.0);
  for (const glm::vec3& p : points) mean += glm::dvec3(p);
  mean /= double(std::max<std::size_t>(1, points.size()));
  cv::Matx33d cov = cv::Matx33d::zeros();
  for (const glm::vec3& p : points) {
    const glm::dvec3 d = glm::dvec3(p) - mean;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) += d[r] * d[c];
  }
  cv::Mat values, vectors;
  cv::eigen(cv::Mat(cov), values, vectors);
  glm::dvec3 axis[3];
  for (int a = 0; a < 3; ++a)
    axis[a] = glm::normalize(glm::dvec3(vectors.at<double>(a, 0), vectors.at<double>(a, 1), vectors.at<double>(a, 2)));
  if (!(glm::length(axis[0]) > 0.5) || !(glm::length(axis[1]) > 0.5))  // degenerate: world axes
    axis[0] = {1, 0, 0}, axis[1] = {0, 1, 0};
  axis[1] = glm::normalize(axis[1] - glm::dot(axis[1], axis[0]) * axis[0]);
  axis[2] = glm::cross(axis[0], axis[1]);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::vec3& p : points)
    for (int a = 0; a < 3; ++a) {
      const double s = glm::dot(glm::dvec3(p) - mean, axis[a]);
      lo[a] = std::min(lo[a], s), hi[a] = std::max(hi[a], s);
    }
  const double pad = 1e-4 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-6});
  std::array<glm::vec3, 8> corners;
  for (int k = 0; k < 8; ++k) {
    glm::dvec3 c = mean;
    for (int a = 0; a < 3; ++a) c += axis[a] * ((k >> a) & 1 ? hi[a] + pad : lo[a] - pad);
    corners[std::size_t(k)] = glm::vec3(c);
  }
  return corners;
}

// Boxes around the pieces left after `depth` levels of cuts of the triangles (kPartDepth).
void split_parts(const Mesh& m, std::vector<std::uint32_t>& tris, std::size_t b, std::size_t e, int depth,
                 std::vector<std::array<glm::vec3, 8>>& out) {
  if (depth == 0 || e - b < 16) {
    std::vector<glm::vec3> points;
    for (std::size_t k = b; k < e; ++k)
      for (int v = 0; v < 3; ++v) points.push_back(m.positions[m.indices[3 * tris[k] + v]]);
    out.push_back(bounding_box(points));
    return;
  }
  // The split (along an axis, at one of a few quantiles) that minimises the summed
  // surface area of the two halves' boxes: a cone's footprint grows with its box's
  // projected area, and a box's mean projected area is a quarter of its surface.
  const auto centroid = [&](std::uint32_t t) {
    return m.positions[m.indices[3 * t]] + m.positions[m.indices[3 * t + 1]] + m.positions[m.indices[3 * t + 2]];
  };
  const auto box_area = [&](const std::vector<std::uint32_t>& order, std::size_t from, std::size_t to) {
    std::vector<glm::vec3> points;
    for (std::size_t k = from; k < to; ++k)
      for (int v = 0; v < 3; ++v) points.push_back(m.positions[m.indices[3 * order[k] + v]]);
    const std::array<glm::vec3, 8> c = bounding_box(points);
    const float a = glm::length(c[1] - c[0]), b2 = glm::length(c[2] - c[0]), c3 = glm::length(c[4] - c[0]);
    return a * b2 + b2 * c3 + c3 * a;
  };
  const std::size_t n = e - b;
  std::vector<std::uint32_t> sorted(tris.begin() + std::ptrdiff_t(b), tris.begin() + std::ptrdiff_t(e)), best_order;
  float best = 1e30f;
  std::size_t mid = b + n / 2;
  for (int axis = 0; axis < 3; ++axis) {
    std::sort(sorted.begin(), sorted.end(),
              [&](std::uint32_t x, std::uint32_t y) { return centroid(x)[axis] < centroid(y)[axis]; });
    for (int q = 0; q <= kSplitSteps; ++q) {
      const std::size_t k = n / kMinShare + (n - 2 * (n / kMinShare)) * std::size_t(q) / std::size_t(kSplitSteps);
      if (k == 0 || k >= n) continue;
      const float cost = box_area(sorted, 0, k) + box_area(sorted, k, n);
      if (cost < best) best = cost, mid = b + k, best_order = sorted;
    }
  }
  if (!best_order.empty()) std::copy(best_order.begin(), best_order.end(), tris.begin() + std::ptrdiff_t(b));
  split_parts(m, tris, b, mid, depth - 1, out);
  split_parts(m, tris, mid, e, depth - 1, out);
}

// A single ray's context that also learns which triangle blocked it: Embree calls the
// context filter on each hit it finds (the scene is flagged for it), and an occlusion
// ray stops at the first hit it keeps.
struct BlockerContext {
  RTCIntersectContext context;
  std::uint32_t triangle;
};

void record_blocker(const RTCFilterFunctionNArguments* args) {
  if (args->N == 1 && args->valid[0] != 0)
    reinterpret_cast<BlockerContext*>(args->context)->triangle = RTCHitN_primID(args->hit, 1, 0);
}

}  // namespace

OccluderMesh::OccluderMesh(const Mesh& model) {
  if (model.triangle_count() == 0) throw InputError("OccluderMesh: the mesh has no triangles");
  // Triangles in Morton order of their centroids: neighbours on the mesh are mostly
  // neighbours in memory, for blocked_near's walks (the triangle ids are Embree's too).
  Mesh m;
  m.positions = model.positions;
  {
    const auto [lo, hi] = model.bounds();
    const glm::vec3 scale = 1023.0f / glm::max(hi - lo, glm::vec3(1e-9f));
    std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed(model.triangle_count());
    for (std::uint32_t t = 0; t < model.triangle_count(); ++t) {
      const glm::vec3 c = (model.positions[model.indices[3 * t]] + model.positions[model.indices[3 * t + 1]] +
                           model.positions[model.indices[3 * t + 2]]) /
                          3.0f;
      const glm::uvec3 q = glm::uvec3(glm::clamp((c - lo) * scale, glm::vec3(0.0f), glm::vec3(1023.0f)));
      std::uint32_t key = 0;
      for (int bit = 9; bit >= 0; --bit)
        for (int a = 0; a < 3; ++a) key = (key << 1) | ((q[a] >> bit) & 1u);
      keyed[t] = {key, t};
    }
    std::sort(keyed.begin(), keyed.end());
    for (const auto& [key, t] : keyed)
      for (int k = 0; k < 3; ++k) m.indices.push_back(model.indices[3 * t + std::uint32_t(k)]);
  }

  RTCDevice device = embree_device();
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);           // built once, traced every frame
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // record_blocker
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), m.positions.size()));
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    v[3 * i] = m.positions[i].x, v[3 * i + 1] = m.positions[i].y, v[3 * i + 2] = m.positions[i].z;
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), m.triangle_count()));
  std::copy(m.indices.begin(), m.indices.end(), idx);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  scene_ = scene;
  std::vector<std::uint32_t> tris(m.triangle_count());
  std::iota(tris.begin(), tris.end(), 0u);
  split_parts(m, tris, 0, tris.size(), kPartDepth, pieces_);
  whole_ = bounding_box(m.positions);

  triangles_.resize(m.triangle_count());
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::pair<std::uint32_t, int>>> edges;
  for (std::uint32_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t* c = &m.indices[3 * t];
    Triangle& tri = triangles_[t];
    tri.v0 = m.positions[c[0]];
    tri.e1 = m.positions[c[1]] - tri.v0, tri.e2 = m.positions[c[2]] - tri.v0;
    tri.area2 = glm::length(glm::cross(tri.e1, tri.e2));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t x = c[(k + 1) % 3], y = c[(k + 2) % 3];
      edges[{std::min(x, y), std::max(x, y)}].push_back({t, k});
    }
  }
  for (const auto& [edge, sides] : edges) {
    if (sides.size() != 2) continue;
    triangles_[sides[0].first].across[std::size_t(sides[0].second)] = sides[1].first;
    triangles_[sides[1].first].across[std::size_t(sides[1].second)] = sides[0].first;
  }
}

bool OccluderMesh::within_walk_reach(const std::array<glm::vec3, 8>& box, const glm::dmat4& world_now,
                                     const glm::dmat4& world_then) {
  double moved = 0.0;
  for (const glm::vec3& c : box) {
    const glm::dvec4 x(glm::dvec3(c), 1.0);
    moved = std::max(moved, glm::length(glm::dvec3(world_now * x - world_then * x)));
  }
  return moved <= kWalkReach;
}

OccluderMesh::~OccluderMesh() { rtcReleaseScene(static_cast<RTCScene>(scene_)); }

bool OccluderMesh::occluded(const glm::vec3& origin, const glm::vec3& dir, float t_far, std::uint32_t* blocker) const {
  BlockerContext c;
  rtcInitIntersectContext(&c.context);
  c.context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  if (blocker) c.context.filter = record_blocker;
  c.triangle = kNoTriangle;
  RTCRay r{};
  r.org_x = origin.x, r.org_y = origin.y, r.org_z = origin.z, r.tnear = 0.0f;
  r.dir_x = dir.x, r.dir_y = dir.y, r.dir_z = dir.z, r.tfar = t_far;
  r.mask = 0xFFFFFFFFu;
  rtcOccluded1(static_cast<RTCScene>(scene_), &c.context, &r);
  if (blocker) *blocker = c.triangle;
  return r.tfar < 0.0f;
}

LUMAR_AVX2_CLONES bool OccluderMesh::blocked_near(const glm::vec3& o, const glm::vec3& d, float t_far,
                                                  std::uint32_t& triangle) const {
  // Margins (barycentric, and along the segment) far above float error: a hit here is a
  // hit for Embree's watertight test too. Rays within ~0.06 degrees of a triangle's plane
  // are left to Embree.
  constexpr float kInside = 1e-4f, kGrazing = 1e-3f;
  // At most kSteps steps, and none towards a crossing more than kFar triangle widths
  // away: a line that slid off a thin part (it may still cross the mesh elsewhere) fails
  // early and goes to Embree.
  constexpr int kSteps = 4;
  constexpr float kFar = 3.0f;
  const float grazing2 = kGrazing * kGrazing * glm::dot(d, d);
  std::uint32_t t = triangle;
  for (int step = 0; step <= kSteps && t < triangles_.size(); ++step) {
    const Triangle& tri = triangles_[t];
    // Moeller-Trumbore without the division: the weights below are the barycentric
    // weights of the line's crossing with the triangle's plane, times |det|.
    const glm::vec3 p = glm::cross(d, tri.e2);
    const float det = glm::dot(tri.e1, p);
    if (!(det * det > grazing2 * tri.area2 * tri.area2)) return false;
    const float sign = det > 0.0f ? 1.0f : -1.0f, scale = det * sign;
    const glm::vec3 s = o - tri.v0;
    const glm::vec3 q = glm::cross(s, tri.e1);
    const float u = sign * glm::dot(s, p), v = sign * glm::dot(d, q), w = scale - u - v;  // corners 1, 2, 0
    const float inside = kInside * scale;
    if (u >= inside && v >= inside && w >= inside) {
      const float at = sign * glm::dot(tri.e2, q);
      if (!(at >= inside * t_far && at <= (scale - inside) * t_far)) return false;
      triangle = t;
      return true;
    }
    // Step across the edge opposite the most negative weight, towards the crossing.
    const int k = w <= u && w <= v ? 0 : (u <= v ? 1 : 2);
    if (std::min({u, v, w}) < -kFar * scale) return false;
    t = tri.across[std::size_t(k)];
  }
  return false;
}

static_assert(sizeof(OccluderMesh::StreamRay) == sizeof(RTCRay));
static_assert(offsetof(OccluderMesh::StreamRay, origin) == offsetof(RTCRay, org_x));
static_assert(offsetof(OccluderMesh::StreamRay, t_near) == offsetof(RTCRay, tnear));
static_assert(offsetof(OccluderMesh::StreamRay, dir) == offsetof(RTCRay, dir_x));
static_assert(offsetof(OccluderMesh::StreamRay, t_far) == offsetof(RTCRay, tfar));
static_assert(offsetof(OccluderMesh::StreamRay, flags) == offsetof(RTCRay, flags));

void OccluderMesh::occluded(StreamRay* rays, std::size_t n) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcOccluded1M(static_cast<RTCScene>(scene_), &context, reinterpret_cast<RTCRay*>(rays), unsigned(n), sizeof(RTCRay));
}

}  // namespace lumar
