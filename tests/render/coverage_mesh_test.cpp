// The antialiasing's coverage from simplified meshes (gl::Renderer::set_coverage_mesh_error):
// a finely tessellated sphere, white on black, whose outline is an analytic circle, drawn
// far and near. Each outline pixel's value is the coverage the antialiasing gave it; where
// that is more than half a pixel off the circle's own coverage (8 x 8 samples per pixel),
// the pixel is no farther from the circle than the error allowed (plus half a pixel for the
// 4 samples). Far away fewer triangles are drawn than near; inside the object's box, all.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lumar/base/error.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

constexpr float kRadius = 0.5f;
const CameraIntrinsics kCamera = make_camera(640, 480, 300, 300, 319.5, 239.5);

struct Sphere {
  explicit Sphere(double coverage_error_px) : renderer(kCamera) {
    mesh = make_sphere({0, 0, 0}, kRadius, 128, 64);
    const int id = renderer.add_object(mesh);
    renderer.set_object_material(id, glm::vec3(1.0f), uniform_sh(1.0));  // linear value 1
    renderer.set_features({.antialiasing = true, .self_occlusion = false, .noise = false, .blur = false});
    renderer.set_coverage_mesh_error(coverage_error_px);
  }
  // Each pixel's coverage as drawn: its linear value (green).
  cv::Mat coverage(const Pose& pose) {
    const cv::Mat black(kCamera.height, kCamera.width, CV_8UC3, cv::Scalar::all(0));
    cv::Mat c;
    cv::extractChannel(linear_of(renderer.render_overlay(black, pose, 1.0)), c, 1);
    return c;
  }
  Mesh mesh;
  gl::Renderer renderer;
};

struct OutlineMiss {
  double worst_px = 0.0;  // the farthest a pixel more than half off its coverage is from the circle
  double area_px = 0.0;   // the covered area drawn
  double circle_area_px = 0.0;
};

// The sphere seen from distance d straight on is a disc of radius f r / sqrt(d^2 - r^2).
OutlineMiss outline_miss(const cv::Mat& coverage, double distance) {
  const double radius = kCamera.fx * kRadius / std::sqrt(distance * distance - kRadius * kRadius);
  OutlineMiss m;
  m.circle_area_px = std::numbers::pi * radius * radius;
  m.area_px = cv::sum(coverage)[0];
  for (int y = 0; y < coverage.rows; ++y)
    for (int x = 0; x < coverage.cols; ++x) {
      const double rho = std::hypot(x - kCamera.cx, y - kCamera.cy);
      if (std::abs(rho - radius) > 2.0 + gl::Renderer::kMaxCoverageErrorPx) continue;  // all in or all out
      double inside = 0.0;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
          inside += std::hypot(x - 0.5 + (i + 0.5) / 8 - kCamera.cx, y - 0.5 + (j + 0.5) / 8 - kCamera.cy) < radius;
      if (std::abs(coverage.at<float>(y, x) - inside / 64.0) > 0.5)
        m.worst_px = std::max(m.worst_px, std::abs(rho - radius));
    }
  return m;
}

TEST(CoverageMesh, SmallOnScreenFewerTrianglesWithinTheAllowedPixels) {
  headless_context();
  const Pose far = look_at({0, 0, 6}, {0, 0, 0}), near = look_at({0, 0, 0.9}, {0, 0, 0});
  Sphere exact(0.0);
  const std::size_t all = exact.mesh.triangle_count();
  const OutlineMiss as_given = outline_miss(exact.coverage(far), 6.0);
  EXPECT_EQ(exact.renderer.coverage_triangles(), all);
  EXPECT_NEAR(as_given.area_px, as_given.circle_area_px, 0.005 * as_given.circle_area_px);
  EXPECT_LT(as_given.worst_px, 1.0);
  // As coarse as allowed, the near sphere is off its outline by more than 1 px allows:
  // the measure sees a mesh too coarse. (meshoptimizer's errors are on the safe side: the
  // outlines are well within what was allowed.)
  Sphere coarsest(gl::Renderer::kMaxCoverageErrorPx);
  const OutlineMiss coarsest_near = outline_miss(coarsest.coverage(near), 0.9);
  EXPECT_GT(coarsest_near.worst_px, as_given.worst_px + 1.0);
  std::printf("as given: %zu triangles, outline within %.2f px, area %.1f of %.1f px; %g px near: %zu, %.2f px\n", all,
              as_given.worst_px, as_given.area_px, as_given.circle_area_px, gl::Renderer::kMaxCoverageErrorPx,
              coarsest.renderer.coverage_triangles(), coarsest_near.worst_px);

  for (double px : {1.0, 4.0}) {
    Sphere coarse(px);
    const OutlineMiss f = outline_miss(coarse.coverage(far), 6.0);
    const std::size_t far_triangles = coarse.renderer.coverage_triangles();
    EXPECT_LT(far_triangles, all / 2) << px << " px";
    EXPECT_LE(f.worst_px, px + 0.5) << px << " px";
    // The simplified meshes' corners are the sphere's: their outline lies inside the circle.
    EXPECT_LE(f.area_px, as_given.area_px + 1.0) << px << " px";
    EXPECT_GE(f.area_px,
              as_given.area_px - 2.0 * std::numbers::pi * std::sqrt(f.circle_area_px / std::numbers::pi) * px);
    const OutlineMiss n = outline_miss(coarse.coverage(near), 0.9);
    EXPECT_GT(coarse.renderer.coverage_triangles(), far_triangles) << "nearer: finer";
    EXPECT_LE(n.worst_px, px + 0.5) << px << " px, near";
    std::printf("%g px: %zu triangles at 6 m (within %.2f px), %zu at 0.9 m (%.2f px)\n", px, far_triangles, f.worst_px,
                coarse.renderer.coverage_triangles(), n.worst_px);
    // From inside the object's box any error is too much: the mesh as given.
    coarse.coverage(look_at({0, 0, 0.3}, {0, 0, -1}));
    EXPECT_EQ(coarse.renderer.coverage_triangles(), all);
  }
  Sphere four(4.0), one(1.0);
  four.coverage(near);
  one.coverage(near);
  EXPECT_LT(four.renderer.coverage_triangles(), one.renderer.coverage_triangles()) << "more allowed: coarser";
}

TEST(CoverageMesh, OutOfRangeIsRefusedAndChangesNothing) {
  headless_context();
  Sphere s(1.0);
  EXPECT_THROW(s.renderer.set_coverage_mesh_error(-0.5), InputError);
  EXPECT_THROW(s.renderer.set_coverage_mesh_error(gl::Renderer::kMaxCoverageErrorPx + 1), InputError);
  EXPECT_THROW(s.renderer.set_coverage_mesh_error(std::nan("")), InputError);
  EXPECT_EQ(s.renderer.coverage_mesh_error(), 1.0);
}

}  // namespace
}  // namespace lumar::test
