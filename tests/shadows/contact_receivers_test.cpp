// The contact receivers against analytic cases: where a sphere touches the floor, and its
// contact shadow under a uniform sky, 1 - (R/D)^3, which the scene's coarse receivers
// blur and the patch's correction restores.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "lumar/lighting/shadows/contact_receivers.h"
#include "lumar/lighting/shadows/shadow_emitters.h"
#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/lighting/shadows/shadow_receivers.h"
#include "shadow_test_util.h"

namespace lumar {
namespace {

constexpr double kR = 0.1;  // the sphere's radius, metres

glm::dmat4 at(double x, double y, double z) { return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z)); }

SceneBox floor_region() { return SceneBox{{-1.3, -0.01, -1.3}, {1.3, 0.01, 1.3}}; }

TEST(ContactReceivers, RegionsLieUnderWhatTouchesTheFloorAndDoNotOverlap) {
  const Mesh sphere = test::make_sphere({0, 0, 0}, float(kR), 64, 32);
  const double reach = 0.05;
  // Resting on the floor: its vertices below 5 cm form a cap of radius sqrt(R² - (R - 5 cm)²).
  const auto one = contact_regions({floor_region()}, {&sphere}, {at(0, kR, 0)}, reach);
  ASSERT_EQ(one.size(), 1u);
  const double cap = std::sqrt(kR * kR - (kR - reach) * (kR - reach));
  EXPECT_NEAR(one[0].box.max.x, cap + reach, 0.006);
  EXPECT_NEAR(one[0].box.min.z, -(cap + reach), 0.006);
  EXPECT_EQ(one[0].box.min.y, floor_region().min.y);  // the region's slab, as the receivers need
  EXPECT_EQ(one[0].box.max.y, floor_region().max.y);
  EXPECT_EQ(one[0].object, 0);
  // 20 cm above the floor it touches nothing.
  EXPECT_TRUE(contact_regions({floor_region()}, {&sphere}, {at(0, kR + 0.2, 0)}, reach).empty());
  // Two spheres 20 cm apart: their boxes overlap and become one; a third far off stays apart.
  const auto merged = contact_regions({floor_region()}, {&sphere, &sphere, &sphere},
                                      {at(0, kR, 0), at(0.2, kR, 0), at(0.9, kR, 0)}, reach);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_NEAR(merged[0].box.min.x, -(cap + reach), 0.006);
  EXPECT_NEAR(merged[0].box.max.x, 0.2 + cap + reach, 0.006);
  EXPECT_EQ(merged[0].object, -1);  // two objects' contact: neither can carry it alone
  EXPECT_NEAR(merged[1].box.min.x, 0.9 - (cap + reach), 0.006);
  EXPECT_EQ(merged[1].object, 2);
  // Clipped to the region.
  const auto edge = contact_regions({floor_region()}, {&sphere}, {at(1.28, kR, 0)}, reach);
  ASSERT_EQ(edge.size(), 1u);
  EXPECT_EQ(edge[0].box.max.x, 1.3);
}

// A ground plane under a distant sky of radiance 1, and its emitters.
struct SkyOverGround {
  RayScene proxy;
  Emitters emitters;
  SkyOverGround() {
    proxy.add_static(test::make_ground(3.0f));
    proxy.commit();
    EnvironmentMap sky;
    sky.width = 128, sky.height = 64;
    sky.rgb.assign(std::size_t(sky.width) * sky.height * 3, 1.0f);
    emitters = build_emitters(sky, proxy, true, {0, 0, 0}, {0, 1, 0});
  }
};

