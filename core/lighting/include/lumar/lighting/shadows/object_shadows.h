#pragma once
// Per frame: how much of the emitters' light each vertex of a virtual object loses to the
// OTHER virtual objects (object B shading object A). The overlay multiplies the
// irradiance-volume shading of A's vertices by this ratio.
//
// Per vertex (posed, normal rotated with the pose) and per emitter sample point (the line
// ends of shadow_lines.h): one line from the vertex's shadow-ray origin to the sample. The
// ratio is E_with / E_without per RGB channel, where E_without sums the samples'
// unoccluded irradiance (emitter_irradiance) and E_with drops the lines another object's
// mesh blocks (a line blocked by two objects counts once).
// No proxy-room visibility enters the ratio: the irradiance volume already carries the
// room's own shadowing; this only says what the other virtual objects take away.
//
// Cost: per ordered pair (A receiving, B occluding) and sample, the shadow cones
// (shadow_cone.h) of B's posed box and of boxes around 8 pieces of B's mesh are tested
// against A's posed bounding box, then against boxes around groups and chunks of A's
// spatially sorted vertices, then against the vertices (groups in parallel, TBB).
// Only the lines inside a cone are traced, in B's model space against B's own BVH
// (built once). Vertices with no such line keep 1 without any other work (a shadowed
// vertex's E_without is kept until its own object moves); a single object, or nothing
// moved since the last update, costs nothing. Exact for the given
// emitter samples: a blocked line is always inside the cone.
#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "lumar/lighting/shadows/shadow_cone.h"
#include "lumar/lighting/shadows/shadow_emitters.h"
#include "lumar/scene/mesh.h"

namespace lumar {

class OccluderMesh;

struct ObjectShadowStats {
  bool recomputed = false;
  std::size_t lines_tested = 0;       // (vertex, sample, occluder) tested against a cone
  std::size_t rays_traced = 0;        // candidate lines tested against a mesh (walked or traced)
  std::size_t lines_blocked = 0;      // (vertex, sample) lines blocked by at least one object
  std::size_t lines_walked = 0;       // blocked lines proven by a walk from the last update's blocker (no ray)
  std::size_t vertices_shadowed = 0;  // vertices (all objects) with attenuation below 1
  double ms = 0;                      // wall time of the update
};

class ObjectShadows {
 public:
  // The emitter sample points (Emitters::samples, Emitters::distant) are the line ends.
  explicit ObjectShadows(const Emitters& emitters);
  ~ObjectShadows();
  ObjectShadows(const ObjectShadows&) = delete;
  ObjectShadows& operator=(const ObjectShadows&) = delete;

  // A model-space mesh (one unit normal per vertex) and its pose (a similarity
  // transform). Returns its id. Throws InputError when normals and positions differ in count.
  int add_object(const Mesh& model, const glm::dmat4& T_world_model);
  // Throws RuntimeError for an id add_object did not return.
  void set_object_pose(int id, const glm::dmat4& T_world_model);

  // Recomputes if any pose changed (or an object was added) since the last call; returns
  // whether it did.
  bool update();

  // Per vertex of object id's mesh (model vertex order): E_with / E_without per channel,
  // in [0, 1]. Throws RuntimeError for a bad id.
  const std::vector<glm::vec3>& vertex_attenuation(int id) const;
  const ObjectShadowStats& stats() const { return stats_; }
  std::size_t object_count() const { return objects_.size(); }

 private:
  struct Chunk {
    std::uint32_t begin = 0, end = 0;  // range in Object::order (a group's: in Object::chunks)
    glm::vec3 lo{0.0f}, hi{0.0f};      // world box of the chunk's ray origins, this pose
  };
  struct Object {
    std::vector<glm::vec3> model_positions, model_normals;
    std::vector<std::uint32_t> order;  // vertices sorted spatially (model space), chunked
    glm::dmat4 T_world_model{1.0};
    glm::mat4 T_model_world{1.0f};
    std::shared_ptr<const OccluderMesh> mesh;  // null: no triangles, casts no shadow
    std::array<glm::vec3, 8> box{};            // its boxes in world space, this pose
    std::vector<std::array<glm::vec3, 8>> parts;
    // This pose, in `order`: world positions, normals, ray origins; chunks; box of all origins.
    std::vector<glm::vec3> position, normal, origin;
    std::vector<glm::vec3> without;  // E_without, where without_known
    std::vector<std::uint8_t> without_known;
    std::vector<Chunk> chunks, groups;
    glm::vec3 lo{0.0f}, hi{0.0f};
    std::vector<glm::vec3> attenuation;  // model vertex order
    // Per group: the lines other objects blocked at the last update, in the order shade()
    // visits them (sample, occluder, vertex), each with a triangle that blocked it; a
    // line's first test this update is a walk from it (OccluderMesh::blocked_near).
    struct Blocked {
      std::uint32_t sample, occluder, vertex, triangle;
    };
    std::vector<std::vector<Blocked>> blocked;
    // Per other object: its model space from this one's at that update (the walks pay
    // only if the lines moved little across the occluder's mesh since).
    std::vector<glm::dmat4> occluder_from_model;
  };
  void place(Object& o, const glm::dmat4& T_world_model);
  void shade(Object& a, std::size_t self);
  void build_cones();
  glm::vec3 unshadowed(const glm::vec3& x, const glm::vec3& n) const;

  std::vector<EmitterPoint> samples_;
  // The samples again as a structure of arrays (position xyz, normal xyz, flux rgb; each
  // row padded to a multiple of 4 with samples of no flux), for unshadowed()'s SIMD loop.
  std::vector<float> sample_rows_;
  std::size_t sample_stride_ = 0;
  bool distant_ = false;
  std::vector<Object> objects_;
  bool dirty_ = true;
  ObjectShadowStats stats_;
  // This frame's cones, per object and sample: the whole box's, then its pieces'.
  std::vector<std::vector<ShadowCone>> cones_;
};

}  // namespace lumar
