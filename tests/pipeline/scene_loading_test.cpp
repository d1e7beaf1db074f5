// The scene is decoded once per run: the overlay hands one LoadedScene to the renderer,
// the irradiance volume and the shadows, and none of them reads a scene file again.
#include <gtest/gtest.h>

#include <set>

#include "lumar/pipeline/replay_overlay.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

std::filesystem::path real_path(const std::filesystem::path& p) { return std::filesystem::weakly_canonical(p); }

TEST(SceneLoading, AnOverlayRunDecodesEachSceneFileOnce) {
  ASSERT_TRUE(scene_file_decodes().empty());
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/orbit");
  int frames = 0;
  overlay.run(4, [&](const pipeline::OverlayFrame&) { return ++frames > 0; });
  EXPECT_EQ(frames, 4);

  const Scene& manifest = overlay.scene().manifest;
  std::set<std::filesystem::path> files{real_path(manifest.environment_map), real_path(manifest.room_mesh)};
  for (const SceneObject& o : manifest.objects) files.insert(real_path(o.mesh));
  const auto decodes = scene_file_decodes();
  EXPECT_EQ(decodes.size(), files.size());
  for (const auto& [file, count] : decodes) {
    EXPECT_TRUE(files.count(file)) << file << " is not a file of the scene";
    EXPECT_EQ(count, 1) << file << " was decoded " << count << " times";
  }
}

TEST(SceneLoading, ObjectsSharingAMeshShareOneDecode) {
  Scene manifest = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  SceneObject twin = manifest.objects.at(0);
  twin.name = "twin";
  manifest.objects.push_back(twin);
  const LoadedScene scene = load_scene_files(manifest);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[1].model.positions, scene.objects[0].model.positions);
  EXPECT_EQ(scene_file_decodes().at(real_path(twin.mesh)), 1);
  // The map is placed once, where the manifest says.
  EXPECT_EQ(scene.map.capture_position, manifest.capture_position);
  EXPECT_EQ(scene.map.azimuth_offset_deg, manifest.azimuth_offset_deg);
  EXPECT_FALSE(scene.distant());
}

}  // namespace
}  // namespace lumar
