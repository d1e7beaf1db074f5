#pragma once
// Shared pieces of the irradiance tests: error statistics, the divided
// proxy room with its synthetic window map (built in code, so the tests need no files).
#include <glm/glm.hpp>
#include <vector>

#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"
#include "test_geometry.h"

namespace lumar::test {

struct ErrorStats {
  double mean = 0, p99 = 0, max = 0;
};
// Relative luminance error of `value` against `reference`, per entry.
ErrorStats luminance_errors(const std::vector<glm::dvec3>& value, const std::vector<glm::dvec3>& reference);

// Axis-aligned box, 12 triangles, faces outward (inward if `inward`).
void append_box(Mesh& mesh, const glm::vec3& lo, const glm::vec3& hi, bool inward);

// The divided room: a 6 x 3 x 4 m box (faces inward), a table (0.8 m high) and a
// dividing wall at x = 0 (0.1 m thick) with a 1 m wide, 2 m high doorway at z in
// [1, 2]. The map is captured at (-1.5, 1.5, -0.5) in the bright half (x < 0): dim
// walls (0.05) except a bright window (radiance 30) on the far wall x = -3, and a
// small very bright lamp (2000) on the ceiling.
struct DividedRoom {
  Mesh proxy;
  EnvironmentMap map;
  glm::dvec3 box_min, box_max;  // movement box, both halves
};
DividedRoom make_divided_room();

}  // namespace lumar::test
