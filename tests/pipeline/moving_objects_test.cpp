// An animated object's shadow moves with it. Replaying the walk recording (the figurine
// walks across the floor and turns beside a second, still figurine) with true poses:
// the overlay stands the walker where its path is at each frame's time, and the shadow
// the frame shows (the radiosity lines' attenuation of the floor's receivers) has its
// centroid within 1 cm of the brute-force reference's for that pose, so the shadow
// travels with the object.
#include <gtest/gtest.h>

#include <cstdio>

#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

// The shadow's centroid on the floor: receivers weighted by the light they lose.
glm::dvec3 shadow_centroid(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& attenuation) {
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double w = 1.0 - (attenuation[i].x + attenuation[i].y + attenuation[i].z) / 3.0;
    sum += w * glm::dvec3(positions[i]), weight += w;
  }
  return weight > 0 ? sum / weight : glm::dvec3(0.0);
}

TEST(MovingObjects, TheShadowFollowsThePathOnTheFloor) {
  pipeline::ReplayOverlaySettings settings;
  settings.poses = pipeline::PoseSource::Truth;
  settings.overlay.features = {.antialiasing = false, .self_occlusion = false, .noise = false, .blur = false};
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/walk", settings);
  const LoadedScene& scene = overlay.scene();
  ASSERT_EQ(scene.objects.size(), 2u);
  ASSERT_FALSE(scene.objects[0].path.empty());
  ASSERT_TRUE(scene.objects[1].path.empty());
  const Mesh receivers = ShadowScene(scene).receivers();

  std::vector<glm::dvec3> walker, lines_centroid;
  overlay.run(0, [&](const pipeline::OverlayFrame& f) {
    if (f.index % 23 != 0) return true;  // frames 0, 23 and 46
    // The walker stands where its path is at the frame's time; the other stands still.
    const glm::dmat4 T = scene.objects[0].pose_at(nanos_to_seconds(f.time));
    EXPECT_EQ(overlay.compositor().object_pose(0), T) << f.index;
    EXPECT_EQ(overlay.compositor().object_pose(1), scene.objects[1].T_world_model);
    const auto [lo, hi] = transformed(scene.objects[0].model, T).bounds();
    const glm::dvec3 foot(0.5 * (lo.x + hi.x), 0.0, 0.5 * (lo.z + hi.z));

    // The receivers near the walker: the reference costs a ray per emitter texel each.
    std::vector<glm::vec3> positions, normals, lines;
    const auto& attenuation = overlay.compositor().shadows()->attenuation();
    for (std::size_t i = 0; i < receivers.positions.size(); ++i)
      if (glm::distance(glm::dvec3(receivers.positions[i]), foot) < 0.6) {
        positions.push_back(receivers.positions[i]);
        normals.push_back(receivers.normals[i]);
        lines.push_back(attenuation[i]);
      }
    LoadedScene posed = scene;
    posed.objects[0].T_world_model = T;
    const auto reference =
        shadow_attenuation(ShadowScene(std::move(posed)), positions, normals, ShadowMethod::Reference);
    const glm::dvec3 a = shadow_centroid(positions, lines), b = shadow_centroid(positions, reference);
    std::printf(
        "frame %2lld: walker at (%.3f, %.3f), shadow centroid lines (%.4f, %.4f) reference (%.4f, %.4f): %.1f mm\n",
        static_cast<long long>(f.index), foot.x, foot.z, a.x, a.z, b.x, b.z, 1e3 * glm::distance(a, b));
    EXPECT_LT(glm::distance(a, b), 0.01) << "frame " << f.index << ": lines " << a.x << ", " << a.z << " reference "
                                         << b.x << ", " << b.z;
    walker.push_back(foot);
    lines_centroid.push_back(a);
    return true;
  });
  ASSERT_EQ(walker.size(), 3u);
  // It walks 0.7 m; the shadow goes with it, the same way.
  const glm::dvec3 walked = walker.back() - walker.front(), moved = lines_centroid.back() - lines_centroid.front();
  EXPECT_GT(glm::length(walked), 0.5);
  EXPECT_GT(glm::dot(walked, moved) / glm::dot(walked, walked), 0.7) << moved.x << ", " << moved.z;
}

}  // namespace
}  // namespace lumar
