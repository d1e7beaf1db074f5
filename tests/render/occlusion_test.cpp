// The proxy room occludes virtual objects: behind a wall nothing shows, in front all
// of the object does (its silhouette area matches the analytic disc), and a half wall
// hides exactly one half.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

TEST(RenderOcclusion, ProxyWallHidesObjectsBehindIt) {
  headless_context();
  const CameraIntrinsics camera = make_camera(320, 240, 300, 300, 160.0, 120.0);
  const Pose pose = look_at({0, 0, 0}, {0, 0, -1});  // looking down -z
  gl::Renderer renderer(camera);
  renderer.set_features({.antialiasing = false});  // whole pixels, to count them
  const float radius = 0.3f;
  const int sphere = renderer.add_object(make_sphere({0, 0, 0}, radius, 64, 32));
  renderer.set_object_material(sphere, glm::vec3(1.0f), SH9{});
  // A wall at z = -3, spanning the view.
  renderer.set_room(make_quad({0, 0, -3}, {5, 0, 0}, {0, 5, 0}, {0, 0, 1}));

  renderer.set_object_pose(sphere, glm::translate(glm::dmat4(1.0), {0, 0, -4}));
  EXPECT_EQ(cv::countNonZero(renderer.render_object_mask(pose)), 0);
  // The composite is then the video alone.
  const cv::Mat video(240, 320, CV_8UC3, cv::Scalar(90, 60, 30));
  cv::Mat diff;
  cv::absdiff(renderer.render_overlay(video, pose, 1.0), video, diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);

  renderer.set_object_pose(sphere, glm::translate(glm::dmat4(1.0), {0, 0, -2}));
  const int visible = cv::countNonZero(renderer.render_object_mask(pose));
  // Silhouette of a sphere straight ahead: a disc of radius f r / sqrt(d^2 - r^2).
  const double disc_radius = 300.0 * radius / std::sqrt(4.0 - radius * radius);
  const double disc_area = std::numbers::pi * disc_radius * disc_radius;
  std::printf("sphere in front of the wall: %d px, analytic disc %.1f px\n", visible, disc_area);
  EXPECT_NEAR(visible, disc_area, 0.02 * disc_area);
  // Unlit (zero SH) and black: the object covers the video.
  cv::Mat gray;
  cv::cvtColor(renderer.render_overlay(video, pose, 1.0), gray, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::countNonZero(gray == 0), visible);
}

TEST(RenderOcclusion, HalfWallHidesHalfTheObject) {
  headless_context();
  const CameraIntrinsics camera = make_camera(320, 240, 300, 300, 160.0, 120.0);
  const Pose pose = look_at({0, 0, 0}, {0, 0, -1});
  gl::Renderer renderer(camera);
  const int sphere = renderer.add_object(make_sphere({0, 0, 0}, 0.3f, 64, 32));
  renderer.set_object_pose(sphere, glm::translate(glm::dmat4(1.0), {0, 0, -4}));
  const int full = cv::countNonZero(renderer.render_object_mask(pose));
  // The wall covers x < 0 at z = -3: the left half of the image.
  renderer.set_room(make_quad({-2.5f, 0, -3}, {2.5f, 0, 0}, {0, 5, 0}, {0, 0, 1}));
  const cv::Mat mask = renderer.render_object_mask(pose);
  int left = 0;
  for (int r = 0; r < mask.rows; ++r)
    for (int c = 0; c < 160; ++c) left += mask.at<uchar>(r, c) ? 1 : 0;
  const int visible = cv::countNonZero(mask);
  std::printf("half wall: %d of %d px visible, %d left of the centre\n", visible, full, left);
  EXPECT_EQ(left, 0);
  EXPECT_NEAR(visible, full / 2.0, 0.03 * full);
}

}  // namespace
}  // namespace lumar::test
