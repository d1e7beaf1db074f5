// Virtual object shading: radiance = albedo * E(n) / pi * exposure, E from nine SH
// coefficients, encoded to sRGB. Compared with the colour transfer in color.h and a CPU
// evaluation of the Ramamoorthi-Hanrahan formula on coefficients integrated here.
#include <gtest/gtest.h>

#include <numbers>

#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

// Brute-force projection of a radiance function onto the basis, texel by texel.
template <class Radiance>
SH9 integrate_sh(Radiance radiance, int width, int height) {
  SH9 sh;
  for (int r = 0; r < height; ++r) {
    const double solid_angle = latlong_pixel_solid_angle(r, width, height);
    for (int c = 0; c < width; ++c) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, width, height);
      const glm::dvec3 L = radiance(d);
      const auto Y = sh_basis(d);
      for (int k = 0; k < 9; ++k) sh.coefficients[k] += L * Y[k] * solid_angle;
    }
  }
  return sh;
}

int encoded_level(double linear) { return int(std::lround(255.0 * linear_to_srgb(float(linear)))); }

// One small quad per normal, in a grid facing the camera; the vertex normals carry n.
struct QuadGrid {
  explicit QuadGrid(const std::vector<glm::dvec3>& normals) {
    renderer = std::make_unique<gl::Renderer>(camera);
    for (std::size_t i = 0; i < normals.size(); ++i) {
      const float x = -0.75f + 0.5f * float(i % 4), y = 0.45f - 0.45f * float(i / 4);
      ids.push_back(renderer->add_object(
          make_quad({x, y, -2.0f}, {0.15f, 0, 0}, {0, 0.15f, 0}, glm::vec3(glm::normalize(normals[i])))));
      const glm::dvec2 px = project_pinhole(camera, pose.inverse().apply({x, y, -2.0}));
      centres.emplace_back(int(std::lround(px.x)), int(std::lround(px.y)));
    }
  }
  CameraIntrinsics camera = make_camera(240, 180, 200, 200, 120, 90);
  Pose pose = look_at({0, 0, 0}, {0, 0, -1});
  std::unique_ptr<gl::Renderer> renderer;
  std::vector<cv::Point> centres;
  std::vector<int> ids;
};

// How far (relative) a linear value lies outside the interval an 8-bit sRGB level stands for.
double relative_error_beyond_quantisation(int level, double expected) {
  const double lo = srgb_to_linear(float(std::max(level - 0.5, 0.0) / 255.0));
  const double hi = srgb_to_linear(float(std::min(level + 0.5, 255.0) / 255.0));
  return std::max({0.0, lo - expected, expected - hi}) / std::max(expected, 1e-3);
}

TEST(RenderShading, UniformLightGivesAlbedoTimesExposure) {
  headless_context();
  const CameraIntrinsics camera = make_camera(160, 120, 140, 140, 80.3, 59.6);
  gl::Renderer renderer(camera);
  renderer.set_features({.antialiasing = false});  // no partly covered pixels around the mask
  const int id = renderer.add_object(make_sphere({0, 0, 0}, 0.4f, 32, 16));
  const glm::vec3 albedo(0.5f, 0.25f, 0.75f);
  renderer.set_object_material(id, albedo, uniform_sh(1.0));
  renderer.set_object_pose(id, glm::dmat4(1.0));
  const Pose pose = look_at({0.3, 0.5, 1.5}, {0, 0, 0});
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  const cv::Mat out = renderer.render_overlay(black, pose, 0.8);
  const cv::Mat mask = renderer.render_object_mask(pose);
  ASSERT_GT(cv::countNonZero(mask), 2000);

  // BGR order in the image.
  const int expected[3] = {encoded_level(0.75 * 0.8), encoded_level(0.25 * 0.8), encoded_level(0.5 * 0.8)};
  int worst = 0, background_worst = 0;
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const int v = out.at<cv::Vec3b>(r, c)[k];
        if (mask.at<uchar>(r, c))
          worst = std::max(worst, std::abs(v - expected[k]));
        else
          background_worst = std::max(background_worst, v);
      }
  std::printf("uniform light: expected BGR (%d, %d, %d), max |diff| %d levels over %d object pixels\n", expected[0],
              expected[1], expected[2], worst, cv::countNonZero(mask));
  EXPECT_LE(worst, 1);
  EXPECT_EQ(background_worst, 0);
}

