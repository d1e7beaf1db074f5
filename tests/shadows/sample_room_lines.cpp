#include "sample_room_lines.h"

#include "test_paths.h"

namespace lumar::test {

SampleRoomLines sample_room_lines(int receiver_vertices) {
  SampleRoomLines room;
  LoadedScene scene = load_scene_files(source_dir() / "data/scenes/room/scene.json");
  scene.manifest.shadows.receiver_vertices = receiver_vertices;
  room.scene = std::make_unique<ShadowScene>(std::move(scene));
  room.receivers = room.scene->receivers();
  const Emitters e = room.scene->emitters(room.receivers.positions, room.receivers.normals);
  room.lines = build_shadow_lines(room.receivers.positions, room.receivers.normals, e, room.scene->proxy());
  return room;
}

}  // namespace lumar::test