TEST(ContactReceivers, RestoreTheContactShadowOfASphereUnderAUniformSky) {
  // A ground plane under a distant sky of radiance 1; a sphere of radius R resting on it
  // blocks (R/D)³ of the sky at a floor point D from its centre (docs/ground_truth.md).
  const SkyOverGround world;
  const RayScene& proxy = world.proxy;
  const Emitters& emitters = world.emitters;
  const Mesh coarse = build_receivers(proxy, {floor_region()}, 3200);  // the scene's default count
  const Mesh sphere = test::make_sphere({0, 0, 0}, float(kR), 64, 32);
  const glm::dmat4 pose = at(0.013, kR, -0.021);  // off the coarse grid's nodes

  const auto shadow = [&](const Mesh& receivers) {
    LineShadows lines(build_shadow_lines(receivers.positions, receivers.normals, emitters, proxy));
    lines.add_object(sphere, pose);
    lines.update();
    return lines.attenuation();
  };
  const ContactPatch patch =
      build_contact_patch(proxy, coarse, contact_regions({floor_region()}, {&sphere}, {pose}, 0.05));
  ASSERT_FALSE(patch.empty());
  EXPECT_GT(patch.receivers.positions.size(), 500u);  // 1 cm apart over about 27 cm square
  const std::vector<glm::vec3> coarse_shadow = shadow(coarse), patch_shadow = shadow(patch.receivers);
  const std::vector<glm::vec3> correction = patch.correction(patch_shadow, coarse_shadow);

  // At the patch's vertices: the coarse shadow as drawn (interpolated), and with the correction.
  double coarse_err = 0, corrected_err = 0, far_change = 0;
  int near = 0, far = 0;
  for (std::size_t i = 0; i < patch.receivers.positions.size(); ++i) {
    const glm::vec3& p = patch.receivers.positions[i];
    ASSERT_NE(patch.coarse_weights[i], glm::vec3(0.0f)) << "every patch vertex lies in a coarse triangle";
    float drawn = 0;
    for (int k = 0; k < 3; ++k) drawn += patch.coarse_weights[i][k] * coarse_shadow[patch.coarse_corners[i][k]].g;
    const double x = std::hypot(p.x - pose[3][0], p.z - pose[3][2]);
    const double analytic = 1.0 - std::pow(kR / std::hypot(x, kR), 3.0);
    const double corrected = drawn * correction[i].g;
    EXPECT_NEAR(corrected, patch_shadow[i].g, 1e-4 + 1e-4 * corrected);  // drawn over the coarse: the patch's own
    if (x < kR) {
      coarse_err += std::abs(drawn - analytic), corrected_err += std::abs(corrected - analytic), ++near;
    } else if (x > 1.25 * kR) {
      far_change += std::abs(correction[i].g - 1.0f), ++far;
    }
  }
  ASSERT_GT(near, 100);
  ASSERT_GT(far, 50);
  coarse_err /= near, corrected_err /= near, far_change /= far;
  std::printf("within R of the contact: coarse %.4f, corrected %.4f; beyond 1.25 R the correction moves %.4f\n",
              coarse_err, corrected_err, far_change);
  EXPECT_LT(corrected_err, 0.03);
  EXPECT_LT(corrected_err, 0.5 * coarse_err);
  EXPECT_LT(far_change, 0.02);  // where the coarse mesh resolves the shadow, the patch leaves it
}

// The coarse attenuation interpolated at a floor point (y = 0): the triangle holding it
// in x, z; 1 where none does, as the renderer draws nothing there.
glm::vec3 coarse_at(const Mesh& coarse, const std::vector<glm::vec3>& attenuation, const glm::vec3& p) {
  for (std::size_t t = 0; 3 * t + 2 < coarse.indices.size(); ++t) {
    const std::uint32_t* c = &coarse.indices[3 * t];
    const glm::vec2 a(coarse.positions[c[0]].x, coarse.positions[c[0]].z);
    const glm::vec2 b(coarse.positions[c[1]].x, coarse.positions[c[1]].z);
    const glm::vec2 d(coarse.positions[c[2]].x, coarse.positions[c[2]].z);
    const glm::vec2 q(p.x, p.z);
    const float det = (b.x - a.x) * (d.y - a.y) - (d.x - a.x) * (b.y - a.y);
    if (std::abs(det) < 1e-12f) continue;
    const float w1 = ((q.x - a.x) * (d.y - a.y) - (d.x - a.x) * (q.y - a.y)) / det;
    const float w2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / det;
    if (w1 < -1e-5f || w2 < -1e-5f || w1 + w2 > 1 + 1e-5f) continue;
    return (1 - w1 - w2) * attenuation[c[0]] + w1 * attenuation[c[1]] + w2 * attenuation[c[2]];
  }
  return glm::vec3(1.0f);
}

