#include "lumar/scene/scene_writer.h"

#include <glm/gtc/quaternion.hpp>
#include <map>
#include <nlohmann/json.hpp>

#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/base/output_file.h"

namespace lumar {

namespace {

using nlohmann::json;

// `path` (absolute, or relative to the working folder) as the new manifest will name it.
std::string relative_to(const std::filesystem::path& path, const std::filesystem::path& folder) {
  return std::filesystem::absolute(path)
      .lexically_normal()
      .lexically_relative(std::filesystem::absolute(folder).lexically_normal())
      .generic_string();
}

json vec(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }

json pose_json(const glm::dmat4& T) {
  const glm::dmat3 M(T);
  const double scale = glm::length(M[0]);
  const glm::dquat q = glm::normalize(glm::quat_cast(M / scale));
  return {{"translation", vec(glm::dvec3(T[3]))},
          {"rotation_wxyz", json::array({q.w, q.x, q.y, q.z})},
          {"scale", scale},
          {"model_origin", vec(glm::dvec3(0.0))}};
}

}  // namespace

void save_scene(const Scene& scene, const std::filesystem::path& out) {
  json doc = read_json_file(scene.manifest, "scene manifest");
  const std::filesystem::path folder = out.parent_path().empty() ? "." : out.parent_path();
  if (doc.contains("room") && doc["room"].is_object() && !scene.room_mesh.empty())
    doc["room"]["mesh"] = relative_to(scene.room_mesh, folder);
  if (doc.contains("environment_map") && doc["environment_map"].is_object())
    doc["environment_map"]["path"] = relative_to(scene.environment_map, folder);

  // The source's entries by name, so that keys the editor leaves alone stay.
  std::map<std::string, json> before;
  if (doc.contains("objects") && doc["objects"].is_array())
    for (const json& o : doc["objects"])
      if (o.is_object() && o.contains("name") && o["name"].is_string()) before[o["name"].get<std::string>()] = o;
  json objects = json::array();
  for (const SceneObject& o : scene.objects) {
    json entry = before.count(o.name) ? before[o.name] : json::object();
    entry["name"] = o.name;
    entry["mesh"] = relative_to(o.mesh, folder);
    entry["albedo"] = vec(glm::dvec3(o.albedo));
    if (o.bounce)
      entry.erase("bounce");  // the default
    else
      entry["bounce"] = false;
    // An animated object keeps its source's pose and path: its keys are read against
    // that pose (its scale, origin and rotation).
    if (o.path.empty() || !entry.contains("path")) {
      entry["pose"] = pose_json(o.T_world_model);
      entry.erase("path");
    }
    objects.push_back(entry);
  }
  doc["objects"] = objects;
  if (doc.contains("lighting") || scene.lighting.method != LightingSettings{}.method)
    doc["lighting"]["method"] = scene.lighting.method;
  write_file_atomically(out, doc.dump(2) + "\n");
}

}  // namespace lumar
