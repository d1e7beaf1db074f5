#include "lumar/lighting/irradiance_scene.h"

#include "lumar/base/error.h"
#include "lumar/scene/mesh.h"

namespace lumar {

VolumeSettings scene_volume_settings(const LightingSettings& lighting, const std::string& method) {
  VolumeSettings s = volume_settings_for(method);
  if (lighting.spacing) s.spacing = *lighting.spacing;
  if (lighting.rays_per_probe) s.rays_per_probe = *lighting.rays_per_probe;
  if (lighting.octahedral_resolution) s.octahedral_resolution = *lighting.octahedral_resolution;
  if (lighting.max_lights) s.radiance.max_lights = *lighting.max_lights;
  if (lighting.refine) s.refine = *lighting.refine;
  if (lighting.visibility) s.visibility = *lighting.visibility;
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
