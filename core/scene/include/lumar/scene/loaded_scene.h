#pragma once
// A scene manifest with its files decoded once: the environment map, placed at the
// manifest's capture point and azimuth; the proxy room in world metres; each object's
// mesh. Built once per run and handed to everything that needs the scene (lighting,
// shadows, the renderer, the synthesiser), so no part decodes or places a file again.
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"
#include "lumar/scene/object_path.h"
#include "lumar/scene/scene.h"

namespace lumar {

struct LoadedObject {
  std::string name;
  Mesh model;                     // in the file's units
  glm::dmat4 T_world_model{1.0};  // its pose; an animated object's at its path's start
  glm::vec3 albedo{0.8f};
  ObjectPath path;     // empty: it stands still
  bool bounce = true;  // it reflects light onto the real surfaces

  // Where it stands t seconds into the recording.
  glm::dmat4 pose_at(double t_s) const { return path.empty() ? T_world_model : path.at(t_s); }
};

struct LoadedScene {
  Scene manifest;
  EnvironmentMap map;                 // capture_position and azimuth_offset_deg set
  Mesh room;                          // the proxy in world metres; empty without one
  std::vector<LoadedObject> objects;  // in manifest order

  // The map lights by direction alone: the manifest says it is distant, or there is no
  // proxy to project it onto. The one definition every part uses.
  bool distant() const { return manifest.distant_map || room.triangle_count() == 0; }
};

// Decodes every file the manifest names, each once. InputError naming the file.
LoadedScene load_scene_files(const Scene& manifest);
// load_scene, then the above.
LoadedScene load_scene_files(const std::filesystem::path& manifest);

// How many times this process has decoded each scene file (maps and meshes), by path:
// what a test counts to know that a run read its scene once.
std::map<std::filesystem::path, int> scene_file_decodes();

}  // namespace lumar
