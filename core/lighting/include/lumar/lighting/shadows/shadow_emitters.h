#pragma once
// The light that casts shadows: the environment map's texels mapped back onto the proxy
// surfaces they came from (rays from the capture point through each texel), or kept at
// infinity for a distant map; grouped into emitter patches, each represented by a few
// sample points (the ends of the shadow lines). All the light counts: every lit texel
// belongs to a patch. See docs/shadows.md.
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/envmap.h"
#include "lumar/scene/scene.h"

namespace lumar {

// A point light standing for part of the map.
struct EmitterPoint {
  glm::vec3 position{0.0f};  // on the proxy; for a distant map the unit direction towards the light
  glm::vec3 normal{0.0f};    // proxy surface normal facing the room (unused when distant)
  glm::vec3 flux{0.0f};      // proxy: sum of radiance x area; distant: sum of radiance x solid angle
};

struct EmitterPatch {
  std::uint32_t first_sample = 0, sample_count = 0;  // range in Emitters::samples
  glm::vec3 flux{0.0f};
};

struct Emitters {
  bool distant = false;
  std::vector<EmitterPoint> texels;   // every lit texel at the working resolution
  std::vector<EmitterPoint> samples;  // patch sample points, grouped by patch
  std::vector<EmitterPatch> patches;
  // Share of the receivers' unshadowed irradiance (at their centre) carried by patches
  // small enough to be "resolved" (EmitterOptions::resolved_angle_deg).
  double resolved_fraction = 0.0;
};

struct EmitterOptions {
  int map_width = 128;               // working resolution of the map (box-filtered), 2:1
  double resolved_fraction = 0.9;    // split patches until this share of the irradiance is resolved ...
  double resolved_angle_deg = 10.0;  // ... i.e. sits in patches whose angular radius is below this
  int max_patches = 64;              // ... or until there are this many patches
  int fixed_patches = 0;             // > 0: exactly this many patches (benchmarks), ignoring the above
  int samples_per_patch = 8;         // sample points (line ends) per patch
  // 2004 baseline: keep only texels with luminance >= threshold x the mean (0 = all).
  double threshold_over_mean = 0.0;
  std::vector<SceneBox> regions;  // non-empty: only texels whose proxy point lies inside one
};

// Builds the emitters of `map` seen from receivers around `receiver_centre` facing
// `receiver_normal` (used to rank patches when splitting). `proxy` is the room (may be
// empty); with `distant` the map stays at infinity.
Emitters build_emitters(const EnvironmentMap& map, const RayScene& proxy, bool distant,
                        const glm::vec3& receiver_centre, const glm::vec3& receiver_normal,
                        const EmitterOptions& options = {});

// Unoccluded irradiance at x (unit normal n) from one emitter point.
glm::vec3 emitter_irradiance(const EmitterPoint& e, bool distant, const glm::vec3& x, const glm::vec3& n);

// Where a shadow line from x towards the emitter point ends (distant: far away).
glm::vec3 emitter_line_end(const EmitterPoint& e, bool distant, const glm::vec3& x);
// A distant light's line ends this far (metres) from the receiver: beyond any occluder.
constexpr float kDistantLineLength = 1000.0f;

// Origin of shadow rays leaving a surface point: nudged off the surface along n.
inline glm::vec3 shadow_ray_origin(const glm::vec3& x, const glm::vec3& n) { return x + 1e-3f * n; }

}  // namespace lumar
