#include "lumar/lighting/irradiance_scene.h"

#include "lumar/base/error.h"
#include "lumar/scene/mesh.h"

namespace lumar {

std::string scene_lighting_method(const Scene& scene) {
  const auto it = scene.lighting.find("method");
  if (it == scene.lighting.end()) return "volume";
  if (!it->is_string())
    throw InputError(scene.manifest.string() + ": lighting.method: expected a string such as \"volume\"");
  return it->get<std::string>();
}

VolumeSettings scene_volume_settings(const Scene& scene, const std::string& method) {
  VolumeSettings s = volume_settings_for(method == "sh9-object" ? "sh9" : method);
  const auto it = scene.lighting.find("irradiance");
  if (it == scene.lighting.end()) return s;
  const std::string where = scene.manifest.string() + ": lighting.irradiance";
  if (!it->is_object()) throw InputError(where + ": expected an object");
  for (const auto& [key, value] : it->items()) {
    const auto number = [&](double lo, double hi) {
      if (!value.is_number() || value.get<double>() < lo || value.get<double>() > hi)
        throw InputError(where + "." + key + ": expected a number in [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "]");
      return value.get<double>();
    };
    const auto boolean = [&] {
      if (!value.is_boolean()) throw InputError(where + "." + key + ": expected true or false");
      return value.get<bool>();
    };
    if (key == "spacing")
      s.spacing = number(0.02, 100.0);
    else if (key == "rays_per_probe")
      s.rays_per_probe = int(number(16, 65536));
    else if (key == "octahedral_resolution")
      s.octahedral_resolution = int(number(2, 64));
    else if (key == "max_lights")
      s.radiance.max_lights = int(number(0, 32));
    else if (key == "refine")
      s.refine = boolean();
    else if (key == "visibility")
      s.visibility = boolean();
    else
      throw InputError(where + "." + key +
                       ": unknown key; use spacing, rays_per_probe, octahedral_resolution, "
                       "max_lights, refine or visibility");
  }
  return s;
}

std::unique_ptr<RoomRadiance> scene_radiance(const Scene& scene, const RadianceSettings& settings) {
  EnvironmentMap map = load_environment_map(scene.environment_map);
  map.capture_position = scene.capture_position;
  map.azimuth_offset_deg = scene.azimuth_offset_deg;
  if (scene.distant_map || scene.room_mesh.empty()) return std::make_unique<RoomRadiance>(map, settings);
  const double k = scene.room_scale;
  return std::make_unique<RoomRadiance>(map, transformed(load_mesh(scene.room_mesh), glm::dmat4(glm::dmat3(k))),
                                        settings);
}

}  // namespace lumar
