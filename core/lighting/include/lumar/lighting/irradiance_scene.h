#pragma once
// The irradiance volume of a scene manifest: its map, proxy, movement box and the
// `lighting` settings (docs/irradiance.md), shared by `lumar irradiance` and the Compositor.
#include <filesystem>
#include <memory>
#include <string>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/room_radiance.h"
#include "lumar/lighting/sh.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar {

// Named settings (volume_settings_for) with the manifest's lighting.irradiance knobs.
VolumeSettings scene_volume_settings(const LightingSettings& lighting, const std::string& method);
// The room's radiance: the scene's map on its proxy, or by direction alone when distant.
std::unique_ptr<RoomRadiance> scene_radiance(const LoadedScene& scene, const RadianceSettings& settings);
// The radiance the scene's own volume is built from: scene_radiance with the radiance
// settings of the manifest's lighting.method.
std::unique_ptr<RoomRadiance> scene_base_radiance(const LoadedScene& scene);
// The scene's irradiance volume over its movement box with `method`'s settings, loaded
// from the cache (cache_dir; empty: the default) when it holds one built from the same
// inputs, else built (and stored, unless use_cache is false). `loaded` says which.
IrradianceVolume scene_irradiance_volume(const LoadedScene& scene, const std::string& method, bool use_cache = true,
                                         const std::filesystem::path& cache_dir = {}, bool* loaded = nullptr);

// The scene's lighting after the room changed (pipeline/live_lighting.h): the change
// per map cell; the irradiance volume over the movement box rebuilt from `base` relit to
// the scaled map, so that it has the layout of the scene's own volume and the two can be
// blended (IrradianceVolume::blend); the scaled map's SH9. `base`: scene_base_radiance(scene).
// No volume when the manifest's lighting.method is "sh9".
struct SceneLighting {
  MapCellScale scale;
  std::shared_ptr<const IrradianceVolume> volume;
  SH9 sh{};

  // (1 - w) a + w b: the lighting of the blended light.
  static SceneLighting blend(const SceneLighting& a, const SceneLighting& b, double w);
};
SceneLighting relit_scene_lighting(const LoadedScene& scene, const RoomRadiance& base, const MapCellScale& scale);

}  // namespace lumar
