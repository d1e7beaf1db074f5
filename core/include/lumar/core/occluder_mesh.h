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

  // A ray of a stream, laid out as Embree's RTCRay (checked where it is traced), so that
  // a stream is traced where it was filled, without a copy.
  struct StreamRay {
    glm::vec3 origin{0.0f};
    float t_near = 0.0f;
    glm::vec3 dir{0.0f};
    float time = 0.0f;
    float t_far = 0.0f;  // after occluded(): negative when the ray is blocked
    std::uint32_t mask = ~0u, id = 0, flags = 0;
  };
  // Many rays at once, as one coherent stream (Embree's rtcOccluded1M).
  void occluded(StreamRay* rays, std::size_t n) const;

 private:
  void* scene_ = nullptr;  // RTCScene: Embree stays out of this header
  std::array<glm::vec3, 8> whole_{};
  std::vector<std::array<glm::vec3, 8>> pieces_;
};

}  // namespace lumar
