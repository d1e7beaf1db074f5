#pragma once
// The scene manifest (scene.json, format in docs/formats.md): the proxy room model,
// the environment map, the box where virtual objects may move, the virtual objects
// and the lighting settings. Relative paths are resolved against the manifest's folder.
#include <filesystem>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lumar {

struct SceneObject {
  std::string name;
  std::filesystem::path mesh;
  // T_world_model = translate(translation) * rotate(axis, angle) * scale(s) * translate(-model_origin)
  glm::dmat4 T_world_model{1.0};
  glm::vec3 albedo{0.8f};
};

struct Scene {
  std::filesystem::path manifest;
  std::filesystem::path room_mesh;
  double room_scale = 1.0;  // room model units to metres
  std::filesystem::path environment_map;
  glm::dvec3 capture_position{0.0};
  double azimuth_offset_deg = 0.0;
  bool distant_map = false;  // map at infinity: no proxy needed for lighting
  glm::dvec3 movement_min{0.0}, movement_max{0.0};
  std::vector<SceneObject> objects;
  nlohmann::json lighting = nlohmann::json::object();  // per-method settings, kept as given
};

// Throws InputError naming the manifest (and the key) on missing files, malformed
// JSON, missing keys or bad values.
Scene load_scene(const std::filesystem::path& manifest);

}  // namespace lumar
