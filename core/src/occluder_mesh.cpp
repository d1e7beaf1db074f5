#include "lumar/core/occluder_mesh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <opencv2/core.hpp>
#include <string>

#include "lumar/core/error.h"

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
  for (int a = 0; a < 3; ++a) axis[a] = glm::normalize(glm::dvec3(vectors.at<double>(a, 0), vectors.at<double>(a, 1),
                                                                  vectors.at<double>(a, 2)));
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

void report_embree_error(void*, RTCError code, const char* message) {
  if (code != RTC_ERROR_NONE) throw RuntimeError(std::string("Embree (shadow meshes): ") + (message ? message : "error"));
}

// The model-space BVHs live on their own device (RayScene keeps its device private).
RTCDevice bvh_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice("threads=0");
    if (!d) throw RuntimeError("Embree: cannot create a device for the shadow meshes");
    rtcSetDeviceErrorFunction(d, report_embree_error, nullptr);
    return d;
  }();
  return device;
}

}  // namespace

OccluderMesh::OccluderMesh(const Mesh& m) {
  if (m.triangle_count() == 0) throw InputError("OccluderMesh: the mesh has no triangles");
  RTCDevice device = bvh_device();
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);  // built once, traced every frame
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
}

OccluderMesh::~OccluderMesh() { rtcReleaseScene(static_cast<RTCScene>(scene_)); }

bool OccluderMesh::occluded(const glm::vec3& origin, const glm::vec3& dir, float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRay r{};
  r.org_x = origin.x, r.org_y = origin.y, r.org_z = origin.z, r.tnear = 0.0f;
  r.dir_x = dir.x, r.dir_y = dir.y, r.dir_z = dir.z, r.tfar = t_far;
  r.mask = 0xFFFFFFFFu;
  rtcOccluded1(static_cast<RTCScene>(scene_), &context, &r);
  return r.tfar < 0.0f;
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
