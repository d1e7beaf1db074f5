// RayScene against an independent brute-force ray-triangle test (Möller–Trumbore).
#include "lumar/lighting/ray_scene.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "test_paths.h"

namespace lumar {
namespace {

std::optional<float> brute_force_hit(const Mesh& m, const glm::dmat4& T, const Ray& ray) {
  std::optional<float> best;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec3(T * glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + k]]), 1.0));
    const glm::dvec3 o(ray.origin), d(ray.direction);
    const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::dvec3 h = glm::cross(d, e2);
    const double a = glm::dot(e1, h);
    if (std::abs(a) < 1e-14) continue;
    const glm::dvec3 s = o - p[0];
    const double u = glm::dot(s, h) / a;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) / a;
    const double tt = glm::dot(e2, q) / a;
    if (u < 0 || v < 0 || u + v > 1 || tt < ray.t_near || tt > ray.t_far) continue;
    if (!best || tt < *best) best = float(tt);
  }
  return best;
}

Mesh figurine() { return load_mesh(test::shared_dir() / "data/models/parasaurolophus_6700.ply"); }

TEST(RayScene, NearestHitsMatchBruteForceOnInstancedFigurine) {
  const Mesh mesh = figurine();
  const auto [lo, hi] = mesh.bounds();
  const glm::dvec3 centre = (glm::dvec3(lo) + glm::dvec3(hi)) * 0.5;
  glm::dmat4 T = glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, 0.2, -0.1)) *
                 glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(0, 1, 0)) *
                 glm::scale(glm::dmat4(1.0), glm::dvec3(0.002)) * glm::translate(glm::dmat4(1.0), -centre);
  RayScene scene;
  const int id = scene.add_instance(mesh, glm::dmat4(1.0));
  scene.set_instance_transform(id, T);  // moved after creation: must take effect
  scene.commit();

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    Ray ray;
    ray.origin = glm::vec3(0.3f, 0.2f, -0.1f) + glm::vec3(u(rng), u(rng), 1.0f) * 0.6f;
    const glm::vec3 target = glm::vec3(0.3f, 0.2f, -0.1f) + glm::vec3(u(rng), u(rng), u(rng)) * 0.15f;
    ray.direction = glm::normalize(target - ray.origin);
    const auto expected = brute_force_hit(mesh, T, ray);
    const auto got = scene.intersect(ray);
    ASSERT_EQ(expected.has_value(), got.has_value()) << "ray " << i;
    EXPECT_EQ(scene.occluded(ray), expected.has_value());
    if (got) {
      ++hits;
      EXPECT_NEAR(got->t, *expected, 1e-4f);
      EXPECT_EQ(got->instance, id);
      EXPECT_LT(glm::dot(got->normal, ray.direction), 0.0f);
    }
  }
  EXPECT_GT(hits, 30);  // the rays must actually test the mesh
}

TEST(RayScene, StaticMeshAndBatchQueriesAgree) {
  // A unit square at y = 0 facing up, two triangles.
  Mesh floor;
  floor.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  floor.normals.assign(4, {0, 1, 0});
  floor.indices = {0, 2, 1, 0, 3, 2};
  RayScene scene;
  EXPECT_TRUE(scene.empty());
  EXPECT_EQ(scene.add_static(floor), 0u);
  scene.commit();
  EXPECT_FALSE(scene.empty());

  std::vector<Ray> rays;
  for (int i = 0; i < 1000; ++i) {
    const float x = -1.5f + 3.0f * float(i) / 999.0f;
    rays.push_back({{x, 2.0f, 0.3f}, 0.0f, {0.0f, -1.0f, 0.0f}, (i % 3 == 0) ? 1.5f : 10.0f});
  }
  std::vector<std::uint8_t> blocked(rays.size());
  scene.occluded(rays, blocked);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool inside = std::abs(rays[i].origin.x) < 1.0f;
    EXPECT_EQ(bool(blocked[i]), inside && rays[i].t_far > 2.0f) << i;
    EXPECT_EQ(bool(blocked[i]), scene.occluded(rays[i])) << i;
  }
  const auto hit = scene.intersect({{0.2f, 2.0f, 0.3f}, 0.0f, {0.0f, -2.0f, 0.0f}, 10.0f});
  ASSERT_TRUE(hit);
  EXPECT_FLOAT_EQ(hit->t, 1.0f);  // direction length 2: t in its units
  EXPECT_EQ(hit->instance, -1);
  EXPECT_EQ(hit->normal, glm::vec3(0, 1, 0));
  EXPECT_FALSE(hit->back_face);
  const auto from_below = scene.intersect({{0.2f, -2.0f, 0.3f}, 0.0f, {0.0f, 1.0f, 0.0f}, 10.0f});
  ASSERT_TRUE(from_below);
  EXPECT_TRUE(from_below->back_face);
  EXPECT_EQ(from_below->normal, glm::vec3(0, -1, 0));  // facing against the ray
}

// A box standing on the floor: its bottom face and the floor lie in one plane, so a ray
// from inside the box meets both at the same distance. Which one Embree reports depends
// on its kernels (the instruction set it picked); intersect() must say "back face" either
// way, since the ray starts inside geometry. Checked for both orders of adding the two
// meshes and for the box as an instance.
TEST(RayScene, CoincidentFacesFromInsideGeometryAreBackFaces) {
  Mesh floor;
  floor.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  floor.normals.assign(4, {0, 1, 0});
  floor.indices = {0, 2, 1, 0, 3, 2};
  Mesh box;  // [-0.5, 0.5] x [0, 1] x [-0.5, 0.5], faces outwards
  for (int k = 0; k < 8; ++k)
    box.positions.push_back({k & 1 ? 0.5f : -0.5f, k & 2 ? 1.0f : 0.0f, k & 4 ? 0.5f : -0.5f});
  box.normals.assign(8, {0, 1, 0});
  box.indices = {0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
                 1, 3, 7, 1, 7, 5, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
  const glm::dmat4 lift = glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, 0.0, -0.2));
  for (int variant = 0; variant < 3; ++variant) {
    RayScene scene;
    glm::dvec3 offset(0.0);
    if (variant == 0) scene.add_static(floor), scene.add_static(box);
    if (variant == 1) scene.add_static(box), scene.add_static(floor);
    if (variant == 2) scene.add_instance(box, lift), scene.add_static(floor), offset = glm::dvec3(lift[3]);
    scene.commit();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.45f, 0.45f);
    for (int i = 0; i < 200; ++i) {
      const glm::vec3 inside = glm::vec3(offset) + glm::vec3(u(rng), 0.5f + u(rng), u(rng));
      const auto down = scene.intersect({inside, 0.0f, {0.0f, -1.0f, 0.0f}, 10.0f});
      ASSERT_TRUE(down);
      EXPECT_TRUE(down->back_face) << "variant " << variant << ", ray " << i;
      EXPECT_NEAR(down->t, inside.y, 1e-5f);
      EXPECT_EQ(down->normal, glm::vec3(0, 1, 0)) << "variant " << variant;  // facing against the ray
      // Outside the box the floor is the only face there: a front face.
      const glm::vec3 beside = inside + glm::vec3(1.2f, 0.0f, 0.0f);
      const auto floor_hit = scene.intersect({beside, 0.0f, {0.0f, -1.0f, 0.0f}, 10.0f});
      ASSERT_TRUE(floor_hit);
      EXPECT_FALSE(floor_hit->back_face);
    }
  }
}

}  // namespace
}  // namespace lumar
