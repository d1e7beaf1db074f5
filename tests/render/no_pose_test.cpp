// A frame without a camera pose shows the video alone: the object that would stand in
// front of the camera is not drawn, and the background is unchanged.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "lumar/render/renderer.h"
#include "render_test_util.h"

using namespace lumar;

TEST(NoPose, DrawsTheVideoAloneWithoutAnObject) {
  test::headless_context();
  const CameraIntrinsics camera = test::make_camera(160, 120, 130, 130, 79.5, 59.5);
  gl::Renderer with_object(camera), empty(camera);
  const int id = with_object.add_object(test::make_sphere({0, 0, 0}, 0.3f, 24, 12));
  SH9 sh;
  sh.coefficients[0] = glm::dvec3(0.282095 * 4 * 3.14159265358979);  // uniform radiance 1
  with_object.set_object_material(id, {0.9f, 0.9f, 0.9f}, sh);

  cv::Mat video(camera.height, camera.width, CV_8UC3);
  cv::randu(video, 0, 255);
  const Pose eye = test::look_at({0, 0, 2}, {0, 0, 0});

  const cv::Mat posed = with_object.render_overlay(video, eye, 1.0);
  const cv::Mat unposed = with_object.render_overlay(video, std::nullopt, 1.0);
  const cv::Mat reference = empty.render_overlay(video, std::nullopt, 1.0);
  // The sphere covers the middle when posed (so the check below can fail)...
  EXPECT_GT(cv::norm(posed, reference, cv::NORM_L1) / posed.total(), 10.0);
  // ...and is absent without a pose.
  EXPECT_EQ(cv::norm(unposed, reference, cv::NORM_INF), 0.0);
}
