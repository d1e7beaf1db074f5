// LightSelfShadow against shadows drawn by hand: a ball floating over a plate, one mesh,
// under one or two distant lights; and the volume's evaluation split in two parts (the
// probes' light and the exact lights) that add up to the whole.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "irradiance_test_util.h"
#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/lighting/light_self_shadow.h"
#include "lumar/lighting/room_radiance.h"
#include "test_geometry.h"

namespace lumar {
namespace {

constexpr float kRadius = 0.5f, kHeight = 1.5f;

// A 4 m plate whose top is y = 0 (17 × 17 vertices facing up) and a ball of kRadius
// floating kHeight above its middle: one object.
Mesh ball_over_plate() {
  Mesh m = test::make_box({-2, -0.1f, -2}, {2, 0, 2}, false, 16);
  const Mesh ball = test::make_sphere({0, kHeight, 0}, kRadius, 48, 24);
  const auto base = std::uint32_t(m.positions.size());
  m.positions.insert(m.positions.end(), ball.positions.begin(), ball.positions.end());
  m.normals.insert(m.normals.end(), ball.normals.begin(), ball.normals.end());
  for (std::uint32_t i : ball.indices) m.indices.push_back(base + i);
  return m;
}

VolumeLight distant_light(const glm::dvec3& toward, double radiance, double solid_angle) {
  VolumeLight l;
  l.direction = glm::normalize(toward);
  l.radiance = glm::dvec3(radiance);
  l.solid_angle = solid_angle;
  return l;
}

bool on_plate_top(const Mesh& m, std::size_t i) { return m.positions[i].y == 0.0f && m.normals[i].y > 0.99f; }

TEST(LightSelfShadow, ABallShadowsThePlateBelowItAndNothingElse) {
  const Mesh mesh = ball_over_plate();
  const LightSelfShadow shadow(mesh);
  const std::vector<VolumeLight> sun{distant_light({0, 1, 0}, 1000.0, 1e-4)};
  const std::vector<float> blocked = shadow.blocked(glm::dmat4(1.0), sun, {0, 0, 0});
  ASSERT_EQ(blocked.size(), mesh.positions.size());
  int under = 0, beside = 0, ball = 0;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3 p = mesh.positions[i];
    const float r = std::hypot(p.x, p.z);
    if (on_plate_top(mesh, i) && r < kRadius - 0.05f) {
      EXPECT_EQ(blocked[i], 1.0f) << "under the ball at " << p.x << ", " << p.z;
      ++under;
    } else if (on_plate_top(mesh, i) && r > kRadius + 0.05f) {
      EXPECT_EQ(blocked[i], 0.0f) << "beside the ball at " << p.x << ", " << p.z;
      ++beside;
    } else if (p.y > 1.0f) {
      // The ball's upper half sees the sun; its lower half faces away from it.
      EXPECT_EQ(blocked[i], 0.0f) << "ball vertex " << i;
      ++ball;
    } else if (p.y < 0.0f || !on_plate_top(mesh, i)) {
      EXPECT_EQ(blocked[i], 0.0f) << "the plate's sides and bottom get no sun to block";
    }
  }
  std::printf("under the ball %d vertices, beside it %d, on it %d\n", under, beside, ball);
  EXPECT_GE(under, 9);
  EXPECT_GE(beside, 200);
}

TEST(LightSelfShadow, TwoLightsBlockInProportionToTheirIrradiance) {
  const Mesh mesh = ball_over_plate();
  const LightSelfShadow shadow(mesh);
  // A: straight up, behind the ball for the plate's middle. B: 45° towards +x, whose
  // shadow of the ball falls 1.5 m to the -x side.
  const std::vector<VolumeLight> lights{distant_light({0, 1, 0}, 1000.0, 1e-4), distant_light({1, 1, 0}, 3000.0, 2e-4)};
  const std::vector<float> blocked = shadow.blocked(glm::dmat4(1.0), lights, {0, 0, 0});
  const double a = 1000.0 * 1e-4, b = 3000.0 * 2e-4 * std::sqrt(0.5);
  int checked = 0;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3 p = mesh.positions[i];
    if (!on_plate_top(mesh, i) || std::hypot(p.x, p.z) > 0.3f) continue;
    EXPECT_NEAR(blocked[i], a / (a + b), 1e-6) << p.x << ", " << p.z;
    ++checked;
  }
  // In B's shadow only (the ball's centre seen along B from the plate: x = -1.5).
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3 p = mesh.positions[i];
    if (!on_plate_top(mesh, i) || std::hypot(p.x + kHeight, p.z) > 0.25f) continue;
    EXPECT_NEAR(blocked[i], b / (a + b), 1e-6) << p.x << ", " << p.z;
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

TEST(LightSelfShadow, MovesWithThePoseAndNotWithTheScale) {
  const Mesh mesh = ball_over_plate();
  const LightSelfShadow shadow(mesh);
  const std::vector<VolumeLight> lights{distant_light({0.3, 1, 0.2}, 1000.0, 1e-4)};
  const std::vector<float> still = shadow.blocked(glm::dmat4(1.0), lights, {0, 0, 0});
  // Moved and scaled up: the same shadow on the same vertices.
  const glm::dmat4 moved = glm::scale(glm::translate(glm::dmat4(1.0), {3, 0.5, -1}), glm::dvec3(2.0));
  const std::vector<float> bigger = shadow.blocked(moved, lights, {0, 0, 0});
  // Turned upside down (about x): the ball hangs under the plate, which now shadows every
  // part of the ball the light would reach, and the plate's top faces away from it.
  const glm::dmat4 flipped = glm::rotate(glm::dmat4(1.0), kPi, glm::dvec3(1, 0, 0));
  const std::vector<float> upside_down = shadow.blocked(flipped, lights, {0, 0, 0});
  const glm::dvec3 toward = lights[0].direction;
  int differ = 0, shadowed = 0, ball_facing = 0;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    differ += still[i] != bigger[i];
    shadowed += still[i] > 0.5f;
    const glm::dvec3 n = glm::dmat3(flipped) * glm::dvec3(mesh.normals[i]);
    if (mesh.positions[i].y > 1.0f && glm::dot(n, toward) > 0.05) {
      EXPECT_EQ(upside_down[i], 1.0f) << "ball vertex " << i << " under the plate";
      ++ball_facing;
    }
    if (on_plate_top(mesh, i)) {
      EXPECT_EQ(upside_down[i], 0.0f);
    }
  }
  std::printf("shadowed vertices: %d; moved and scaled: %d differ; upside down: %d ball vertices under the plate\n",
              shadowed, differ, ball_facing);
  EXPECT_GE(shadowed, 9);
  EXPECT_LE(differ, 2);  // rays along a triangle's edge may fall either way
  EXPECT_GE(ball_facing, 400);
}

