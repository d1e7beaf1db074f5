// OccluderMesh: Embree's occlusion test names a triangle that blocks a segment, and the
// cheap walk over the mesh (blocked_near) proves a segment blocked only when Embree finds
// it blocked too, and does so for most segments near a known blocker.
#include "lumar/lighting/shadows/occluder_mesh.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "test_geometry.h"

namespace lumar {
namespace {

struct Segment {
  glm::vec3 origin, dir;  // origin + t dir, t in (0, 1)
};

// Segments between two points on a sphere of radius 0.5 about the origin, aimed across
// it within `spread` of the centre: most pass through a ball of radius 0.1 there.
std::vector<Segment> random_segments(int count, float spread, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Segment> out;
  for (int k = 0; k < count; ++k) {
    const glm::vec3 a = 0.5f * glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    const glm::vec3 aim = spread * glm::vec3(u(rng), u(rng), u(rng));
    out.push_back({a, 2.0f * (aim - a)});
  }
  return out;
}

TEST(OccluderMesh, WalkProvesOnlyWhatEmbreeFinds) {
  const Mesh ball = test::make_sphere({0, 0, 0}, 0.1f, 48, 24);
  const OccluderMesh mesh(ball);
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> any_triangle(0, std::uint32_t(ball.triangle_count() - 1));
  std::size_t blocked = 0, proven_from_blocker = 0, near_blocked = 0, proven_near = 0, wrong = 0;
  for (const Segment& s : random_segments(4000, 0.15f, 1)) {
    std::uint32_t blocker = OccluderMesh::kNoTriangle;
    const bool hit = mesh.occluded(s.origin, s.dir, 1.0f, &blocker);
    // From any triangle: never a proof of a segment Embree finds free.
    std::uint32_t start = any_triangle(rng);
    wrong += mesh.blocked_near(s.origin, s.dir, 1.0f, start) && !hit;
    if (!hit) {
      EXPECT_EQ(blocker, OccluderMesh::kNoTriangle);
      continue;
    }
    ++blocked;
    ASSERT_NE(blocker, OccluderMesh::kNoTriangle);
    // The named blocker proves the segment itself (unless it is met within the margin of an edge).
    std::uint32_t t = blocker;
    proven_from_blocker += mesh.blocked_near(s.origin, s.dir, 1.0f, t);
    // The segment moved 3 mm sideways, as a line moves between two frames: the walk
    // from the old blocker finds the new crossing a few triangles (about 1.3 cm) away.
    const glm::vec3 side = 0.003f * glm::normalize(glm::cross(s.dir, glm::vec3(0.3f, 1.0f, 0.2f)));
    const Segment moved{s.origin + side, s.dir};
    const bool moved_hit = mesh.occluded(moved.origin, moved.dir, 1.0f);
    t = blocker;
    const bool moved_proven = mesh.blocked_near(moved.origin, moved.dir, 1.0f, t);
    wrong += moved_proven && !moved_hit;
    near_blocked += moved_hit, proven_near += moved_proven;
  }
  std::printf("%zu of 4000 segments blocked; proven from their blocker %zu, moved 3 mm %zu of %zu\n", blocked,
              proven_from_blocker, proven_near, near_blocked);
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(blocked, 1500u);
  EXPECT_GT(double(proven_from_blocker), 0.98 * double(blocked));
  EXPECT_GT(double(proven_near), 0.9 * double(near_blocked));
}

TEST(OccluderMesh, SegmentEndingShortOfTheSurfaceIsFree) {
  const Mesh ball = test::make_sphere({0, 0, 0}, 0.1f, 48, 24);
  const OccluderMesh mesh(ball);
  const glm::vec3 origin(0.0f, 0.5f, 0.0f), towards(0.01f, -1.0f, 0.02f);
  std::uint32_t blocker = OccluderMesh::kNoTriangle;
  ASSERT_TRUE(mesh.occluded(origin, towards, 1.0f, &blocker));
  // The same line, ending 2 mm before it reaches the ball (which it meets about 0.4 away).
  const float before = (0.5f - 0.1f - 0.002f) / glm::length(towards);
  EXPECT_FALSE(mesh.occluded(origin, towards, before));
  EXPECT_FALSE(mesh.blocked_near(origin, towards, before, blocker));
  // Reversed, starting inside the ball: the segment still crosses the surface once.
  // (Off the axis: along it the line would meet the pole, a vertex, where no triangle's
  // inside margin holds.)
  const glm::vec3 up(0.013f, 0.5f, 0.007f);
  std::uint32_t t = OccluderMesh::kNoTriangle;
  ASSERT_TRUE(mesh.occluded(glm::vec3(0.0f), up, 1.0f, &t));
  EXPECT_TRUE(mesh.blocked_near(glm::vec3(0.0f), up, 1.0f, t));
}

}  // namespace
}  // namespace lumar
