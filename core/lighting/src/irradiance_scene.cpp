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
  if (lighting.shadow_map_resolution) s.shadow_map_resolution = *lighting.shadow_map_resolution;
  if (lighting.refine) s.refine = *lighting.refine;
  if (lighting.visibility) s.visibility = *lighting.visibility;
  return s;
}

std::unique_ptr<RoomRadiance> scene_radiance(const LoadedScene& scene, const RadianceSettings& settings) {
  if (scene.distant()) return std::make_unique<RoomRadiance>(scene.map, settings);
  return std::make_unique<RoomRadiance>(scene.map, scene.room, settings);
}

std::unique_ptr<RoomRadiance> scene_base_radiance(const LoadedScene& scene) {
  const LightingSettings& lighting = scene.manifest.lighting;
  return scene_radiance(scene, scene_volume_settings(lighting, lighting.method).radiance);
}

IrradianceVolume scene_irradiance_volume(const LoadedScene& scene, const std::string& method, bool use_cache,
                                         const std::filesystem::path& cache_dir, bool* loaded) {
  const VolumeSettings settings = scene_volume_settings(scene.manifest.lighting, method);
  const auto radiance = scene_radiance(scene, settings.radiance);
  const Scene& m = scene.manifest;
  if (loaded) *loaded = false;
  if (!use_cache) return IrradianceVolume::build(*radiance, m.movement_min, m.movement_max, settings);
  return cached_irradiance_volume(*radiance, m.movement_min, m.movement_max, settings, cache_dir, loaded);
}

SceneLighting SceneLighting::blend(const SceneLighting& a, const SceneLighting& b, double w) {
  SceneLighting out;
  out.scale = MapCellScale::blend(a.scale, b.scale, w);
  if (a.volume && b.volume)
    out.volume = std::make_shared<const IrradianceVolume>(IrradianceVolume::blend(*a.volume, *b.volume, w));
  for (std::size_t i = 0; i < out.sh.coefficients.size(); ++i)
    out.sh.coefficients[i] = (1.0 - w) * a.sh.coefficients[i] + w * b.sh.coefficients[i];
  return out;
}

SceneLighting relit_scene_lighting(const LoadedScene& scene, const RoomRadiance& base, const MapCellScale& scale) {
  SceneLighting out;
  out.scale = scale;
  const EnvironmentMap map = scale_environment_map(scene.map, scale);
  out.sh = project_radiance_sh9(map);
  const std::string& method = scene.manifest.lighting.method;
  if (method == "sh9") return out;
  const RoomRadiance relit(base, map);
  const Scene& m = scene.manifest;
  out.volume = std::make_shared<const IrradianceVolume>(
      IrradianceVolume::build(relit, m.movement_min, m.movement_max, scene_volume_settings(m.lighting, method)));
  return out;
}

}  // namespace lumar
