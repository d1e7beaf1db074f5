// ObjectBounce (the light virtual objects reflect onto real receivers) against analytic
// cases and against the composite's ground truth (composite_reference.h, brute force).
#include "lumar/lighting/shadows/object_bounce.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <tuple>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/loaded_scene.h"
#include "shadow_test_util.h"
#include "test_paths.h"

namespace lumar {
namespace {

glm::dmat4 translation(double x, double y, double z) { return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z)); }

// A uniform sky of radiance 1 in every direction.
EnvironmentMap uniform_sky() {
  EnvironmentMap m;
  m.width = 128, m.height = 64;
  m.rgb.assign(std::size_t(m.width) * m.height * 3, 1.0f);
  return m;
}

// A sphere of radius R resting on the floor at the origin blocks (R/D)³ of a uniform sky
// at a floor point whose distance to its centre is D (a cap wholly above the horizon:
// projected solid angle π sin²α cos θ with sin α = cos θ = R/D).
double sphere_form_factor(double radius, double x) { return std::pow(radius / std::hypot(x, radius), 3); }

const std::vector<double> kDistances = {0.3, 0.6, 1.0, 1.5, 2.5, 4.0};

TEST(SurfaceClusters, PartitionTheTrianglesIntoPatchesOfEqualAreaAndThoseAgain) {
  const Mesh sphere = test::make_sphere({0, 0, 0}, 1.0f, 96, 48);
  const SurfaceClusters surface = surface_clusters(sphere, 256, 8);
  const std::vector<std::uint32_t>& order = surface.order;
  ASSERT_EQ(order.size(), sphere.triangle_count());
  std::vector<int> seen(sphere.triangle_count(), 0);
  for (std::uint32_t t : order) ++seen[t];
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; }));  // a permutation
  double mesh_area = 0;
  for (std::size_t t = 0; t < sphere.triangle_count(); ++t) {
    const glm::vec3 a = sphere.positions[sphere.indices[3 * t]], b = sphere.positions[sphere.indices[3 * t + 1]],
                    c = sphere.positions[sphere.indices[3 * t + 2]];
    mesh_area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  // Both levels: consecutive runs covering every triangle, areas summing to the mesh's,
  // none more than twice its share, compact patches whose normal points outwards.
  const auto check_level = [&](const std::vector<SurfaceCluster>& level, std::size_t expected, float max_radius) {
    ASSERT_GE(level.size(), expected * 98 / 100);
    ASSERT_LE(level.size(), expected);
    double total = 0;
    std::uint32_t next = 0;
    for (const SurfaceCluster& c : level) {
      EXPECT_EQ(c.first, next);
      next = c.first + c.count;
      total += c.area;
      EXPECT_NEAR(glm::length(c.normal), 1.0f, 1e-4f);
      EXPECT_GT(glm::dot(c.normal, glm::normalize(c.centre)), 0.9f);
      EXPECT_LT(c.radius, max_radius);
      EXPECT_LT(c.area, 2.0 * mesh_area / double(expected));
      for (std::uint32_t i = c.first; i < c.first + c.count; ++i)
        for (int k = 0; k < 3; ++k)
          EXPECT_LE(glm::length(sphere.positions[sphere.indices[3 * order[i] + std::uint32_t(k)]] - c.centre),
                    c.radius * 1.0001f);
    }
    EXPECT_EQ(next, sphere.triangle_count());
    EXPECT_NEAR(total, mesh_area, 1e-3 * mesh_area);
  };
  check_level(surface.clusters, 256, 0.4f);
  check_level(surface.children, 256 * 8, 0.15f);
  // Each cluster's children lie inside it and cover it.
  for (const SurfaceCluster& c : surface.clusters) {
    EXPECT_GE(c.child_count, 4u);
    EXPECT_LE(c.child_count, 16u);
    const SurfaceCluster &first = surface.children[c.first_child],
                         &last = surface.children[c.first_child + c.child_count - 1];
    EXPECT_EQ(first.first, c.first);
    EXPECT_EQ(last.first + last.count, c.first + c.count);
  }
  // The same every time; nothing for a mesh without triangles.
  const SurfaceClusters again = surface_clusters(sphere, 256, 8);
  EXPECT_EQ(again.order, order);
  EXPECT_EQ(again.clusters.size(), surface.clusters.size());
  EXPECT_TRUE(surface_clusters(Mesh{}, 10).clusters.empty());
}

