// bake_self_occlusion against analytic cases: a convex sphere sees its whole hemisphere;
// the centre of a well's floor sees the sky through its mouth only.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/lighting/light_self_shadow.h"
#include "lumar/lighting/self_occlusion.h"
#include "test_geometry.h"

namespace lumar {
namespace {

// A round well: a floor disc (its centre is vertex 0, normal +y) and a wall of radius R
// from y = 0 to y = depth, without a lid.
Mesh make_well(float R, float depth, int sides = 64) {
  Mesh m;
  m.positions.push_back({0, 0, 0});
  m.normals.push_back({0, 1, 0});
  for (int i = 0; i < sides; ++i) {
    const float a = 2.0f * float(kPi) * float(i) / float(sides);
    m.positions.push_back({R * std::cos(a), 0, R * std::sin(a)});
    m.normals.push_back({0, 1, 0});
  }
  for (int i = 0; i < sides; ++i)
    m.indices.insert(m.indices.end(), {0u, 1u + std::uint32_t(i), 1u + std::uint32_t((i + 1) % sides)});
  const std::uint32_t base = std::uint32_t(m.positions.size());
  for (int i = 0; i < sides; ++i) {
    const float a = 2.0f * float(kPi) * float(i) / float(sides);
    const glm::vec3 inward(-std::cos(a), 0, -std::sin(a));
    m.positions.push_back({R * std::cos(a), 0, R * std::sin(a)});
    m.positions.push_back({R * std::cos(a), depth, R * std::sin(a)});
    m.normals.push_back(inward);
    m.normals.push_back(inward);
  }
  for (int i = 0; i < sides; ++i) {
    const std::uint32_t a = base + 2 * std::uint32_t(i), b = base + 2 * std::uint32_t((i + 1) % sides);
    m.indices.insert(m.indices.end(), {a, a + 1, b, b, a + 1, b + 1});
  }
  return m;
}

TEST(SelfOcclusion, AConvexSphereIsOpenEverywhere) {
  const Mesh sphere = test::make_sphere({0, 0, 0}, 1.0f, 48, 24);
  const auto occlusion = bake_self_occlusion(sphere);
  ASSERT_EQ(occlusion.size(), sphere.positions.size());
  float least = 1.0f, worst_turn = 1.0f;
  for (std::size_t i = 0; i < occlusion.size(); ++i) {
    least = std::min(least, occlusion[i].open);
    worst_turn = std::min(worst_turn, glm::dot(occlusion[i].bent_normal, glm::normalize(sphere.normals[i])));
  }
  EXPECT_EQ(least, 1.0f);
  EXPECT_GT(worst_turn, 0.9f);  // 64 cosine-weighted rays: their mean lies near the normal
}

TEST(SelfOcclusion, TheFloorOfAWellSeesTheSkyThroughItsMouth) {
  // From the floor's centre the mouth is a cone of half-angle a, tan a = R / depth; a
  // cosine-weighted hemisphere puts sin² a of its weight inside it.
  for (const float depth : {1.0f, 2.0f, 0.5f}) {
    const Mesh well = make_well(1.0f, depth);
    const auto occlusion = bake_self_occlusion(well, {.strata = 16});
    const double a = std::atan(1.0 / depth), expected = std::sin(a) * std::sin(a);
    SCOPED_TRACE(depth);
    EXPECT_NEAR(occlusion[0].open, expected, 0.02);
    EXPECT_GT(occlusion[0].bent_normal.y, 0.999f);  // straight up, by symmetry
  }
}

TEST(SelfOcclusion, IsTheSameOnEveryRunAndRefusesMissingNormals) {
  const Mesh well = make_well(1.0f, 1.0f, 16);
  // The compositor bakes against LightSelfShadow's ray scene of the mesh: the same values.
  const LightSelfShadow shadow(well);
  const auto a = bake_self_occlusion(well), b = bake_self_occlusion(well, shadow.scene());
  int partly_open = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].open, b[i].open);
    EXPECT_EQ(a[i].bent_normal, b[i].bent_normal);
    partly_open += a[i].open > 0.05f && a[i].open < 0.95f;
  }
  EXPECT_GT(partly_open, 0);  // the well's inside: values that a wrong scene would change
  Mesh bare = well;
  bare.normals.clear();
  EXPECT_THROW(bake_self_occlusion(bare), InputError);
  EXPECT_THROW(bake_self_occlusion(well, {.strata = 0}), InputError);
}

}  // namespace
}  // namespace lumar
