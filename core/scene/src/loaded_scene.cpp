#include "lumar/scene/loaded_scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include "decode_counter.h"

namespace lumar {

LoadedScene load_scene_files(const Scene& manifest) {
  LoadedScene out;
  out.manifest = manifest;
  out.map = load_environment_map(manifest.environment_map);
  out.map.capture_position = manifest.capture_position;
  out.map.azimuth_offset_deg = manifest.azimuth_offset_deg;
  if (!manifest.room_mesh.empty())
    out.room = transformed(load_mesh(manifest.room_mesh), glm::dmat4(glm::dmat3(manifest.room_scale)));
  // Objects that share a mesh file share one decode.
  std::map<std::filesystem::path, const Mesh*> decoded;
  out.objects.reserve(manifest.objects.size());  // the pointers above stay valid
  for (const SceneObject& o : manifest.objects) {
    LoadedObject object{o.name, {}, o.T_world_model, o.albedo};
    if (const auto it = decoded.find(o.mesh); it != decoded.end())
      object.model = *it->second;
    else
      object.model = load_mesh(o.mesh);
    out.objects.push_back(std::move(object));
    decoded.emplace(o.mesh, &out.objects.back().model);
  }
  return out;
}

LoadedScene load_scene_files(const std::filesystem::path& manifest) { return load_scene_files(load_scene(manifest)); }

std::map<std::filesystem::path, int> scene_file_decodes() { return decode_counts(); }

}  // namespace lumar