TEST(ObjectBounce, SphereOnAPlaneSendsItsAlbedoTimesWhatItBlocks) {
  // Under a uniform sky of radiance 1 a convex sphere is lit by E = π everywhere, so its
  // radiance is ρ and a floor point gets ρ π F: E_bounce / E_without = ρ (R/D)³.
  const double R = 1.0, albedo = 0.5;
  std::vector<glm::vec3> positions, normals;
  for (double x : kDistances) positions.push_back({float(x), 0.0f, 0.0f}), normals.push_back({0, 1, 0});
  positions.push_back({20, 0, 0}), normals.push_back({0, 1, 0});
  const std::vector<glm::vec3> without(positions.size(), glm::vec3(float(kPi)));
  const auto uniform = [](const glm::vec3&, const glm::vec3&) { return glm::vec3(float(kPi)); };

  // Receivers near a cluster (within 3 of its radii) sum its triangles exactly; farther
  // ones see it as a point. Few large clusters or many small ones: within 3 %.
  for (int samples : {16, 256}) {
    BounceSettings settings;
    settings.clusters = samples;
    ObjectBounce bounce(positions, normals, without, settings);
    bounce.add_object(test::make_sphere({0, 0, 0}, float(R), 96, 48), glm::vec3(float(albedo)), translation(0, R, 0));
    ASSERT_TRUE(bounce.update(uniform));
    EXPECT_FALSE(bounce.update(uniform));  // nothing moved
    double worst = 0;
    for (std::size_t i = 0; i < kDistances.size(); ++i) {
      const double expected = albedo * sphere_form_factor(R, kDistances[i]);
      const glm::vec3 r = bounce.ratio()[i];
      std::printf("%d clusters, x %.1f: bounce %.4f, analytic %.4f\n", samples, kDistances[i], r.g, expected);
      EXPECT_EQ(r.r, r.g);
      worst = std::max(worst, std::abs(r.g - expected) / expected);
    }
    // Beyond the reach (8 radii): nothing at all.
    EXPECT_EQ(bounce.ratio().back(), glm::vec3(0.0f));
    std::printf("%d clusters: worst relative error %.3f\n", samples, worst);
    EXPECT_LT(worst, 0.03);
    EXPECT_GT(bounce.stats().near_pairs, 0u);
  }
}

// A receiver the room hardly lights (a point under a table block, reached only through
// the lines' ties) takes its ratio against a tenth of the receivers' median E_without, not
// its own: the same bounce, bounded, and the same whether its E_without came out 0 or
// a leak's few lines.
TEST(ObjectBounce, DarkReceiversTakeTheRatioAgainstATenthOfTheMedian) {
  const double R = 1.0, albedo = 0.5, d = 1.0;
  std::vector<glm::vec3> positions, normals, without;
  for (double x : kDistances)
    positions.push_back({float(x), 0.0f, 0.0f}), normals.push_back({0, 1, 0}), without.push_back(glm::vec3(float(kPi)));
  // Three receivers at the same point: lit, dark (a leak), and black.
  for (float e : {float(kPi), 1e-3f * float(kPi), 0.0f})
    positions.push_back({0.0f, 0.0f, float(d)}), normals.push_back({0, 1, 0}), without.push_back(glm::vec3(e));
  const auto uniform = [](const glm::vec3&, const glm::vec3&) { return glm::vec3(float(kPi)); };
  ObjectBounce bounce(positions, normals, without);
  bounce.add_object(test::make_sphere({0, 0, 0}, float(R), 96, 48), glm::vec3(float(albedo)), translation(0, R, 0));
  ASSERT_TRUE(bounce.update(uniform));
  const std::size_t lit = kDistances.size(), leak = lit + 1, black = lit + 2;
  const glm::vec3 r_lit = bounce.ratio()[lit];
  EXPECT_NEAR(r_lit.g, albedo * sphere_form_factor(R, d), 0.03 * albedo * sphere_form_factor(R, d));
  // The median E_without is π, so the floor is π/10: ten times the lit ratio, not 1000.
  const float scale = 1.0f / ObjectBounce::kDarkReceiverShare;
  EXPECT_NEAR(bounce.ratio()[leak].g, scale * r_lit.g, 1e-4f * scale * r_lit.g);
  EXPECT_EQ(bounce.ratio()[black], bounce.ratio()[leak]);
  // Relit brighter, the floor follows the median.
  for (glm::vec3& e : without) e *= 2.0f;
  bounce.relight(without);
  ASSERT_TRUE(bounce.update(uniform));
  EXPECT_NEAR(bounce.ratio()[black].g, scale * r_lit.g / 2.0f, 1e-4f * scale * r_lit.g);
}

