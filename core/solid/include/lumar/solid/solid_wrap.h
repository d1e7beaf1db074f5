#pragma once
// A closed, manifold, outward-facing surface around a mesh that has cracks and holes,
// such as a scan stitched from patches (docs/solid.md).
//
// CGAL's alpha wrapping alone floods a shell's inside through its holes and wraps both
// sides of it: a thin closed skin whose inner half faces a dark cavity. So the inside is
// found first, by the mesh's winding number estimated with rays (above 1/2: inside; a
// hole is capped flat), filled with points the wrap cannot pass, and only then wrapped;
// the wrap is then simplified to a triangle budget by edge collapses, which keep it closed.
#include <cstddef>
#include <functional>
#include <string>

#include "lumar/scene/mesh.h"

namespace lumar {

struct SolidWrapSettings {
  // Both as shares of the mesh's bounding-box diagonal.
  double alpha = 1.0 / 150;          // the wrap's ball, 1/400 to 1/2: narrower gaps are closed
  double offset = 1.0 / 1500;        // how far the wrap stays outside the mesh's surface
  std::size_t max_triangles = 9000;  // 0: as wrapped
  int rays_per_point = 32;           // the inside test's rays
  double winding_number = 0.5;       // a point is inside from this winding number up
};

struct SolidWrapReport {
  std::size_t inside_points = 0;      // filling the inside
  std::size_t wrapped_triangles = 0;  // before simplification
};

// `progress` (optional) is told each stage as it starts. InputError for a mesh without
// triangles or settings out of range. The result has area-weighted vertex normals.
Mesh wrap_solid(const Mesh& mesh, const SolidWrapSettings& settings = {}, SolidWrapReport* report = nullptr,
                const std::function<void(const std::string&)>& progress = {});

}  // namespace lumar
