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

#include "lumar/scene/mesh.h"

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

  static constexpr std::uint32_t kNoTriangle = ~std::uint32_t(0);

  // Whether the segment origin + t dir, t in (0, t_far), meets a triangle (model space).
  // If it does and `blocker` is given, *blocker is set to a triangle that it meets.
  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float t_far, std::uint32_t* blocker = nullptr) const;
  // Whether the segment surely meets a triangle found by walking over the mesh from
  // `triangle` towards the segment (a few steps across edges); the one it meets is
  // written back to `triangle`. A cheap proof that a line is blocked when a nearby line
  // (the same line, last frame) was blocked by `triangle`. A hit must lie inside a
  // triangle by a margin, so every line it proves blocked, Embree finds blocked too;
  // false means "not proven", and Embree decides.
  bool blocked_near(const glm::vec3& origin, const glm::vec3& dir, float t_far, std::uint32_t& triangle) const;
  // How far (metres) lines may have moved across the mesh since their blockers were found
  // for a walk from them to pay: a few of the figurine's ~1 cm triangles. Beyond, callers
  // drop the blockers (every walk would fail, only adding to Embree's cost).
  static constexpr double kWalkReach = 0.03;
  // Whether a box (corners in some model space) moved at most kWalkReach in the world
  // between the two maps of that space to the world: then walks from blockers found
  // `then` pay `now`.
  static bool within_walk_reach(const std::array<glm::vec3, 8>& box, const glm::dmat4& world_now,
                                const glm::dmat4& world_then);
  // Starts loading a triangle that blocked_near will soon start from (a hint).
  void prefetch(std::uint32_t triangle) const {
    if (triangle < triangles_.size()) __builtin_prefetch(&triangles_[triangle]);
  }

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
  void* scene_ = nullptr;        // RTCScene: Embree stays out of this header
  struct alignas(64) Triangle {  // one cache line
    glm::vec3 v0, e1, e2;        // a corner and the edges from it
    float area2 = 0.0f;          // |e1 x e2|
    // Across edge k (the edge opposite corner k): the triangle sharing it, or
    // kNoTriangle (a border, or an edge shared by more than two triangles).
    std::array<std::uint32_t, 3> across{kNoTriangle, kNoTriangle, kNoTriangle};
  };
  std::vector<Triangle> triangles_;
  std::array<glm::vec3, 8> whole_{};
  std::vector<std::array<glm::vec3, 8>> pieces_;
};

}  // namespace lumar
