// The ground truth of a composite (lumar/lighting/composite_reference.h) on analytic
// cases: a uniform sky over a plane gives E = π; a sphere resting on the plane blocks
// (R/d)³ of it at distance d from its centre and reflects ρ times as much; far away the
// ratio is 1. And its cone sampling against plain hemisphere sampling in a real room.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "irradiance_test_util.h"
#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_reference.h"

namespace lumar::test {
namespace {

EnvironmentMap uniform_sky(float value) {
  EnvironmentMap m;
  m.width = 128, m.height = 64;
  m.rgb.assign(std::size_t(m.width) * m.height * 3, value);
  return m;
}

LoadedObject sphere_object(double radius, const glm::dvec3& centre, float albedo) {
  LoadedObject o;
  o.name = "sphere";
  o.model = make_sphere(glm::vec3(0.0f), float(radius), 96, 48);
  o.T_world_model = glm::translate(glm::dmat4(1.0), centre);
  o.albedo = glm::vec3(albedo);
  return o;
}

// A unit sphere resting on the plane y = 0 at the origin, under a uniform sky of
// radiance 1 (distant: there is no proxy, the plane is where the queries are).
struct SphereOnPlane {
  EnvironmentMap map = uniform_sky(1.0f);
  RoomRadiance room{map, RadianceSettings{}};
  std::vector<LoadedObject> objects{sphere_object(1.0, {0, 1, 0}, 0.5f)};
};

TEST(CompositeReference, UniformSkyOverAnOpenPlaneGivesPi) {
  SphereOnPlane s;
  CompositeReferenceSettings settings;
  settings.bounce = false;
  const CompositeReference ref(s.room, s.objects, settings);
  // Far from the sphere nothing is blocked: E = π, and the ratio is exactly 1.
  const glm::dvec3 E = ref.irradiance_with_objects({100, 0, 0}, {0, 1, 0}, 32);
  EXPECT_NEAR(luminance(E), kPi, 1e-9);
  EXPECT_EQ(ref.room_ratio({100, 0, 0}, {0, 1, 0}), glm::dvec3(1.0));
  // The top of the sphere sees the whole sky above it: E = π too.
  EXPECT_NEAR(luminance(ref.irradiance_with_objects({0, 2, 0}, {0, 1, 0}, 32)), kPi, 0.01 * kPi);
}

TEST(CompositeReference, SphereOnAPlaneBlocksTheCubeOfRadiusOverDistance) {
  SphereOnPlane s;
  CompositeReferenceSettings settings;
  settings.bounce = false;
  settings.cone_strata = 16;
  const CompositeReference ref(s.room, s.objects, settings);
  // A sphere tangent to the plane is a cap wholly above the horizon: its projected solid
  // angle is π sin²α cos θ with sin α = cos θ = R/d, so E_with/E_without = 1 − (R/d)³.
  double worst = 0;
  for (double x : {0.05, 0.3, 0.7, 1.0, 1.5, 2.5, 4.0, 8.0}) {
    const double d = std::hypot(x, 1.0);
    const double expected = 1.0 - std::pow(1.0 / d, 3);
    const double ratio = luminance(ref.room_ratio({x, 0, 0}, {0, 1, 0}));
    // Both branches are covered: inside the bounding sphere (radius √3, hemisphere
    // sampling) up to x = √2, in the cone beyond.
    worst = std::max(worst, std::abs(ratio - expected));
    std::printf("x %.2f: ratio %.4f, analytic %.4f\n", x, ratio, expected);
    EXPECT_NEAR(ratio, expected, 0.02) << "x = " << x;
  }
  std::printf("worst |ratio - (1 - (R/d)^3)| = %.4f\n", worst);
  // At the contact point the sphere covers the whole sky.
  EXPECT_LT(luminance(ref.room_ratio({0, 0, 0}, {0, 1, 0})), 0.02);
}

TEST(CompositeReference, SphereReflectsItsAlbedoOfWhatItBlocks) {
  // Under a uniform sky a convex sphere's E is π everywhere, so it sends radiance ρ:
  // the plane gets back ρ of what the sphere blocks, E_with/E_without = 1 − (1 − ρ)(R/d)³.
  SphereOnPlane s;
  CompositeReferenceSettings settings;
  settings.cone_strata = 16;
  const CompositeReference ref(s.room, s.objects, settings);
  for (double x : {0.3, 1.0, 2.5}) {
    const double d = std::hypot(x, 1.0);
    const double expected = 1.0 - 0.5 * std::pow(1.0 / d, 3);
    EXPECT_NEAR(luminance(ref.room_ratio({x, 0, 0}, {0, 1, 0})), expected, 0.02) << "x = " << x;
  }
  // The sphere's own points see the sky, and the plane does not exist for them: π.
  const auto hit = ref.hit_object({0, 1, 5}, {0, 0, -1});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z, 1.0, 1e-3);
  EXPECT_NEAR(glm::length(hit->normal - glm::dvec3(0, 0, 1)), 0.0, 1e-3);
  EXPECT_NEAR(luminance(ref.object_radiance(*hit)), 0.5, 0.01);
  EXPECT_NEAR(luminance(ref.object_radiance(*hit, false)), 0.5, 0.01);
}

TEST(CompositeReference, AnotherObjectSendsItsOneBounceRadianceOntoAnObject) {
  // Two unit spheres of albedo ½ under a uniform sky, centres 3 apart along z. From the
  // point of A facing B, B covers sin²α = (R/d)² = ¼ of the cosine-weighted hemisphere
  // (d = 2): black, it leaves E = ¾π. Reflecting, it sends back ρ E_B / π per ray, where
  // E_B on its side facing A lies between ¾π (its pole, which A hides as much) and π:
  // E between (¾ + ¼ · ½ · ¾)π and (¾ + ¼ · ½)π. The object's radiance is ½ E / π.
  const EnvironmentMap map = uniform_sky(1.0f);
  const RoomRadiance room{map, RadianceSettings{}};
  const std::vector<LoadedObject> spheres{sphere_object(1.0, {0, 0, 0}, 0.5f), sphere_object(1.0, {0, 0, 3}, 0.5f)};
  CompositeReferenceSettings settings;
  settings.object_strata = 48;
  for (bool bounce : {false, true}) {
    settings.bounce = bounce;
    const CompositeReference ref(room, spheres, settings);
    const auto hit = ref.hit_object({0, 0, 1.5}, {0, 0, -1});
    ASSERT_TRUE(hit.has_value());
    ASSERT_EQ(hit->object, 0);
    const double E = luminance(ref.object_radiance(*hit)) * kPi / 0.5;
    std::printf("bounce %s: E / pi = %.4f\n", bounce ? "on" : "off", E / kPi);
    if (bounce) {
      EXPECT_GT(E / kPi, 0.75 + 0.25 * 0.5 * 0.75 - 0.01);
      EXPECT_LT(E / kPi, 0.75 + 0.25 * 0.5 + 0.01);
    } else {
      EXPECT_NEAR(E / kPi, 0.75, 0.01);
    }
    // Its far side sees neither sphere: π either way (A does not light itself).
    const auto back = ref.hit_object({0, 0, -5}, {0, 0, 1});
    ASSERT_TRUE(back.has_value());
    EXPECT_NEAR(luminance(ref.object_radiance(*back)) * kPi / 0.5, kPi, 0.01 * kPi);
  }
}

TEST(CompositeReference, RatioTendsToOneAndIsOneBeyondReach) {
  SphereOnPlane s;
  CompositeReferenceSettings settings;
  settings.bounce = false;
  const CompositeReference ref(s.room, s.objects, settings);
  const double reach = settings.reach * std::sqrt(3.0);  // the bounding sphere's radius is √3
  const double x = std::sqrt(reach * reach - 1.0) - 0.01;
  const double blocked = 1.0 - luminance(ref.room_ratio({x, 0, 0}, {0, 1, 0}));
  EXPECT_NEAR(blocked, std::pow(1.0 / std::hypot(x, 1.0), 3), 0.2 * std::pow(1.0 / reach, 3));  // about 2e-4
  EXPECT_EQ(ref.room_ratio({reach + 0.01, 0, 0}, {0, 1, 0}), glm::dvec3(1.0));
  // Facing away from the sphere (a wall turned from it): nothing blocked.
  EXPECT_EQ(ref.room_ratio({3, 0.5, 0}, {1, 0, 0}), glm::dvec3(1.0));
}

TEST(CompositeReference, ConeSamplingAgreesWithHemisphereSamplingInARoom) {
  // In the divided room (a proxy, a window and a small bright lamp), a box on the table:
  // the ratio from cone sampling and exact bright texels equals that of two plain
  // hemisphere integrals with and without the box, 64² rays each, sharing their rays.
  const DividedRoom d = make_divided_room();
  RoomRadiance room(d.map, d.proxy, reference_radiance_settings());
  LoadedObject box;
  box.name = "box";
  box.model = make_box({-0.15f, 0.0f, -0.15f}, {0.15f, 0.3f, 0.15f});
  box.T_world_model = glm::translate(glm::dmat4(1.0), glm::dvec3(-1.8, 0.8, 0.8));
  std::vector<LoadedObject> objects{box};
  CompositeReferenceSettings settings;
  settings.bounce = false;
  settings.cone_strata = 24;
  settings.room_strata = 48;
  const CompositeReference ref(room, objects, settings);
  double worst = 0;
  // Three points on the table top around the box, one on the floor that sees it over the
  // table's edge.
  for (const glm::dvec3& p : {glm::dvec3(-1.6, 0.8, 0.8), glm::dvec3(-1.8, 0.8, 1.0), glm::dvec3(-2.05, 0.8, 0.55),
                              glm::dvec3(-1.0, 0.0, -1.0)}) {
    const glm::dvec3 n(0, 1, 0);
    const double brute =
        luminance(ref.irradiance_with_objects(p, n, 64)) / luminance(reference_irradiance(room, p, n, 64));
    const double cone = luminance(ref.room_ratio(p, n));
    worst = std::max(worst, std::abs(cone - brute));
    std::printf("(%.1f, %.1f, %.1f): cone %.4f, hemisphere %.4f\n", p.x, p.y, p.z, cone, brute);
    EXPECT_NEAR(cone, brute, 0.03) << "at " << p.x << " " << p.y << " " << p.z;
    if (p.y > 0) {
      EXPECT_LT(cone, 0.999);  // beside the box: shadowed
    }
  }
  std::printf("worst |cone - hemisphere| = %.4f\n", worst);
}

}  // namespace
}  // namespace lumar::test
