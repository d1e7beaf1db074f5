// The room unlike its proxy (sim::furnished_room): closed, every face turned towards the
// room, and differing from the proxy where it says: the far wall 3 cm back with a 20 cm
// recess, the furniture standing in the room.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/sim/furnished_room.h"
#include "test_paths.h"

namespace lumar {
namespace {

std::optional<RayHit> cast(const RayScene& scene, const glm::vec3& from, const glm::vec3& to) {
  Ray ray;
  ray.origin = from;
  ray.direction = glm::normalize(to - from);
  return scene.intersect(ray);
}

TEST(FurnishedRoom, IsClosedAndDiffersFromTheProxyWhereItSays) {
  const LoadedScene scene = load_scene_files(test::source_dir() / "data/scenes/room/scene.json");
  const Mesh room = sim::furnished_room(scene.room);
  RayScene rays;
  rays.add_static(room);
  rays.commit();
  const glm::vec3 capture(0.0f, 1.4f, 0.0f);
  // Every direction from the middle of the room meets a face turned towards it.
  int misses = 0, back_faces = 0;
  for (int i = 0; i < 2000; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 2000, phi = i * 2.399963;  // a Fibonacci sphere
    const double r = std::sqrt(1.0 - z * z);
    const auto hit =
        cast(rays, capture, capture + glm::vec3(float(r * std::cos(phi)), float(z), float(r * std::sin(phi))));
    if (!hit)
      ++misses;
    else if (hit->back_face)
      ++back_faces;
  }
  EXPECT_EQ(misses, 0);
  EXPECT_EQ(back_faces, 0);
  // The far wall (z = -2.5 in the proxy) is 3 cm back, and the recess 20 cm behind it.
  const auto wall = cast(rays, capture, {1.5f, 1.0f, -2.5f});
  ASSERT_TRUE(wall);
  EXPECT_NEAR(capture.z + wall->t * glm::normalize(glm::vec3(1.5f, 1.0f, -2.5f) - capture).z, -2.53f, 1e-4f);
  EXPECT_NEAR(wall->normal.z, 1.0f, 1e-6f);
  const glm::vec3 recess(-0.9f, 0.45f, -2.5f);
  const auto back = cast(rays, capture, recess);
  ASSERT_TRUE(back);
  EXPECT_NEAR(capture.z + back->t * glm::normalize(recess - capture).z, -2.73f, 1e-4f);
  EXPECT_NEAR(back->normal.z, 1.0f, 1e-6f);
  // Looked into from the left, the recess's right side faces the viewer (-x).
  const auto side = cast(rays, {-2.0f, 0.45f, -1.5f}, {-0.4f, 0.45f, -2.65f});
  ASSERT_TRUE(side);
  EXPECT_FALSE(side->back_face);
  EXPECT_NEAR(side->normal.x, -1.0f, 1e-6f);
  // The cabinet stands against the left wall, where the proxy has none.
  const auto cabinet = cast(rays, capture, {-3.0f, 0.5f, -0.8f});
  ASSERT_TRUE(cabinet);
  EXPECT_NEAR(capture.x + cabinet->t * glm::normalize(glm::vec3(-3.0f, 0.5f, -0.8f) - capture).x, -2.55f, 1e-4f);
}

}  // namespace
}  // namespace lumar
