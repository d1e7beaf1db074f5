#include "mesh_levels.h"

#include <meshoptimizer.h>

#include <algorithm>

namespace lumar::gl {

std::vector<MeshLevel> mesh_levels(const Mesh& mesh) {
  std::vector<MeshLevel> levels{{mesh.indices, 0.0f}};
  if (mesh.indices.empty()) return levels;
  const float* positions = &mesh.positions[0].x;
  // meshoptimizer's errors are relative to the mesh's size.
  const float scale = meshopt_simplifyScale(positions, mesh.positions.size(), sizeof(glm::vec3));
  while (levels.back().indices.size() / 3 >= 2 * kMinLevelTriangles) {
    const MeshLevel& finer = levels.back();
    const std::size_t target = finer.indices.size() / 6 * 3;
    MeshLevel coarser;
    coarser.indices.resize(mesh.indices.size());  // meshoptimizer may write as many as it reads
    float relative = 0.0f;
    // From the full mesh each time, so that errors do not compound; any error allowed: the
    // triangle count is the target, the error is what it cost.
    coarser.indices.resize(meshopt_simplify(coarser.indices.data(), mesh.indices.data(), mesh.indices.size(), positions,
                                            mesh.positions.size(), sizeof(glm::vec3), target, 1.0f, 0, &relative));
    if (coarser.indices.size() > finer.indices.size() * 4 / 5) break;
    coarser.error = std::max(relative * scale, finer.error);
    levels.push_back(std::move(coarser));
  }
  return levels;
}

}  // namespace lumar::gl