TEST(ObjectBounce, SpheresUnderAUniformSkyLightEachOther) {
  // Each sphere is lit by E = π, so its radiance is its albedo ρ, and a point that sees
  // the whole of a sphere of radius R at distance D, at an angle θ from its normal, gets
  // E = ρ π (R/D)² cos θ: the other sphere's vertices facing it must get that, those
  // turned away nothing.
  const std::vector<glm::vec3> positions{{50, 0, 0}}, normals{{0, 1, 0}}, without{glm::vec3(float(kPi))};
  const auto uniform = [](const glm::vec3&, const glm::vec3&) { return glm::vec3(float(kPi)); };
  const glm::vec3 rho_a(0.8f, 0.4f, 0.2f), rho_b(0.5f);
  const double Ra = 1.0, Rb = 0.3;
  const glm::dvec3 ca(0.0), cb(2.5, 0.0, 0.0);
  const Mesh sphere_a = test::make_sphere({0, 0, 0}, float(Ra), 96, 48),
             sphere_b = test::make_sphere({0, 0, 0}, float(Rb), 48, 24);
  ObjectBounce bounce(positions, normals, without);
  const int a = bounce.add_object(sphere_a, rho_a, translation(ca.x, ca.y, ca.z));
  ASSERT_TRUE(bounce.update(uniform));
  for (const glm::vec3& e : bounce.object_bounce(a))
    ASSERT_EQ(e, glm::vec3(0.0f)) << "one object lights nothing of its own";
  const int b = bounce.add_object(sphere_b, rho_b, translation(cb.x, cb.y, cb.z));
  ASSERT_TRUE(bounce.update(uniform));

  // Onto `to` (posed at `at`) from a sphere of radius R and albedo rho at `from`.
  const auto check = [&](int to, const Mesh& mesh, const glm::dvec3& at, const glm::dvec3& from, double R,
                         const glm::vec3& rho) {
    double worst = 0;
    int facing = 0, away = 0;
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      const glm::dvec3 x = glm::dvec3(mesh.positions[v]) + at, n = glm::normalize(glm::dvec3(mesh.normals[v]));
      const double D = glm::length(from - x), cos_theta = glm::dot(n, (from - x) / D);
      const glm::vec3 got = bounce.object_bounce(to)[v];
      if (cos_theta >= R / D) {
        for (int c = 0; c < 3; ++c) {
          const double want = rho[c] * kPi * (R / D) * (R / D) * cos_theta;
          worst = std::max(worst, std::abs(got[c] - want) / want);
        }
        ++facing;
      } else if (cos_theta <= -R / D) {
        EXPECT_EQ(got, glm::vec3(0.0f)) << "vertex " << v << " is turned away";
        ++away;
      }
    }
    std::printf("%d vertices facing the other sphere: worst relative error %.4f; %d turned away get 0\n", facing, worst,
                away);
    EXPECT_GT(facing, 20);
    EXPECT_GT(away, 20);
    EXPECT_LT(worst, 0.03);
  };
  check(b, sphere_b, cb, ca, Ra, rho_a);
  check(a, sphere_a, ca, cb, Rb, rho_b);
  // A sphere that does not reflect (the manifest's "bounce": false) lights nothing.
  bounce.set_object_enabled(b, false);
  bounce.update(uniform);
  for (const glm::vec3& e : bounce.object_bounce(a)) ASSERT_EQ(e, glm::vec3(0.0f));
  EXPECT_THROW(bounce.object_bounce(7), RuntimeError);
}

TEST(ObjectBounce, TheSameOnOneThreadAsOnTwo) {
  // The receivers' loop and the clusters' light run in parallel (tbb); each receiver's sum
  // is its own, so the result must not depend on the threads, bit for bit.
  std::vector<glm::vec3> positions, normals, without;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) {
      positions.push_back({0.05f * float(i), 0.0f, 0.05f * float(j)});
      normals.push_back({0, 1, 0});
      without.push_back(glm::vec3(float(kPi)));
    }
  // Light that varies with the direction, so every cluster differs.
  const auto sky = [](const glm::vec3&, const glm::vec3& n) { return glm::vec3(2.0f + n.y, 1.5f + n.x, 1.0f + n.z); };
  const auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    ObjectBounce bounce(positions, normals, without);
    bounce.add_object(test::make_sphere({0, 0, 0}, 0.2f, 48, 24), glm::vec3(0.8f, 0.4f, 0.2f), translation(0, 0.2, 0));
    bounce.add_object(test::make_sphere({0, 0, 0}, 0.1f, 32, 16), glm::vec3(0.5f), translation(0.35, 0.1, 0.1));
    bounce.update(sky);
    return std::make_tuple(bounce.ratio(), bounce.object_bounce(0), bounce.object_bounce(1), bounce.stats().pairs,
                           bounce.stats().near_pairs);
  };
  const auto one = run(1), two = run(2);
  EXPECT_GT(std::get<4>(one), 0u) << "receivers under the spheres are summed by triangles";
  EXPECT_GT(
      std::count_if(std::get<0>(one).begin(), std::get<0>(one).end(), [](const glm::vec3& r) { return r.x > 0.0f; }),
      100);
  EXPECT_TRUE(one == two);
}

