// The proxy room textured by the environment map projected from its capture point,
// compared with an analytic ray cast of the room box and a CPU lat-long lookup.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

const glm::dvec3 kRoomMin(-2.0, 0.0, -3.0), kRoomMax(3.0, 2.6, 2.5);

EnvironmentMap make_map(int width, int height, glm::dvec3 capture, double offset_deg,
                        glm::vec3 (*texel)(double u01, double v01)) {
  EnvironmentMap map;
  map.width = width;
  map.height = height;
  map.capture_position = capture;
  map.azimuth_offset_deg = offset_deg;
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const glm::vec3 v = texel((c + 0.5) / width, (r + 0.5) / height);
      map.rgb.insert(map.rgb.end(), {v.x, v.y, v.z});
    }
  return map;
}

// Bilinear lookup with texel centres at (c + 0.5, r + 0.5), wrapping in u, clamped in v.
glm::dvec3 bilinear(const EnvironmentMap& map, glm::dvec2 uv) {
  const double x = uv.x - 0.5, y = uv.y - 0.5;
  const int c0 = int(std::floor(x)), r0 = int(std::floor(y));
  const double fx = x - c0, fy = y - r0;
  const auto at = [&](int c, int r) {
    c = ((c % map.width) + map.width) % map.width;
    r = std::clamp(r, 0, map.height - 1);
    return glm::dvec3(map.texel(c, r));
  };
  return glm::mix(glm::mix(at(c0, r0), at(c0 + 1, r0), fx), glm::mix(at(c0, r0 + 1), at(c0 + 1, r0 + 1), fx), fy);
}

// Where a ray from inside the box leaves it.
glm::dvec3 exit_point(const glm::dvec3& origin, const glm::dvec3& dir) {
  double t = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] > 0) t = std::min(t, (kRoomMax[a] - origin[a]) / dir[a]);
    if (dir[a] < 0) t = std::min(t, (kRoomMin[a] - origin[a]) / dir[a]);
  }
  return origin + t * dir;
}

class RenderRoomRadiance : public testing::Test {
 protected:
  void SetUp() override {
    headless_context();
    renderer = std::make_unique<gl::Renderer>(make_camera(64, 48, 60, 60, 32, 24));
    renderer->set_room(make_box(glm::vec3(kRoomMin), glm::vec3(kRoomMax), true));
  }
  // Differs from the constructor's camera in size and intrinsics, as the synth's margin does.
  const CameraIntrinsics camera = make_camera(200, 150, 110.0, 112.0, 97.3, 80.1);
  const Pose pose = look_at({0.4, 1.5, 1.0}, {-1.0, 1.9, -2.0}, 12.0);
  std::unique_ptr<gl::Renderer> renderer;
};

TEST_F(RenderRoomRadiance, UniformMapGivesItsColourEverywhere) {
  renderer->set_environment(
      make_map(64, 32, {0.3, 1.2, -0.4}, 35.0, [](double, double) { return glm::vec3(0.2f, 0.4f, 0.6f); }));
  const cv::Mat out = renderer->render_room_radiance(camera, pose);
  ASSERT_EQ(out.type(), CV_32FC3);
  ASSERT_EQ(out.size(), cv::Size(200, 150));
  double worst = 0;
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c) {
      const cv::Vec3f v = out.at<cv::Vec3f>(r, c);  // BGR
      worst = std::max({worst, std::abs(v[0] - 0.6), std::abs(v[1] - 0.4), std::abs(v[2] - 0.2)});
    }
  std::printf("uniform map: max |diff| %.2e\n", worst);
  EXPECT_LE(worst, 1e-4);
}

