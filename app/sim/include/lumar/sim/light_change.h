#pragma once
// A change of the room's light during a synthetic recording (`lumar synth --change-*`):
// a lamp that goes out, a window whose light turns warmer. The map's texels whose
// direction from the capture point meets the proxy inside a world box are multiplied by
// an RGB factor, from a given time on, over a ramp. The video shows the room under the
// blended map, so the overlay's lighting adaptation (pipeline/live_lighting.h) has a
// change whose truth is known: the changed map.
#include <glm/glm.hpp>

#include "lumar/scene/envmap.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/scene/scene.h"

namespace lumar::sim {

struct LightChange {
  SceneBox region;             // world metres: texels seen on the proxy inside it change
  glm::dvec3 scale{1.0};       // RGB factor
  double brighter_than = 0.0;  // only texels of at least this luminance (a lamp, not the ceiling around it)
  double at_s = 0.0;           // when it starts, seconds into the recording
  double ramp_s = 0.0;         // how long it takes (0: at once)

  // How far the change has gone at t_s: 0 before, 1 once done.
  double weight(double t_s) const;
};

// The scene's map once the change is done. InputError when the region holds no texel
// of the map on the proxy (a box outside the room), or the scale is negative.
EnvironmentMap changed_environment_map(const LoadedScene& scene, const LightChange& change);

// (1 - w) a + w b, texel by texel; the maps must be the same size.
EnvironmentMap blend_environment_maps(const EnvironmentMap& a, const EnvironmentMap& b, double w);

}  // namespace lumar::sim