TEST(ObjectBounce, FollowsPoseAlbedoAndSwitch) {
  const std::vector<glm::vec3> positions{{1, 0, 0}}, normals{{0, 1, 0}}, without{glm::vec3(float(kPi))};
  ObjectBounce bounce(positions, normals, without);
  const auto uniform = [](const glm::vec3&, const glm::vec3&) { return glm::vec3(float(kPi)); };
  const int id = bounce.add_object(test::make_sphere({0, 0, 0}, 0.5f, 48, 24), glm::vec3(0.8f, 0.4f, 0.2f),
                                   translation(0, 0.5, 0));
  bounce.update(uniform);
  const glm::vec3 near = bounce.ratio()[0];
  EXPECT_NEAR(near.g / near.r, 0.5f, 1e-5f);  // the colour is the albedo's
  EXPECT_NEAR(near.b / near.r, 0.25f, 1e-5f);
  bounce.set_object_pose(id, translation(-1, 0.5, 0));  // twice as far
  ASSERT_TRUE(bounce.update(uniform));
  EXPECT_LT(bounce.ratio()[0].r, 0.5f * near.r);
  bounce.set_object_albedo(id, glm::vec3(0.0f));
  ASSERT_TRUE(bounce.update(uniform));
  EXPECT_EQ(bounce.ratio()[0], glm::vec3(0.0f));
  bounce.set_object_albedo(id, glm::vec3(0.8f));
  bounce.set_object_enabled(id, false);
  ASSERT_TRUE(bounce.update(uniform));
  EXPECT_EQ(bounce.ratio()[0], glm::vec3(0.0f));
  // Half open everywhere: the sample is lit by half and sends half of that past itself.
  bounce.set_object_enabled(id, true);
  bounce.set_object_pose(id, translation(0, 0.5, 0));
  const Mesh sphere = test::make_sphere({0, 0, 0}, 0.5f, 48, 24);
  std::vector<VertexOcclusion> half(sphere.positions.size());
  for (std::size_t v = 0; v < half.size(); ++v) half[v] = {sphere.normals[v], 0.5f};
  bounce.set_object_occlusion(id, half);
  ASSERT_TRUE(bounce.update(uniform));
  EXPECT_NEAR(bounce.ratio()[0].r, 0.25f * near.r, 1e-4f * near.r);
  EXPECT_THROW(bounce.set_object_occlusion(id, std::vector<VertexOcclusion>(3)), InputError);
  EXPECT_THROW(bounce.set_object_pose(7, glm::dmat4(1.0)), RuntimeError);
  EXPECT_THROW(ObjectBounce(positions, {}, without), InputError);
}

// The whole method as `lumar shadows --bounce` runs it: lines for the shadow, the
// bounce from the objects shaded by the scene's (distant) irradiance volume and their
// baked self-occlusion.
std::vector<glm::vec3> floor_ratio(float albedo, ShadowMethod method) {
  const double R = 0.5;
  LoadedObject sphere;
  sphere.name = "sphere";
  sphere.model = test::make_sphere({0, 0, 0}, float(R), 96, 48);
  sphere.T_world_model = translation(0, R, 0);
  sphere.albedo = glm::vec3(albedo);
  const ShadowScene scene(uniform_sky(), true, test::make_ground(6.0f), {sphere});
  std::vector<glm::vec3> positions, normals;
  for (double x : kDistances) positions.push_back({float(x * R), 0.0f, 0.0f}), normals.push_back({0, 1, 0});
  ShadowMethodOptions options;
  options.bounce = true;
  options.volume_cache = false;
  return shadow_attenuation(scene, positions, normals, method, options);
}

