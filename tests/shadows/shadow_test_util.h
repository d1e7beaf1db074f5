#pragma once
// Shared pieces of the shadow tests: meshes built in code, the sample scene, a sky with
// a sun written as a real EXR, and error statistics against the reference.
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"
#include "test_geometry.h"

namespace lumar::test {

// A square in the y = height plane, facing +Y, split into 2 triangles.
Mesh make_ground(float half_size, float height = 0.0f);
// A regular grid of points on the y = height plane around (cx, cz), normals +Y.
void floor_grid(float cx, float cz, float half, int n, float height, std::vector<glm::vec3>& positions,
                std::vector<glm::vec3>& normals);

// A clear sky (upper hemisphere blue-ish, ground dim) with a small, very bright sun disc
// (angular radius `sun_radius_deg`) at the given elevation and azimuth; W x W/2.
EnvironmentMap make_sun_sky(int width, double sun_elevation_deg, double sun_azimuth_deg, double sun_radius_deg,
                            float sun_radiance);

struct ShadowError {
  double mean_shadowed = 0;  // mean |a - ref| where ref < 0.98 (any channel)
  double mean_lit = 0;       // elsewhere
  std::size_t shadowed = 0, lit = 0;
};
ShadowError shadow_error(const std::vector<glm::vec3>& attenuation, const std::vector<glm::vec3>& reference);

}  // namespace lumar::test