TEST(RenderShading, DirectionalIrradianceMatchesCpuFormula) {
  headless_context();
  // Upper hemisphere only, the reference case: E(up) = pi, E(down) = 0, E(sideways) = pi / 2,
  // and order-2 SH is exact at these three normals.
  const SH9 hemisphere =
      integrate_sh([](const glm::dvec3& d) { return d.y > 0 ? glm::dvec3(1.0) : glm::dvec3(0.0); }, 512, 256);
  EXPECT_NEAR(sh_irradiance_reference(hemisphere, {0, 1, 0}).x, kPi, 0.01 * kPi);
  EXPECT_NEAR(sh_irradiance_reference(hemisphere, {0, -1, 0}).x, 0.0, 0.01 * kPi);
  EXPECT_NEAR(sh_irradiance_reference(hemisphere, {1, 0, 0}).x, kPi / 2, 0.01 * kPi);
  EXPECT_NEAR(sh_irradiance_reference(hemisphere, {0, 0, -1}).x, kPi / 2, 0.01 * kPi);

  // A light that fills all nine coefficients: the upper hemisphere, brighter towards +x,
  // different per channel.
  const SH9 sky = integrate_sh(
      [](const glm::dvec3& d) {
        if (d.y <= 0) return glm::dvec3(0.05);
        return glm::dvec3(0.8 + 0.6 * d.x, 0.6 + 0.4 * d.z * d.x, 0.5 + 0.5 * d.y * d.y - 0.3 * d.z);
      },
      256, 128);

  const std::vector<glm::dvec3> normals = {{0, 1, 0},          {0, -1, 0},      {1, 0, 0},        {-1, 0, 0},
                                           {0, 0, 1},          {0, 0, -1},      {1, 1, 0},        {0.3, -0.5, 0.81},
                                           {-0.6, 0.2, -0.77}, {0.5, 0.7, 0.5}, {-0.2, 0.9, 0.4}, {0.7, -0.1, -0.7}};
  const std::vector<std::pair<const char*, SH9>> lights = {{"hemisphere", hemisphere}, {"sky", sky}};
  QuadGrid grid(normals);
  const glm::vec3 albedo(0.9f, 0.7f, 0.8f);
  const double exposure = 0.55;

  double worst_relative = 0;
  int worst_levels = 0;
  for (const auto& [name, sh] : lights) {
    for (int id : grid.ids) grid.renderer->set_object_material(id, albedo, sh);
    const cv::Mat black(grid.camera.height, grid.camera.width, CV_8UC3, cv::Scalar::all(0));
    const cv::Mat out = grid.renderer->render_overlay(black, grid.pose, exposure);
    for (std::size_t i = 0; i < normals.size(); ++i) {
      const glm::dvec3 E = glm::max(sh_irradiance_reference(sh, glm::normalize(normals[i])), glm::dvec3(0.0));
      const glm::dvec3 linear = glm::dvec3(albedo) * E / kPi * exposure;
      for (int k = 0; k < 3; ++k) {
        const double expected = linear[2 - k];  // image is BGR
        const int level = out.at<cv::Vec3b>(grid.centres[i])[k];
        // The GPU's 8-bit level stands for the linear interval it quantises; the CPU value
        // must lie within 1% of that interval.
        const double relative = relative_error_beyond_quantisation(level, expected);
        worst_relative = std::max(worst_relative, relative);
        worst_levels = std::max(worst_levels, std::abs(level - encoded_level(expected)));
        EXPECT_LE(relative, 0.01) << name << " normal " << i << " channel " << k << ": level " << level
                                  << ", expected linear " << expected;
      }
    }
  }
  std::printf("directional SH: GPU vs CPU beyond 8-bit quantisation: max %.4f %%, max |diff| %d levels\n",
              100.0 * worst_relative, worst_levels);
  EXPECT_LE(worst_levels, 1);
}

TEST(RenderShading, AgreesWithCoreShProjectionAndIrradiance) {
  // The producer of the coefficients (sh.cpp) and the shader must share the basis order
  // and frame: a map with an azimuth offset, projected by the core, shaded on the GPU,
  // compared with the core's CPU irradiance.
  headless_context();
  EnvironmentMap map;
  map.width = 128;
  map.height = 64;
  map.azimuth_offset_deg = 40.0;
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, map.width, map.height);
      const bool window = d.x > 0.5 && d.y > 0.1;  // a bright patch, up and to one side
      map.rgb.insert(map.rgb.end(), {float(0.2 + (window ? 3.0 : 0.0)), float(0.3 + 0.2 * d.y),
                                     float(0.25 + (window ? 1.5 : 0.0) + 0.1 * d.z)});
    }
  const SH9 sh = project_radiance_sh9(map);
  const std::vector<glm::dvec3> normals = {{1, 0.3, 0}, {0, 1, 0},        {-1, 0, 0},      {0, 0, 1},
                                           {0, 0, -1},  {0.6, 0.6, -0.5}, {0.6, 0.6, 0.5}, {0, -1, 0}};
  QuadGrid grid(normals);
  const glm::vec3 albedo(0.6f, 0.8f, 0.7f);
  const double exposure = 0.35;
  for (int id : grid.ids) grid.renderer->set_object_material(id, albedo, sh);
  const cv::Mat black(grid.camera.height, grid.camera.width, CV_8UC3, cv::Scalar::all(0));
  const cv::Mat out = grid.renderer->render_overlay(black, grid.pose, exposure);
  double worst = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const glm::dvec3 E = glm::max(sh9_irradiance(sh, glm::normalize(normals[i])), glm::dvec3(0.0));
    const glm::dvec3 linear = glm::dvec3(albedo) * E / kPi * exposure;
    for (int k = 0; k < 3; ++k) {
      const int level = out.at<cv::Vec3b>(grid.centres[i])[k];
      const double relative = relative_error_beyond_quantisation(level, linear[2 - k]);
      worst = std::max(worst, relative);
      EXPECT_LE(relative, 0.01) << "normal " << i << " channel " << k;
    }
  }
  std::printf("GPU vs core sh9_irradiance: max %.4f %% beyond 8-bit quantisation\n", 100.0 * worst);
}

}  // namespace
}  // namespace lumar::test
