// The camera's response and vignetting in the overlay: video pixels pass through
// unchanged, rendered pixels are encoded with the camera's response and darkened by its
// vignetting, against a CPU evaluation of the same model.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumar/base/error.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

// A gamma-2.2 camera with a different gain per channel (B, G, R).
gl::VideoRadiometry gamma_camera(double a, double b) {
  gl::VideoRadiometry radiometry;
  const float gains[3] = {0.8f, 1.0f, 1.3f};
  radiometry.linear_of_code.resize(3);
  for (int c = 0; c < 3; ++c)
    for (int v = 0; v < 256; ++v) radiometry.linear_of_code[c][v] = gains[c] * std::pow(v / 255.0f, 2.2f);
  radiometry.vignetting_a = a;
  radiometry.vignetting_b = b;
  return radiometry;
}

TEST(VideoRadiometry, VideoPassesThroughUnchanged) {
  headless_context();
  const CameraIntrinsics camera = make_camera(96, 64, 90, 90, 47.5, 31.5);
  gl::Renderer renderer(camera);
  renderer.set_video_radiometry(gamma_camera(-0.3, 0.05));
  cv::Mat video(64, 96, CV_8UC3);
  cv::randu(video, 0, 256);
  const cv::Mat out = renderer.render_overlay(video, std::nullopt, 1.0);
  EXPECT_EQ(cv::norm(out, video, cv::NORM_INF), 0.0) << "decode then encode must give the video back";
}

TEST(VideoRadiometry, RenderedPixelsGetTheResponseAndTheVignetting) {
  headless_context();
  const CameraIntrinsics camera = make_camera(160, 120, 140, 140, 83.0, 57.0);
  gl::Renderer renderer(camera);
  const double a = -0.3, b = 0.05;
  renderer.set_video_radiometry(gamma_camera(a, b));
  // A quad filling the view, lit by a uniform radiance of 1: linear = albedo * exposure.
  const int id = renderer.add_object(make_quad({0, 0, -1}, {1.5f, 0, 0}, {0, 1.5f, 0}, {0, 0, 1}));
  const glm::vec3 albedo(0.5f, 0.3f, 0.2f);  // R, G, B
  renderer.set_object_material(id, albedo, uniform_sh(1.0));
  const double exposure = 0.9;
  const cv::Mat out =
      renderer.render_overlay(cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(0)), look_at({0, 0, 0}, {0, 0, -1}), exposure);
  const float gains[3] = {0.8f, 1.0f, 1.3f};
  const double linear_bgr[3] = {albedo.b * exposure, albedo.g * exposure, albedo.r * exposure};
  const double half_diagonal = 0.5 * std::hypot(160.0, 120.0);
  int worst = 0;
  double corner_ratio = 0;
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      const double r2 = (std::pow(x - 83.0, 2) + std::pow(y - 57.0, 2)) / (half_diagonal * half_diagonal);
      const double gain = 1 + a * r2 + b * r2 * r2;
      for (int c = 0; c < 3; ++c) {
        const double code = 255.0 * std::pow(std::min(1.0, linear_bgr[c] * gain / gains[c]), 1 / 2.2);
        worst = std::max(worst, int(std::lround(std::abs(out.at<cv::Vec3b>(y, x)[c] - code))));
      }
    }
  corner_ratio = double(out.at<cv::Vec3b>(0, 0)[1]) / out.at<cv::Vec3b>(57, 83)[1];
  std::printf("response + vignetting: worst %d levels; corner/centre green %.3f\n", worst, corner_ratio);
  EXPECT_LE(worst, 1);
  EXPECT_LT(corner_ratio, 0.93);  // the fall-off is really there
}

TEST(VideoRadiometry, RejectsABadTable) {
  headless_context();
  gl::Renderer renderer(make_camera(32, 24, 30, 30, 16, 12));
  gl::VideoRadiometry bad = gamma_camera(0, 0);
  bad.linear_of_code[1][100] = 0.0f;  // decreasing
  EXPECT_THROW(renderer.set_video_radiometry(bad), InputError);
  bad.linear_of_code.resize(2);
  EXPECT_THROW(renderer.set_video_radiometry(bad), InputError);
}

}  // namespace
}  // namespace lumar::test