// The share of a light as LightSelfShadow spreads it, whose rays from p meet the ball: a
// 200 × 200 grid over the light's disk and an analytic ray–sphere test. A distant light
// is a disk of radius tan(half angle) at unit distance along its direction; one on the
// proxy, a disk of its texels' area facing its normal.
double covered_share(const glm::dvec3& p, const VolumeLight& l, const glm::dvec3& capture) {
  const glm::dvec3 t(1, 0, 0), b(0, 0, 1), centre(0, kHeight, 0);
  double radius = std::tan(std::acos(1 - l.solid_angle / (2 * kPi)));
  if (l.on_proxy) radius = std::sqrt(l.solid_angle * glm::dot(capture - l.position, capture - l.position) / kPi);
  int inside = 0, hit = 0;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      const double u = (i + 0.5) / 100 - 1, v = (j + 0.5) / 100 - 1;
      if (u * u + v * v > 1) continue;
      ++inside;
      const glm::dvec3 q = (l.on_proxy ? l.position : l.direction) + radius * (u * t + v * b);
      const glm::dvec3 w = glm::normalize(l.on_proxy ? q - p : q), oc = centre - p;
      const double along = glm::dot(oc, w);
      hit += along > 0 && glm::dot(oc, oc) - along * along < double(kRadius) * kRadius;
    }
  return double(hit) / inside;
}

