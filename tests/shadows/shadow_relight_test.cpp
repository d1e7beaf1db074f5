// The shadow lines relit (the room's light changed): scaling each emitter sample's light
// after the lines were built gives the shadows of lines built from the scaled emitters.
#include <gtest/gtest.h>

#include "lumar/base/error.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/scene/scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(ShadowRelight, MatchesLinesBuiltFromTheRelitEmitters) {
  Scene manifest = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  manifest.shadows.receiver_vertices = 400;
  const ShadowScene scene(load_scene_files(manifest));
  const Mesh receivers = scene.receivers();
  EmitterOptions options;
  options.max_patches = 16;
  const Emitters emitters = scene.emitters(receivers.positions, receivers.normals, options);
  ASSERT_GE(emitters.patches.size(), 2u);
  // Every line kept, so that the two sets hold the same lines.
  const ShadowLineOptions all_lines{.max_dropped_fraction = 0.0};

  // The brightest patch goes out (a lamp); the next turns warmer.
  std::vector<glm::vec3> scale(emitters.samples.size(), glm::vec3(1.0f));
  const auto set_patch = [&](std::size_t p, glm::vec3 k) {
    for (std::uint32_t s = 0; s < emitters.patches[p].sample_count; ++s)
      scale[emitters.patches[p].first_sample + s] = k;
  };
  set_patch(0, glm::vec3(0.0f));
  set_patch(1, glm::vec3(1.5f, 1.0f, 0.5f));
  Emitters relit = emitters;
  for (std::size_t s = 0; s < relit.samples.size(); ++s) relit.samples[s].flux *= scale[s];

  const auto& object = scene.objects().front();
  const auto shadows = [&](const Emitters& e) {
    auto lines = std::make_unique<LineShadows>(
        build_shadow_lines(receivers.positions, receivers.normals, e, scene.proxy(), all_lines));
    lines->add_object(object.model, object.T_world_model);
    lines->update();
    return lines;
  };
  auto built = shadows(emitters);
  const std::vector<glm::vec3> before = built->attenuation();
  const auto reference = shadows(relit);

  built->relight(std::vector<glm::vec3>(emitters.samples.size(), glm::vec3(1.0f)));
  double unchanged = 0;
  for (std::size_t i = 0; i < before.size(); ++i)
    unchanged = std::max(unchanged, double(glm::length(built->attenuation()[i] - before[i])));
  EXPECT_LT(unchanged, 1e-5) << "relit by ones, the shadows must not change";

  built->relight(scale);
  double worst = 0, moved = 0, worst_unshadowed = 0;
  for (std::size_t i = 0; i < before.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, double(std::abs(built->attenuation()[i][c] - reference->attenuation()[i][c])));
      moved = std::max(moved, double(std::abs(built->attenuation()[i][c] - before[i][c])));
      const double want = reference->lines().unshadowed[i][c];
      if (want > 0)
        worst_unshadowed = std::max(worst_unshadowed, std::abs(built->lines().unshadowed[i][c] - want) / want);
    }
  std::printf("relit against rebuilt: attenuation within %.2g, E_without within %.2g %%; the change moved it by %.3f\n",
              worst, 100 * worst_unshadowed, moved);
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(worst_unshadowed, 1e-4);
  EXPECT_GT(moved, 0.01) << "the change should move the shadows";
  EXPECT_THROW(built->relight({glm::vec3(1.0f)}), RuntimeError);
}

}  // namespace
}  // namespace lumar
