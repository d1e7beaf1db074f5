#pragma once
// The irradiance volume of a scene manifest: its map, proxy, movement box and the
// `lighting` settings (docs/irradiance.md), shared by `lumar irradiance` and the Compositor.
#include <filesystem>
#include <memory>
#include <string>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/room_radiance.h"
#include "lumar/scene/scene.h"

namespace lumar {

// Named settings (volume_settings_for) with the manifest's lighting.irradiance knobs.
VolumeSettings scene_volume_settings(const LightingSettings& lighting, const std::string& method);
// Loads the map (with capture point and azimuth offset) and, unless distant, the proxy.
std::unique_ptr<RoomRadiance> scene_radiance(const Scene& scene, const RadianceSettings& settings);

}  // namespace lumar
