#pragma once
// Coarser versions of a mesh for drawing it small: each level about half the triangles of
// the one before, over the same vertices (meshoptimizer's edge collapses keep a subset of
// them), so everything kept per vertex (light, occlusion, bounce) stays valid at every
// level. On a software rasteriser the cost of an object is its triangles, not its pixels.
#include <cstdint>
#include <vector>

#include "lumar/scene/mesh.h"

namespace lumar::gl {

struct MeshLevel {
  std::vector<std::uint32_t> indices;  // three per triangle, into the full mesh's vertices
  float error = 0.0f;                  // how far its surface may be from the full one, model units
};

// Level 0 is the mesh itself (error 0). Then about half the triangles each, down to
// kMinLevelTriangles or until a halving no longer removes a fifth of them (the rest is
// borders and seams that are locked). Errors grow with the level.
std::vector<MeshLevel> mesh_levels(const Mesh& mesh);

inline constexpr std::size_t kMinLevelTriangles = 256;

}  // namespace lumar::gl
