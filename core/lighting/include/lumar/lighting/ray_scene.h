#pragma once
// Ray queries against triangle meshes (Embree 3): a static part, such as the proxy room,
// and movable instances, such as virtual objects, whose transforms change without
// rebuilding their acceleration structure. Queries are thread-safe after commit().
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <span>

#include "lumar/scene/mesh.h"

namespace lumar {

struct Ray {
  glm::vec3 origin{0.0f};
  float t_near = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // need not be unit; t is in its units
  float t_far = 1e30f;
};

struct RayHit {
  float t = 0.0f;
  glm::vec3 normal{0.0f};  // unit geometric normal in world space, facing against the ray
  bool back_face = false;  // the ray met the triangle's back (counter-clockwise = front): it
                           // starts inside geometry. Of faces at the same distance, a back face wins.
  int instance = -1;       // -1: static geometry; otherwise the id add_instance returned
  std::uint32_t mesh = 0;  // which static mesh (add_static order) when instance == -1
  std::uint32_t triangle = 0;
};

class RayScene {
 public:
  RayScene();
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // A world-space mesh that never moves. Returns its index among static meshes.
  std::uint32_t add_static(const Mesh& world_mesh);
  // A movable copy of a model-space mesh; returns its instance id.
  int add_instance(const Mesh& model_mesh, const glm::dmat4& T_world_model);
  void set_instance_transform(int id, const glm::dmat4& T_world_model);
  // Builds what changed: call after adding meshes and after moving instances, before
  // querying. Moving an instance only refits the top level.
  void commit();

  bool empty() const;
  // Nearest hit with t in [t_near, t_far], if any.
  std::optional<RayHit> intersect(const Ray& ray) const;
  // Whether anything lies on the ray between t_near and t_far.
  bool occluded(const Ray& ray) const;
  // Occlusion for many rays at once (Embree's stream API): blocked[i] = 1 or 0.
  // `coherent`: neighbouring rays start close together and point the same way (e.g. one
  // receiver towards one emitter patch); Embree may then trace them as packets.
  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> blocked, bool coherent = false) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lumar