TEST(ObjectBounce, WhiteSphereUnderAUniformSkyLeavesTheFloorUnchanged) {
  // A convex object of albedo ρ under a uniform sky is uniformly lit, so a floor point
  // loses F of its light and gets ρ F back: 1 − (1 − ρ) F. White: exactly 1.
  for (ShadowMethod method : {ShadowMethod::Lines, ShadowMethod::Reference})
    for (float albedo : {1.0f, 0.5f, 0.0f}) {
      const std::vector<glm::vec3> ratio = floor_ratio(albedo, method);
      double worst = 0;
      for (std::size_t i = 0; i < kDistances.size(); ++i) {
        const double expected = 1.0 - (1.0 - albedo) * sphere_form_factor(1.0, kDistances[i]);
        worst = std::max(worst, std::abs(double(ratio[i].g) - expected));
        EXPECT_NEAR(ratio[i].g, expected, 0.03) << (method == ShadowMethod::Lines ? "lines" : "reference")
                                                << ", albedo " << albedo << ", x " << kDistances[i];
      }
      std::printf("%s, albedo %.1f: worst |ratio - (1 - (1 - albedo) F)| = %.4f\n",
                  method == ShadowMethod::Lines ? "lines" : "reference", albedo, worst);
    }
  // The 2004 method had no bounce: refused, not silently left out.
  EXPECT_THROW(floor_ratio(1.0f, ShadowMethod::Sphere), InputError);
}

// The acceptance case: a saturated red box on the sample room's floor, 5 cm from a wall.
struct RedBoxInTheRoom {
  std::unique_ptr<ShadowScene> scene;
  std::vector<glm::vec3> positions, normals;  // floor points around the box

  RedBoxInTheRoom() {
    Scene manifest = load_scene(test::source_dir() / "data/scenes/room/scene.json");
    // The volume covers the corner the box stands in.
    manifest.movement_min = {-2.99, 0.0, -0.7};
    manifest.movement_max = {-1.6, 1.0, 0.9};
    manifest.objects.clear();
    LoadedScene loaded = load_scene_files(manifest);
    LoadedObject box;
    box.name = "red box";
    // Faces of 8 x 8 cells, so that the reference's per-vertex light on the box is not
    // four corners interpolated across a face.
    box.model = test::make_box({-0.15f, 0.0f, -0.15f}, {0.15f, 0.3f, 0.15f}, false, 8);
    const double gap = 0.05;
    box.T_world_model = translation(-3.0 + gap + 0.15, 0.0, 0.1);
    box.albedo = {0.9f, 0.05f, 0.05f};
    loaded.objects.push_back(box);
    scene = std::make_unique<ShadowScene>(std::move(loaded));
    for (float x = -2.97f; x < -1.9f; x += 0.06f)
      for (float z = -0.6f; z < 0.8f; z += 0.06f) {
        if (x > -3.0 + gap - 0.01 && x < -2.69 + gap && z > -0.06f && z < 0.26f) continue;  // under the box
        positions.push_back({x, 0.0f, z});
        normals.push_back({0, 1, 0});
      }
  }
};

TEST(ObjectBounce, RedBoxBesideTheFloorAndAWallMatchesTheReference) {
  RedBoxInTheRoom room;
  ShadowMethodOptions options;
  const std::vector<glm::vec3> shadow =
      shadow_attenuation(*room.scene, room.positions, room.normals, ShadowMethod::Lines, options);
  options.bounce = true;
  const std::vector<glm::vec3> with_bounce =
      shadow_attenuation(*room.scene, room.positions, room.normals, ShadowMethod::Lines, options);
  // The reference's bounce: the ground truth with and without it, with the same rays.
  const std::unique_ptr<RoomRadiance> radiance = scene_radiance(room.scene->scene(), RadianceSettings{});
  CompositeReferenceSettings settings;
  settings.cone_strata = 16;  // converged: at 8 its own noise is 2-3 % of the bounce
  const CompositeReference truth(*radiance, room.scene->objects(), settings);
  settings.bounce = false;
  const CompositeReference truth_without(*radiance, room.scene->objects(), settings);
  double error = 0, size = 0, red = 0, green = 0;
  for (std::size_t i = 0; i < room.positions.size(); ++i) {
    const glm::dvec3 p(room.positions[i]), n(room.normals[i]);
    const glm::dvec3 reference = truth.room_ratio(p, n) - truth_without.room_ratio(p, n);
    const glm::dvec3 bounce = glm::dvec3(with_bounce[i] - shadow[i]);
    for (int c = 0; c < 3; ++c) error += std::abs(bounce[c] - reference[c]), size += reference[c];
    red += bounce.r, green += bounce.g;
  }
  std::printf(
      "red box: bounce vs reference, sum |difference| / sum reference = %.3f over %zu floor points; "
      "mean bounce ratio %.4f (red), %.4f (green)\n",
      error / size, room.positions.size(), red / room.positions.size(), green / room.positions.size());
  EXPECT_GT(size, 0.0);
  EXPECT_LT(error / size, 0.10);
  EXPECT_GT(red, 10 * green);  // the floor turns red, not grey
}

}  // namespace
}  // namespace lumar
