#pragma once
// The irradiance volume of a scene manifest: its map, proxy, movement box and the
// `lighting` settings (docs/irradiance.md), shared by `lumar irradiance` and the Compositor.
//
// scene.json "lighting" keys read here (all optional):
//   "method": "volume" | "sh9" | "octahedral" | "lights" | "greger2004" (default "volume";
//             the Compositor keeps its plain per-object SH9 for "sh9"),
//   "irradiance": {"spacing": m, "rays_per_probe": n, "octahedral_resolution": n,
//                  "max_lights": n, "refine": bool, "visibility": bool}
#include <filesystem>
#include <memory>
#include <string>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/room_radiance.h"
#include "lumar/scene/scene.h"

namespace lumar {

// The scene's method name (lighting.method, else "volume").
std::string scene_lighting_method(const Scene& scene);
// Named settings with the scene's lighting.irradiance overrides. Throws InputError
// naming the manifest for a bad value.
VolumeSettings scene_volume_settings(const Scene& scene, const std::string& method);
// Loads the map (with capture point and azimuth offset) and, unless distant, the proxy.
std::unique_ptr<RoomRadiance> scene_radiance(const Scene& scene, const RadianceSettings& settings);

}  // namespace lumar
