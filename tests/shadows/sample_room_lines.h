#pragma once
// The sample room's shadow lines, as several shadow tests start from them: the scene
// manifest's floor receivers (`receiver_vertices` of them), its emitters, and the lines.
#include <memory>

#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/scene/mesh.h"

namespace lumar::test {

struct SampleRoomLines {
  std::unique_ptr<ShadowScene> scene;
  Mesh receivers;
  ShadowLines lines;
  const ShadowScene::Object& figurine() const { return scene->objects().at(0); }
};

SampleRoomLines sample_room_lines(int receiver_vertices);

}  // namespace lumar::test
