#pragma once
// Per frame: which precomputed shadow lines (shadow_lines.h) the virtual objects block,
// and the attenuation E_with / E_without of every receiver. The occluders are the
// objects' own meshes. Before any ray is traced, the lines are culled pencil by pencil:
// for each emitter sample point, the shadow cones (shadow_cone.h) of boxes around pieces
// of each object's mesh are intersected with the receiver grids' planes
// (shadow_receiver_grid.h) and scanned row by row: only the receivers in a footprint are
// looked at (and tested against the cone); every other line costs nothing. Only the
// candidates are tested, in the object's model space: a line the object blocked at the
// last update first walks over the mesh from the triangle that blocked it then (a few
// steps, OccluderMesh::blocked_near); the rest are traced against its own BVH (built
// once). Exact: a blocked line is always a candidate, and a walk only proves what Embree
// would find. Nothing moved since the last update: no work.
#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "lumar/lighting/shadows/shadow_cone.h"
#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/scene/mesh.h"

namespace lumar {

class OccluderMesh;

struct ShadowFrameStats {
  bool recomputed = false;
  std::size_t rows_scanned = 0;      // grid rows a cone's footprint was scanned along
  std::size_t receivers_tested = 0;  // receivers in a footprint, tested against the cone
  std::size_t rays_traced = 0;       // candidate lines traced (culling off: every line)
  std::size_t lines_blocked = 0;
  std::size_t lines_walked = 0;      // blocked lines proven by a walk from last frame's blocker, without Embree
  double cull_ms = 0, trace_ms = 0;  // CPU time (calling thread) of the culling and of the ray tracing
};

class LineShadows {
 public:
  explicit LineShadows(ShadowLines lines);
  ~LineShadows();
  LineShadows(const LineShadows&) = delete;
  LineShadows& operator=(const LineShadows&) = delete;

  // An occluder: a model-space mesh and its pose (a similarity transform). Returns its id.
  int add_object(const Mesh& model, const glm::dmat4& T_world_model);
  void set_object_pose(int id, const glm::dmat4& T_world_model);
  // Off: every line is traced against the meshes (one coherent ray stream per object,
  // rtcOccluded1M): the brute-force baseline.
  void set_culling(bool on);

  // Recomputes the attenuation if an object moved (or was added) since the last call;
  // returns whether it did.
  bool update();
  // The room's light changed: each emitter sample's light is `sample_scale` (RGB, one per
  // lines().samples) times what it was when the lines were built. Each receiver's
  // E_without and its lines' shares follow (the dropped share scaling as the rest), and
  // the attenuation is recomputed at once for the lines blocked now. No tracing.
  void relight(const std::vector<glm::vec3>& sample_scale);

  // Per receiver, E_with / E_without per channel, in [0, 1]. (lines() keeps the shares
  // as built; after relight, lines().unshadowed is the relit E_without.)
  const std::vector<glm::vec3>& attenuation() const { return attenuation_; }
  const ShadowFrameStats& stats() const { return stats_; }
  const ShadowLines& lines() const { return lines_; }
  // The lines (indices into lines().lines) the last update found blocked, ascending when
  // culling is off; with culling on, the lines it traced (the candidates; off: empty,
  // meaning every line).
  const std::vector<std::uint32_t>& blocked_lines() const { return blocked_lines_; }
  const std::vector<std::uint32_t>& traced_lines() const { return traced_lines_; }

 private:
  struct Object {
    glm::dmat4 T_world_model{1.0};
    glm::mat4 T_model_world{1.0f};
    std::shared_ptr<const OccluderMesh> mesh;     // null: no triangles, casts no shadow
    std::vector<std::array<glm::vec3, 8>> parts;  // its pieces' boxes in world space, this pose
    // This frame, model space: every receiver's ray origin, every sample's line end
    // (distant: the line's direction and length).
    std::vector<glm::vec3> origin_model, sample_model;
    // The lines it blocked at the last update (at pose T_blocked), ascending, with a
    // triangle that blocked each: this frame, a line's first test is a walk from it.
    struct Blocked {
      std::uint32_t line, triangle;
    };
    std::vector<Blocked> blocked, next_blocked;
    glm::dmat4 T_blocked{1.0};
  };
  void place(Object& o, const glm::dmat4& T_world_model);
  void cull(const Object& o, std::uint32_t sample);
  void trace(Object& o);
  void trace_all(const Object& o);

  void sum_attenuation();

  ShadowLines lines_;
  // Relit (relight): each sample's factor k, each receiver's S; a line's share is then
  // fraction × k / S. Empty: as built. The lines themselves keep their built shares.
  std::vector<glm::vec3> sample_scale_, receiver_scale_, fraction_sum_, built_unshadowed_;
  std::vector<Object> objects_;
  bool culling_ = true, dirty_ = true;
  std::vector<glm::vec3> attenuation_;
  ShadowFrameStats stats_;
  std::vector<std::uint32_t> blocked_lines_, traced_lines_;
  // Scratch, kept between frames to avoid allocations.
  struct Candidate {
    std::uint32_t line, receiver, sample;
  };
  std::vector<Candidate> candidates_;  // this object's, by sample then grid order
  std::vector<float> ordered_u_,
      ordered_v_;  // receiver origins in grid order (ShadowLines::grids.order), in their grid's (u, v)
  // Per (sample, chunk of 64 receivers in grid order): which have a line, and the first line.
  std::size_t chunks_ = 0;
  std::vector<std::uint64_t> chunk_mask_;
  std::vector<std::uint32_t> chunk_first_;
  std::vector<std::uint64_t> hits_;        // this sample: receivers (grid order) inside a piece's cone
  std::vector<std::uint32_t> hit_chunks_;  // chunks of hits_ that are non-zero
  std::vector<std::uint8_t> all_blocked_;  // the baseline: per line
};

}  // namespace lumar
