#pragma once
// A virtual object's mesh as the occluder of shadow lines, in its own model space (the
// lines' ends are moved there per frame, the mesh never): an Embree BVH built once, and
// boxes around pieces of the mesh for shadow cones (shadow_cone.h). Shared by the
// shadows on real receivers (shadow_occlusion.h) and on other objects (object_shadows.h).
#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/core/mesh.h"

namespace lumar {

class OccluderMesh {
 public:
  // Throws InputError for a mesh without triangles.
  explicit OccluderMesh(const Mesh& model);
  ~OccluderMesh();
  OccluderMesh(const OccluderMesh&) = delete;
  OccluderMesh& operator=(const OccluderMesh&) = delete;

  // A box around the whole mesh, and boxes (corner k = centre + sum over axes a of +-E_a / 2, sign from bit a of k, as
  // ShadowCone takes them) around pieces of the mesh, model space; together they hold
  // every triangle.
  const std::array<glm::vec3, 8>& whole() const { return whole_; }
  const std::vector<std::array<glm::vec3, 8>>& pieces() const { return pieces_; }

  // Whether the segment origin + t dir, t in (0, t_far), meets a triangle (model space).
  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float t_far) const;
  // The same for n rays at once, traced as one coherent stream (Embree's rtcOccluded1M):
  // blocked[i] = 1 or 0.
  void occluded(std::size_t n, const glm::vec3* origins, const glm::vec3* dirs, float t_far,
                std::uint8_t* blocked) const;

 private:
  void* scene_ = nullptr;  // RTCScene: Embree stays out of this header
  std::array<glm::vec3, 8> whole_{};
  std::vector<std::array<glm::vec3, 8>> pieces_;
};

}  // namespace lumar