TEST(LightSelfShadow, AWideLightLeavesAPenumbraAsWideAsTheLight) {
  const Mesh mesh = ball_over_plate();
  // Lights 0.15 rad across their half angle from the plate's middle, straight up: the
  // ball's shadow on the plate has a core and a penumbra about 0.4 m wide. One distant,
  // one a patch of the proxy's ceiling 10 m up seen from a capture point on the plate.
  const double half_angle = 0.15, omega = 2 * kPi * (1 - std::cos(half_angle));
  VolumeLight ceiling = distant_light({0, 1, 0}, 100.0, omega);
  ceiling.on_proxy = true;
  ceiling.position = {0, 10, 0};
  ceiling.normal = {0, -1, 0};
  for (const VolumeLight& light : {distant_light({0, 1, 0}, 100.0, omega), ceiling}) {
    const std::vector<VolumeLight> wide{light};
    const glm::dvec3 capture(0, 0, 0);
    const std::vector<float> spread = LightSelfShadow(mesh).blocked(glm::dmat4(1.0), wide, capture);
    const std::vector<float> centre = LightSelfShadow(mesh, {.samples = 1}).blocked(glm::dmat4(1.0), wide, capture);
    double error_spread = 0, error_centre = 0;
    int penumbra = 0;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      if (!on_plate_top(mesh, i)) continue;
      const double expected = covered_share(glm::dvec3(mesh.positions[i]), light, capture);
      if (expected < 0.05 || expected > 0.95) {
        EXPECT_NEAR(spread[i], std::round(expected), 0.1) << "outside the penumbra, all or nearly nothing";
        continue;
      }
      ++penumbra;
      EXPECT_NEAR(spread[i], expected, 0.15) << mesh.positions[i].x << ", " << mesh.positions[i].z;
      EXPECT_TRUE(centre[i] == 0.0f || centre[i] == 1.0f);
      error_spread += std::abs(spread[i] - expected);
      error_centre += std::abs(centre[i] - expected);
    }
    std::printf("%s light: %d plate vertices in the penumbra, mean error %.3f spread over it, %.3f at its centre\n",
                light.on_proxy ? "proxy" : "distant", penumbra, error_spread / penumbra, error_centre / penumbra);
    ASSERT_GE(penumbra, 8);
    EXPECT_LT(error_spread, 0.4 * error_centre);
  }
  EXPECT_THROW(LightSelfShadow(mesh, {.samples = 0}), InputError);
  EXPECT_THROW(LightSelfShadow(mesh, {.samples = LightSelfShadowSettings::kMaxSamples + 1}), InputError);
}

TEST(LightSelfShadow, NoLightsBlockNothingAndAMeshWithoutNormalsIsRefused) {
  const Mesh mesh = ball_over_plate();
  const std::vector<float> none = LightSelfShadow(mesh).blocked(glm::dmat4(1.0), {}, {0, 0, 0});
  EXPECT_EQ(none, std::vector<float>(mesh.positions.size(), 0.0f));
  Mesh bare = mesh;
  bare.normals.clear();
  EXPECT_THROW(LightSelfShadow{bare}, InputError);
}

// The two parts of IrradianceVolume::evaluate add up to it, the probes' part does not
// depend on the lights' normal, and the lights' part is the lights' own irradiance at
// that normal (a distant map: nothing on the way).
TEST(IrradianceVolumeParts, AddUpAndTheLightsPartIsTheLightsAtTheirNormal) {
  const EnvironmentMap map = test::dim_sky_with_sun();
  const VolumeSettings settings = volume_settings_for("volume");
  const RoomRadiance radiance(map, settings.radiance);
  const IrradianceVolume volume = IrradianceVolume::build_distant(radiance, settings);
  ASSERT_FALSE(volume.lights.empty());
  const std::vector<glm::dvec3> normals = test::random_normals(40, 11), others = test::random_normals(40, 12);
  double lit = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const glm::dvec3 n = normals[i], m = others[i], p(0.0);
    const glm::dvec3 whole = volume.evaluate(p, n);
    const glm::dvec3 rest = volume.evaluate(p, n, m, 1.0, 0.0), lights = volume.evaluate(p, m, n, 0.0, 1.0);
    EXPECT_NEAR(glm::length(rest + lights - whole), 0.0, 1e-9 * glm::length(whole));
    EXPECT_NEAR(glm::length(rest - volume.evaluate(p, n, n, 1.0, 0.0)), 0.0, 1e-12);
    glm::dvec3 expected(0.0), toward;
    for (const VolumeLight& l : volume.lights) expected += light_irradiance(l, volume.capture_position, p, n, &toward);
    EXPECT_NEAR(glm::length(lights - expected), 0.0, 1e-9 * (1.0 + glm::length(expected)));
    const glm::dvec3 lights_at_m = volume.evaluate(p, n, m, 0.0, 1.0);
    EXPECT_NEAR(glm::length(volume.evaluate(p, n, m, 0.5, 0.25) - (0.5 * rest + 0.25 * lights_at_m)), 0.0,
                1e-9 * glm::length(whole + lights_at_m));
    lit += luminance(lights) > 0.0;
  }
  EXPECT_GE(lit, 10);  // the sun lights a good part of the normals
}

}  // namespace
}  // namespace lumar