// A sphere's patch built where it rested, carried with it as it rolls 23 cm along the
// floor and turns about the vertical, drawn over the coarse shadow there: within R of the
// new contact point it restores the analytic contact shadow as a patch built there would;
// lifted 5 cm, the sphere leaves its patch behind; a second sphere that did not move
// keeps its part where it was.
TEST(ContactReceivers, ThePatchTravelsWithAnObjectAlongTheFloor) {
  const SkyOverGround world;
  const RayScene& proxy = world.proxy;
  const Emitters& emitters = world.emitters;
  const Mesh coarse = build_receivers(proxy, {floor_region()}, 3200);
  const Mesh sphere = test::make_sphere({0, 0, 0}, float(kR), 64, 32);
  const glm::dmat4 built_at = at(0.013, kR, -0.021), still = at(-0.8, kR, 0.5);
  const glm::dmat4 now = at(0.241, kR, 0.037) * glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(0, 1, 0));
  const auto shadow = [&](const Mesh& receivers, const glm::dmat4& pose) {
    LineShadows lines(build_shadow_lines(receivers.positions, receivers.normals, emitters, proxy));
    lines.add_object(sphere, pose);
    lines.add_object(sphere, still);
    lines.update();
    return lines.attenuation();
  };
  const ContactPatch patch = build_contact_patch(
      proxy, coarse, contact_regions({floor_region()}, {&sphere, &sphere}, {built_at, still}, 0.05));
  ASSERT_FALSE(patch.empty());
  const std::vector<glm::vec3> coarse_now = shadow(coarse, now);
  const glm::dmat4 moved[2] = {now * glm::inverse(built_at), glm::dmat4(1.0)};
  const ContactPatch carried_patch = patch.carried(moved, coarse);
  const Mesh& carried = carried_patch.receivers;
  ASSERT_EQ(carried.positions.size(), patch.receivers.positions.size());
  const std::vector<glm::vec3> patch_shadow = shadow(patch.receivers, built_at);
  const std::vector<glm::vec3> now_correction = carried_patch.correction(patch_shadow, coarse_now);
  const std::vector<glm::vec3> correction =
      carried_correction(now_correction, patch.correction(patch_shadow, shadow(coarse, built_at)));
  EXPECT_EQ(carried.triangle_count(), patch.receivers.triangle_count());  // both slid along the floor: all kept
  double coarse_err = 0, carried_err = 0, own_err = 0;
  int near = 0, still_near = 0;
  for (std::size_t i = 0; i < carried.positions.size(); ++i) {
    const glm::vec3& p = carried.positions[i];
    EXPECT_NEAR(p.y, patch.receivers.positions[i].y, 1e-5);
    if (patch.owner[i] == 1) {
      EXPECT_EQ(p, patch.receivers.positions[i]);
      ++still_near;
      continue;
    }
    ASSERT_EQ(patch.owner[i], 0);
    const double x = std::hypot(p.x - now[3][0], p.z - now[3][2]);
    if (x >= kR) continue;
    const double analytic = 1.0 - std::pow(kR / std::hypot(x, kR), 3.0);
    const float drawn = coarse_at(coarse, coarse_now, p).g;
    coarse_err += std::abs(drawn - analytic), carried_err += std::abs(drawn * correction[i].g - analytic), ++near;
    own_err += std::abs(drawn * now_correction[i].g - analytic);
  }
  ASSERT_GT(near, 100);
  ASSERT_GT(still_near, 100);
  coarse_err /= near, carried_err /= near, own_err /= near;
  std::printf(
      "within R of the new contact: coarse %.4f, the carried patch over it %.4f (its own attenuation alone "
      "%.4f)\n",
      coarse_err, carried_err, own_err);
  // Under a uniform sky the shadow moves with the sphere whole: its own attenuation,
  // carried, is what a patch built there would say; the blend keeps some of the coarse
  // mesh's error where the correction was mild, which in a room follows the light better.
  EXPECT_LT(own_err, 0.35 * coarse_err);
  EXPECT_LT(carried_err, 0.6 * coarse_err);

  // Lifted: its part goes, the still sphere's stays.
  const glm::dmat4 lifted[2] = {at(0, 0.05, 0), glm::dmat4(1.0)};
  const Mesh left = patch.carried(lifted, coarse).receivers;
  ASSERT_GT(left.triangle_count(), 0u);
  for (const std::uint32_t v : left.indices) EXPECT_EQ(patch.owner[v], 1);
  // Tilted by 5 degrees about its own contact point: it no longer stands on its patch.
  const glm::dmat4 tilted =
      built_at * glm::rotate(glm::dmat4(1.0), 0.087, glm::dvec3(1, 0, 0)) * glm::inverse(built_at);
  const glm::dmat4 tilt[2] = {tilted, glm::dmat4(1.0)};
  EXPECT_EQ(patch.carried(tilt, coarse).receivers.triangle_count(), left.triangle_count());
}

}  // namespace
}  // namespace lumar
