#pragma once
// Per frame: which precomputed shadow lines (shadow_lines.h) the virtual objects block,
// and the attenuation E_with / E_without of every receiver. The occluders are the
// objects' own meshes, posed as Embree instances (moving one refits only the top level).
// Before any ray is traced, a hierarchy over the lines (receiver-cluster tree x emitter
// tree, Gibson et al. 2003's shafts, here cones around the segment joining two bounding
// spheres) rejects whole groups of lines whose shaft misses every object's bounding
// sphere; the surviving lines are walked (3D-DDA, model space) through a coarse voxel
// grid of the mesh: a line that meets no voxel the surface touches is unblocked, one
// that crosses a voxel inside the closed surface is blocked, and only the rest are
// traced, in batches (coherent rays).
// Nothing moved since the last update: no work.
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/core/mesh.h"
#include "lumar/core/ray_scene.h"
#include "lumar/core/shadow_lines.h"

namespace lumar {

struct ShadowFrameStats {
  bool recomputed = false;
  std::size_t shafts_tested = 0;  // (receiver node, emitter node) pairs tested
  std::size_t lines_tested = 0;   // lines in groups that survived the shafts
  std::size_t rays_traced = 0;    // lines that also met a surface voxel of an object (and no interior one)
  std::size_t lines_inside = 0;   // lines blocked by an interior voxel, without tracing
  std::size_t lines_blocked = 0;
  double cull_ms = 0, trace_ms = 0;  // wall time of the culling and of the ray tracing
};

// Whether the cone-capped shaft joining sphere (a, ra) to sphere (b, rb) -- the union of
// all segments from a point of one to a point of the other lies inside it -- comes within
// `ro` of the point o.
bool shaft_touches_sphere(const glm::vec3& a, float ra, const glm::vec3& b, float rb, const glm::vec3& o, float ro);

class LineShadows {
 public:
  explicit LineShadows(ShadowLines lines);
  LineShadows(const LineShadows&) = delete;
  LineShadows& operator=(const LineShadows&) = delete;

  // An occluder: a model-space mesh and its pose. Returns its id.
  int add_object(const Mesh& model, const glm::dmat4& T_world_model);
  void set_object_pose(int id, const glm::dmat4& T_world_model);
  // Off: every line is traced against the meshes (the brute-force baseline).
  void set_culling(bool on);

  // Recomputes the attenuation if an object moved (or was added) since the last call;
  // returns whether it did.
  bool update();
  // Per receiver, E_with / E_without per channel, in [0, 1].
  const std::vector<glm::vec3>& attenuation() const { return attenuation_; }
  const ShadowFrameStats& stats() const { return stats_; }
  const ShadowLines& lines() const { return lines_; }

  // A node of the sphere tree built around an occluder's triangles.
  struct Sphere {
    glm::vec3 centre{0.0f};
    float radius = 0.0f;
    std::int32_t child[2] = {-1, -1};  // sphere tree over pieces of the mesh
  };
  // A voxel of an occluder's grid (model space): what a line through it may meet.
  enum Voxel : std::uint8_t { kEmpty = 0, kSurface = 1, kInside = 2 };

 private:
  struct Object {
    int instance = -1;
    glm::dmat4 T_world_model{1.0};
    Sphere bound;                                // world sphere around the whole mesh
    glm::vec3 model_min{0.0f}, model_max{0.0f};  // the mesh's box, model space
    glm::mat4 T_model_world{1.0f};
    std::vector<Sphere> model_parts, parts;      // sphere tree around pieces of the mesh (root first): model / world
    glm::ivec3 cells{0};                         // voxel grid over [model_min, model_max]
    glm::vec3 cell_size{1.0f};
    std::vector<std::uint8_t> voxels;            // Voxel, x fastest
    std::vector<std::uint8_t> clearance;         // per voxel: Chebyshev distance (voxels) to a non-empty one
    std::vector<glm::vec3> sample_model;         // per line end sample, this frame: model-space point (distant: offset)
  };
  void place(Object& o, const glm::dmat4& T_world_model);
  bool shaft_hits(const ShadowTreeNode& receivers, const ShadowTreeNode& emitters) const;
  // kEmpty: misses the mesh; kInside: certainly blocked; kSurface: must be traced.
  Voxel classify_line(const Object& o, const glm::vec3& p, const glm::vec3& q, float t_far) const;

  ShadowLines lines_;
  RayScene occluders_;
  std::vector<Object> objects_;
  bool culling_ = true, dirty_ = true;
  std::vector<glm::vec3> attenuation_;
  ShadowFrameStats stats_;
  // Scratch, kept between frames to avoid allocations.
  std::vector<Ray> rays_;
  std::vector<std::uint32_t> ray_lines_;
  std::vector<std::uint8_t> blocked_;
  std::vector<std::uint32_t> inside_lines_;
  std::vector<std::uint8_t> ray_state_;  // per line, Voxel; kEmpty between updates
  std::vector<std::pair<std::int32_t, std::int32_t>> stack_;
};

}  // namespace lumar
