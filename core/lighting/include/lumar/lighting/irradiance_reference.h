#pragma once
// Ground truth for irradiance (docs/irradiance.md).
//  - Distant map: a direct cosine-weighted sum over every texel of the map, each with
//    its solid angle: E(n) = Σ L_i Ω_i max(0, n·ω_i).
//  - Room: the bright texels of a full-resolution RoomRadiance summed exactly as small
//    area lights with a visibility ray each (so small lights are never missed), plus
//    the rest by stratified cosine-weighted hemisphere sampling with many rays, each
//    traced against the proxy (exact visibility).
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <vector>

#include "lumar/lighting/room_radiance.h"
#include "lumar/scene/envmap.h"

namespace lumar {

glm::dvec3 texel_sum_irradiance(const EnvironmentMap& map, const glm::dvec3& normal);
// Many normals at once (parallel over normals).
std::vector<glm::dvec3> texel_sum_irradiance(const EnvironmentMap& map, std::span<const glm::dvec3> normals);

// Settings for the RoomRadiance a reference should use: full resolution, bright texels
// up to 2 % of the sphere, no dominant lights.
RadianceSettings reference_radiance_settings();

// E(p, n) with strata × strata cosine-weighted rays (one jittered ray per stratum,
// seeded by the query so results are reproducible).
glm::dvec3 reference_irradiance(const RoomRadiance& room, const glm::dvec3& p, const glm::dvec3& n, int strata = 64);
// Something besides the proxy on p + t·w (w unit) for t in (0, t_far) (t_far infinite:
// out to infinity): the radiance it sends back along the ray (0 when black), or nullopt
// when nothing is there. Virtual objects, for composite_reference.h.
using ExtraOccluder = std::function<std::optional<glm::dvec3>(const glm::dvec3& p, const glm::dvec3& w, double t_far)>;
// The same with `occluder` blocking rays and bright texels too (none when empty), a
// blocked ray bringing the occluder's radiance instead of the room's; rays start off the
// surface along `off_surface` (a geometric normal where `normal` is a shading normal).
glm::dvec3 reference_irradiance(const RoomRadiance& room, const glm::dvec3& p, const glm::dvec3& normal,
                                const glm::dvec3& off_surface, int strata, const ExtraOccluder& occluder);
// Many queries at once (parallel over queries).
std::vector<glm::dvec3> reference_irradiance(const RoomRadiance& room, std::span<const glm::dvec3> points,
                                             std::span<const glm::dvec3> normals, int strata = 64);

}  // namespace lumar
