#include "lumar/lighting/shadows/shadow_receiver_grid.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/core.hpp>

#include "lumar/base/error.h"

namespace lumar {

namespace {

// The frame of points[idx[b, e)]: the normal is their mean normal (falling back to the
// axis of least spread when the normals cancel), u the axis of largest spread across it;
// with the points' extents along the three axes.
struct Frame {
  glm::dvec3 mean{0.0};
  glm::dvec3 axis[3];  // u, v, normal
  glm::dvec3 lo{1e300}, hi{-1e300};
};

Frame frame_of(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& normals,
               const std::vector<std::uint32_t>& idx, std::size_t b, std::size_t e) {
  Frame f;
  glm::dvec3 normal(0.0);
  for (std::size_t k = b; k < e; ++k) f.mean += glm::dvec3(points[idx[k]]), normal += glm::dvec3(normals[idx[k]]);
  f.mean /= double(e - b);
  cv::Matx33d cov = cv::Matx33d::zeros();
  for (std::size_t k = b; k < e; ++k) {
    const glm::dvec3 d = glm::dvec3(points[idx[k]]) - f.mean;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) += d[r] * d[c];
  }
  cv::Mat values, vectors;
  const auto eigen_row = [&](int row) {
    return glm::dvec3(vectors.at<double>(row, 0), vectors.at<double>(row, 1), vectors.at<double>(row, 2));
  };
  if (glm::length(normal) > 0.5 * double(e - b)) {
    f.axis[2] = glm::normalize(normal);
    // Spread across the normal only.
    cv::Matx33d P = cv::Matx33d::eye();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) P(r, c) -= f.axis[2][r] * f.axis[2][c];
    cv::eigen(cv::Mat(P * cov * P), values, vectors);  // descending eigenvalues, eigenvectors as rows
    f.axis[0] = eigen_row(0) - glm::dot(eigen_row(0), f.axis[2]) * f.axis[2];
  } else {
    cv::eigen(cv::Mat(cov), values, vectors);
    f.axis[2] = glm::normalize(eigen_row(2));
    f.axis[0] = eigen_row(0) - glm::dot(eigen_row(0), f.axis[2]) * f.axis[2];
  }
  if (!(glm::length(f.axis[0]) > 0.5)) {  // no spread: any direction across the normal
    const glm::dvec3 a = std::abs(f.axis[2].x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    f.axis[0] = glm::cross(a, f.axis[2]);
  }
  f.axis[0] = glm::normalize(f.axis[0]);
  f.axis[1] = glm::cross(f.axis[2], f.axis[0]);
  for (std::size_t k = b; k < e; ++k)
    for (int a = 0; a < 3; ++a) {
      const double s = glm::dot(glm::dvec3(points[idx[k]]) - f.mean, f.axis[a]);
      f.lo[a] = std::min(f.lo[a], s), f.hi[a] = std::max(f.hi[a], s);
    }
  return f;
}

void add_grid(const std::vector<glm::vec3>& points, const std::vector<std::uint32_t>& idx, std::size_t b, std::size_t e,
              const Frame& f, ReceiverGrids& out) {
  ReceiverGrid g;
  g.origin = glm::vec3(f.mean);
  g.u_axis = glm::vec3(f.axis[0]), g.v_axis = glm::vec3(f.axis[1]), g.normal = glm::vec3(f.axis[2]);
  const std::size_t m = e - b;
  const double eu = f.hi.x - f.lo.x, ev = f.hi.y - f.lo.y;
  // About four receivers per bucket (twice their spacing): fewer rows to scan per cone,
  // a few more receivers to test at the ends of each row. A long thin group still gets
  // at most ~4 buckets per receiver.
  double cell = 2.0 * std::max({std::sqrt(eu * ev / double(m)), eu / double(m), 1e-4});
  while ((std::floor(eu / cell) + 1) * (std::floor(ev / cell) + 1) > 4.0 * double(m) + 16) cell *= 1.25;
  g.cell = float(cell);
  g.u0 = float(f.lo.x), g.v0 = float(f.lo.y);
  g.nu = int(std::floor(eu / cell)) + 1, g.nv = int(std::floor(ev / cell)) + 1;
  g.first_bucket = std::uint32_t(out.bucket_first.size());
  // Bucket of every point, with the same float arithmetic the culling uses; heights likewise.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed;  // (bucket, receiver)
  g.h_min = 1e30f, g.h_max = -1e30f;
  for (std::size_t k = b; k < e; ++k) {
    const glm::vec3 d = points[idx[k]] - g.origin;
    const float u = glm::dot(d, g.u_axis), v = glm::dot(d, g.v_axis), h = glm::dot(d, g.normal);
    const int i = std::clamp(int(std::floor((u - g.u0) / g.cell)), 0, g.nu - 1);
    const int j = std::clamp(int(std::floor((v - g.v0) / g.cell)), 0, g.nv - 1);
    keyed.push_back({std::uint32_t(j * g.nu + i), idx[k]});
    g.h_min = std::min(g.h_min, h), g.h_max = std::max(g.h_max, h);
  }
  std::sort(keyed.begin(), keyed.end());
  std::size_t cursor = 0;
  for (std::uint32_t bucket = 0; bucket < std::uint32_t(g.nu * g.nv); ++bucket) {
    out.bucket_first.push_back(std::uint32_t(out.order.size()));
    while (cursor < keyed.size() && keyed[cursor].first == bucket) out.order.push_back(keyed[cursor++].second);
  }
  out.grids.push_back(g);
}

void split(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& normals, std::vector<std::uint32_t>& idx,
           std::size_t b, std::size_t e, float flatness, ReceiverGrids& out) {
  const Frame f = frame_of(points, normals, idx, b, e);
  const double thickness = f.hi.z - f.lo.z, longest = std::max(f.hi.x - f.lo.x, f.hi.y - f.lo.y);
  if (e - b <= 2 || thickness <= flatness * longest + 1e-6) {
    add_grid(points, idx, b, e, f, out);
    return;
  }
  // Across the normal, at the middle of the range: separates a table top from the floor.
  const double mid = 0.5 * (f.lo.z + f.hi.z);
  const auto it =
      std::partition(idx.begin() + std::ptrdiff_t(b), idx.begin() + std::ptrdiff_t(e),
                     [&](std::uint32_t k) { return glm::dot(glm::dvec3(points[k]) - f.mean, f.axis[2]) < mid; });
  const auto m = std::size_t(it - idx.begin());
  if (m == b || m == e) {  // cannot happen for distinct heights; keep the group whole
    add_grid(points, idx, b, e, f, out);
    return;
  }
  split(points, normals, idx, b, m, flatness, out);
  split(points, normals, idx, m, e, flatness, out);
}

}  // namespace

ReceiverGrids build_receiver_grids(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& normals,
                                   float flatness) {
  if (normals.size() != points.size())
    throw InputError("build_receiver_grids: receiver points and normals differ in count");
  ReceiverGrids out;
  std::vector<std::uint32_t> idx(points.size());
  std::iota(idx.begin(), idx.end(), 0u);
  if (!idx.empty()) split(points, normals, idx, 0, idx.size(), flatness, out);
  out.bucket_first.push_back(std::uint32_t(out.order.size()));
  return out;
}

}  // namespace lumar
