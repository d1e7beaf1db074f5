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
  EXPECT_NEAR(one[0].max.x, cap + reach, 0.006);
  EXPECT_NEAR(one[0].min.z, -(cap + reach), 0.006);
  EXPECT_EQ(one[0].min.y, floor_region().min.y);  // the region's slab, as the receivers need
  EXPECT_EQ(one[0].max.y, floor_region().max.y);
  // 20 cm above the floor it touches nothing.
  EXPECT_TRUE(contact_regions({floor_region()}, {&sphere}, {at(0, kR + 0.2, 0)}, reach).empty());
  // Two spheres 20 cm apart: their boxes overlap and become one; a third far off stays apart.
  const auto merged = contact_regions({floor_region()}, {&sphere, &sphere, &sphere},
                                      {at(0, kR, 0), at(0.2, kR, 0), at(0.9, kR, 0)}, reach);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_NEAR(merged[0].min.x, -(cap + reach), 0.006);
  EXPECT_NEAR(merged[0].max.x, 0.2 + cap + reach, 0.006);
  EXPECT_NEAR(merged[1].min.x, 0.9 - (cap + reach), 0.006);
  // Clipped to the region.
  const auto edge = contact_regions({floor_region()}, {&sphere}, {at(1.28, kR, 0)}, reach);
  ASSERT_EQ(edge.size(), 1u);
  EXPECT_EQ(edge[0].max.x, 1.3);
}

TEST(ContactReceivers, RestoreTheContactShadowOfASphereUnderAUniformSky) {
  // A ground plane under a distant sky of radiance 1; a sphere of radius R resting on it
  // blocks (R/D)³ of the sky at a floor point D from its centre (docs/ground_truth.md).
  RayScene proxy;
  proxy.add_static(test::make_ground(3.0f));
  proxy.commit();
  EnvironmentMap sky;
  sky.width = 128, sky.height = 64;
  sky.rgb.assign(std::size_t(sky.width) * sky.height * 3, 1.0f);
  const Emitters emitters = build_emitters(sky, proxy, true, {0, 0, 0}, {0, 1, 0});
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

}  // namespace
}  // namespace lumar
