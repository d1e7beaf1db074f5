// Saving an edited scene: read back, it places every object at the same matrix, keeps
// what the editor does not touch (lighting, shadows, an animated object's path), and its
// relative paths still find the files from another folder.
#include "lumar/scene/scene_writer.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(SceneWriter, EditedObjectsReadBackAtTheSameMatrices) {
  const test::Scratch scratch("scene-writer");
  Scene scene = load_scene(test::source_dir() / "data/scenes/room/walk.json");
  const LoadedScene loaded = load_scene_files(scene);
  ASSERT_EQ(scene.objects.size(), 2u);
  // The still figurine is moved, turned, scaled and recoloured; a third object is added.
  SceneObject& still = scene.objects[1];
  const glm::dmat4& T = loaded.objects[1].T_world_model;
  const auto [lo, hi] = transformed(loaded.objects[1].model, T).bounds();
  const glm::dvec3 foot(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
  still.T_world_model = glm::translate(glm::dmat4(1.0), foot + glm::dvec3(-0.123456789, 0.0, 0.1)) *
                        glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(0, 1, 0)) *
                        glm::scale(glm::dmat4(1.0), glm::dvec3(1.1)) * glm::translate(glm::dmat4(1.0), -foot) * T;
  still.albedo = glm::vec3(0.1f, 0.5f, 0.25f);
  still.bounce = false;
  SceneObject added = still;
  added.name = "added";
  added.T_world_model = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.5, 0.0, 0.5)) * loaded.objects[1].T_world_model;
  scene.objects.push_back(added);
  scene.objects[0].T_world_model = loaded.objects[0].T_world_model;

  std::filesystem::create_directories(scratch.dir / "elsewhere");
  const auto out = scratch.dir / "elsewhere/edited.json";
  save_scene(scene, out);
  const LoadedScene back = load_scene_files(out);
  ASSERT_EQ(back.objects.size(), 3u);
  for (std::size_t i = 1; i < 3; ++i)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(back.objects[i].T_world_model[c][r], scene.objects[i].T_world_model[c][r], 1e-12) << i;
  EXPECT_EQ(back.objects[1].albedo, scene.objects[1].albedo);  // `still` dangles after the push_back
  EXPECT_FALSE(back.objects[1].bounce);
  EXPECT_TRUE(back.objects[0].bounce);
  EXPECT_EQ(back.objects[2].name, "added");
  EXPECT_FALSE(back.objects[2].bounce);
  // The walker keeps its path: the same poses along it.
  ASSERT_FALSE(back.objects[0].path.empty());
  for (double t : {0.0, 0.7, 1.9, 5.0})
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(back.objects[0].pose_at(t)[c][r], loaded.objects[0].pose_at(t)[c][r], 1e-12) << t;
  // The room, the map and the lighting are the source's.
  EXPECT_EQ(std::filesystem::canonical(back.manifest.room_mesh), std::filesystem::canonical(scene.room_mesh));
  EXPECT_EQ(std::filesystem::canonical(back.manifest.environment_map),
            std::filesystem::canonical(scene.environment_map));
  EXPECT_EQ(back.manifest.lighting.method, "volume");
  EXPECT_EQ(back.manifest.movement_max, scene.movement_max);
}

TEST(SceneWriter, AMissingSourceManifestIsAnInputErrorAndNothingIsWritten) {
  const test::Scratch scratch("scene-writer");
  Scene scene = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  scene.manifest = scratch.dir / "gone.json";
  EXPECT_THROW(save_scene(scene, scratch.dir / "out.json"), InputError);
  EXPECT_FALSE(std::filesystem::exists(scratch.dir / "out.json"));
}

}  // namespace
}  // namespace lumar