TEST_F(RenderRoomRadiance, GradientMapMatchesRayCastAndCpuLookup) {
  const glm::dvec3 capture(0.3, 1.2, -0.4);
  const double offset_deg = 35.0;
  // Smooth in both directions and periodic in u; every channel varies differently.
  const EnvironmentMap map = make_map(128, 64, capture, offset_deg, [](double u, double v) {
    const double phi = 2 * std::numbers::pi * u;
    return glm::vec3(float(1.0 + 0.5 * std::cos(phi)), float(0.3 + 1.5 * v),
                     float(1.0 + 0.6 * std::sin(2 * phi) * v + 0.2 * std::cos(3 * phi)));
  });
  renderer->set_environment(map);
  const cv::Mat out = renderer->render_room_radiance(camera, pose);

  const glm::dmat3 R = pose.rotation_matrix();
  const double a = glm::radians(offset_deg);
  double worst = 0, sum = 0, worst_core = 0;
  int count = 0;
  for (int r = 0; r < out.rows; r += 2)
    for (int c = 0; c < out.cols; c += 2) {
      const glm::dvec3 ray = R * glm::dvec3((c - camera.cx) / camera.fx, (r - camera.cy) / camera.fy, 1.0);
      const glm::dvec3 d = exit_point(pose.translation, ray) - capture;
      // map direction = Ry(-offset) * world direction
      const glm::dvec3 m(std::cos(a) * d.x - std::sin(a) * d.z, d.y, std::sin(a) * d.x + std::cos(a) * d.z);
      const glm::dvec2 uv = latlong_coordinates(m, map.width, map.height);
      if (uv.y < 1.0 || uv.y > map.height - 1.0) continue;  // the poles, where v clamps
      const glm::dvec3 expected = bilinear(map, uv);
      // The core's own lookup (envmap.cpp) must agree with the renderer too.
      const glm::dvec3 core = glm::dvec3(map.radiance(d));
      const cv::Vec3f got = out.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) {
        const double rel = std::abs(got[k] - expected[2 - k]) / expected[2 - k];
        worst = std::max(worst, rel);
        sum += rel;
        worst_core = std::max(worst_core, std::abs(got[k] - core[2 - k]) / core[2 - k]);
      }
      ++count;
    }
  std::printf("gradient map: %d pixels, relative error mean %.2e, max %.2e (vs EnvironmentMap::radiance max %.2e)\n",
              count, sum / (3.0 * count), worst, worst_core);
  EXPECT_GT(count, 5000);
  EXPECT_LE(worst, 0.01);
  EXPECT_LE(worst_core, 0.01);
}

TEST_F(RenderRoomRadiance, PixelsThatSeeNoRoomAreZero) {
  // From outside the box, looking past it: only the box's pixels are non-zero.
  renderer->set_environment(make_map(16, 8, {0, 1, 0}, 0.0, [](double, double) { return glm::vec3(1.0f); }));
  const Pose outside = look_at({0.5, 1.3, 12.0}, {0.5, 1.3, 0.0});
  const cv::Mat out = renderer->render_room_radiance(camera, outside);
  cv::Mat gray;
  cv::extractChannel(out, gray, 1);
  const int lit = cv::countNonZero(gray);
  // The box's front face (z = 2.5) seen from z = 12: 5 m x 2.6 m at 9.5 m.
  const double area = (110.0 * 5.0 / 9.5) * (112.0 * 2.6 / 9.5);
  std::printf("room seen from outside: %d lit px, analytic %.0f\n", lit, area);
  EXPECT_NEAR(lit, area, 0.03 * area);
  double lo = 0, hi = 0;
  cv::minMaxLoc(gray, &lo, &hi, nullptr, nullptr, gray != 0);
  EXPECT_NEAR(lo, 1.0, 1e-4);
  EXPECT_NEAR(hi, 1.0, 1e-4);
}

TEST(RenderRoomRadianceErrors, NeedsAnEnvironment) {
  headless_context();
  gl::Renderer renderer(make_camera(32, 24, 30, 30, 16, 12));
  EXPECT_THROW(renderer.render_room_radiance(make_camera(32, 24, 30, 30, 16, 12), Pose{}), RuntimeError);
}

}  // namespace
}  // namespace lumar::test
