#pragma once
// Meshes, directions and skies built in code, so that tests need no model files.
#include <glm/glm.hpp>
#include <vector>

#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"

namespace lumar::test {

// Closed UV sphere with outward unit normals.
Mesh make_sphere(const glm::vec3& centre, float radius, int slices, int stacks);
// Axis-aligned box, flat face normals pointing outward (inward if `inward`), each face a
// cells x cells grid (12 triangles for 1).
Mesh make_box(const glm::vec3& min, const glm::vec3& max, bool inward = false, int cells = 1);
// A rectangle through `centre` spanned by half-extents `a` and `b`; all four vertex
// normals are `normal` (need not match the geometry: the shading tests choose it freely).
Mesh make_quad(const glm::vec3& centre, const glm::vec3& a, const glm::vec3& b, const glm::vec3& normal);

// A 256 x 128 lat-long sky of radiance 0.2 with a 3 x 3 texel sun of 4000 at rows 30-32,
// columns 40-42 (towards (0.54, 0.08, 0.83)): the brightest texels, which a volume
// keeps as an exact light.
EnvironmentMap dim_sky_with_sun();

// `count` unit vectors uniformly distributed over the sphere (normalised Gaussians).
std::vector<glm::dvec3> random_normals(int count, unsigned seed);

}  // namespace lumar::test
