// Every pixel the renderer covers must hold a world point that OpenCV projects back
// onto that pixel: the OpenGL matrices agree with cv::projectPoints to a small
// fraction of a pixel, including the half-pixel and row-flip conventions.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/calib3d.hpp>

#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

struct ProjectionError {
  double mean = 0, max = 0;
  int covered = 0;
};

ProjectionError reprojection_error(const cv::Mat& world, const CameraIntrinsics& camera, const Pose& pose) {
  std::vector<cv::Point3d> points;
  std::vector<cv::Point2d> pixels;
  for (int r = 0; r < world.rows; ++r)
    for (int c = 0; c < world.cols; ++c) {
      const cv::Vec4f w = world.at<cv::Vec4f>(r, c);
      if (w[3] == 0.0f) continue;
      points.emplace_back(w[0], w[1], w[2]);
      pixels.emplace_back(c, r);
    }
  ProjectionError e;
  e.covered = int(points.size());
  if (points.empty()) return e;
  cv::Mat rvec, tvec;
  rvec_tvec(pose, rvec, tvec);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(points, rvec, tvec, cv::Mat(camera.camera_matrix()), cv::noArray(), projected);
  for (std::size_t i = 0; i < projected.size(); ++i) {
    const double d = cv::norm(projected[i] - pixels[i]);
    e.mean += d;
    e.max = std::max(e.max, d);
  }
  e.mean /= double(projected.size());
  return e;
}

TEST(RenderProjection, CoveredPixelsReprojectOntoThemselves) {
  headless_context();
  const CameraIntrinsics camera = make_camera(640, 480, 536.1, 536.0, 342.4, 235.5);
  gl::Renderer renderer(camera);
  const int sphere = renderer.add_object(make_sphere({0, 0, 0}, 0.25f, 48, 24));
  const int box = renderer.add_object(make_box({-0.2f, -0.1f, -0.15f}, {0.2f, 0.1f, 0.15f}));

  struct Case {
    const char* name;
    Pose camera;
    glm::dmat4 sphere, box;
  };
  const glm::dmat4 far_away = glm::translate(glm::dmat4(1.0), {0, -100, 0});
  const std::vector<Case> cases = {
      {"centred", look_at({0, 1.4, 1.6}, {0, 1.0, 0}), glm::translate(glm::dmat4(1.0), {0.1, 1.0, 0}), far_away},
      {"off-centre, rolled camera", look_at({1.2, 1.7, 1.4}, {0.1, 0.9, -0.3}, 23.0),
       glm::translate(glm::dmat4(1.0), {0.8, 1.3, -0.2}),
       glm::rotate(glm::translate(glm::dmat4(1.0), {-0.3, 0.7, 0.1}), glm::radians(37.0),
                   glm::normalize(glm::dvec3(1, 2, -1)))},
      {"scaled, rotated box near the corner", look_at({-0.8, 0.4, 2.0}, {0.5, 1.2, -0.5}, -70.0), far_away,
       glm::scale(glm::rotate(glm::translate(glm::dmat4(1.0), {0.0, 0.7, 0.3}), glm::radians(-121.0),
                              glm::normalize(glm::dvec3(0.3, -1, 0.4))),
                  {1.5, 0.7, 1.2})},
  };
  for (const Case& c : cases) {
    renderer.set_object_pose(sphere, c.sphere);
    renderer.set_object_pose(box, c.box);
    const cv::Mat world = renderer.render_object_world_positions(c.camera);
    ASSERT_EQ(world.type(), CV_32FC4);
    ASSERT_EQ(world.size(), cv::Size(640, 480));
    const ProjectionError e = reprojection_error(world, camera, c.camera);
    std::printf("%-40s covered %6d px, reprojection mean %.5f px, max %.5f px\n", c.name, e.covered, e.mean, e.max);
    EXPECT_GT(e.covered, 1000) << c.name;
    EXPECT_LE(e.mean, 0.05) << c.name;
    EXPECT_LE(e.max, 0.5) << c.name;

    // The mask is the covered set.
    const cv::Mat mask = renderer.render_object_mask(c.camera);
    EXPECT_EQ(cv::countNonZero(mask), e.covered) << c.name;
  }
}

}  // namespace
}  // namespace lumar::test
