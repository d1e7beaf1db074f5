#pragma once
// Ground truth for a composite (docs/ground_truth.md): the light of the real room with
// the virtual objects physically in it, by brute force with Embree.
//  - On an object: albedo/π × E with full visibility: objects occlude themselves and
//    each other. A ray that meets the same object brings nothing; one that meets another
//    brings that object's radiance (one bounce, with `bounce`, as onto the room; else
//    nothing). Bright texels are summed exactly, each with a visibility ray past proxy
//    and objects.
//  - On the room: the empty room's radiance × (E_with + E_bounce) / E_without, where
//    E_with − E_without is what the objects block and E_bounce what they reflect onto
//    the room (one bounce, from their own E per vertex). Both are sampled within the cone
//    of each object's bounding sphere, or over the hemisphere where the point lies inside
//    that sphere (under the object), so that a small object is never missed by rays.
// The radiance the room sends is `RoomRadiance`'s: the map projected on the proxy.
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "lumar/lighting/irradiance_reference.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/room_radiance.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar {

struct CompositeReferenceSettings {
  int object_strata = 16;  // strata² cosine-weighted rays per object point
  int vertex_strata = 16;  // the same per object vertex (what objects reflect, and their pixels)
  int room_strata = 12;    // strata² rays for the empty room's E at a room point
  int cone_strata = 8;     // strata² rays into each object's cone per room point
  double reach = 10.0;     // a room point farther than reach × radius from an object ignores it
  bool bounce = true;      // add the light objects reflect onto the room and onto each other
};

// The room's radiance the truth is lit by (`lumar synth --truth`): the reference's, from
// a map of 128 rows, so that its bright texels stay few enough to sum exactly.
RadianceSettings truth_radiance_settings();

struct ObjectHit {
  int object = -1;
  double t = 0.0;           // along the ray, in the direction's units
  glm::dvec3 point{0.0};    // world
  glm::dvec3 normal{0.0};   // shading normal (vertex normals interpolated), unit
  glm::dvec3 facing{0.0};   // geometric normal turned towards the ray's origin
  glm::dvec3 weights{0.0};  // barycentric weights of the triangle's vertices
  std::uint32_t triangle = 0;
};

class CompositeReference {
 public:
  // `objects` placed by their T_world_model; `room` must outlive this.
  CompositeReference(const RoomRadiance& room, std::span<const LoadedObject> objects,
                     const CompositeReferenceSettings& settings = {});
  ~CompositeReference();
  CompositeReference(const CompositeReference&) = delete;
  CompositeReference& operator=(const CompositeReference&) = delete;

  const CompositeReferenceSettings& settings() const { return settings_; }
  const RoomRadiance& room() const { return room_; }
  std::size_t object_count() const { return objects_.size(); }

  // The nearest object along the ray up to t_far.
  std::optional<ObjectHit> hit_object(const glm::dvec3& origin, const glm::dvec3& direction,
                                      double t_far = std::numeric_limits<double>::infinity()) const;
  // E at p (normal n) with every object in place, blocking and reflecting nothing.
  // `strata` 0: settings().object_strata.
  glm::dvec3 irradiance_with_objects(const glm::dvec3& p, const glm::dvec3& n, int strata = 0) const;
  // The radiance an object's surface sends towards a viewer at a hit: albedo/π × E at
  // the hit (the pixel's own integral when `per_point`, with the other objects' bounce;
  // else its vertices' E interpolated, which has none: the one bounce's source).
  glm::dvec3 object_radiance(const ObjectHit& hit, bool per_point = true) const;
  // (E_with + E_bounce) / E_without per channel at a room point p with normal n;
  // exactly 1 where every object is out of reach.
  glm::dvec3 room_ratio(const glm::dvec3& p, const glm::dvec3& n) const;

 private:
  struct Object {
    Mesh world;
    glm::dvec3 albedo{0.8};
    glm::dvec3 centre{0.0};
    double radius = 0.0;
    std::vector<glm::dvec3> vertex_irradiance;  // with settings_.bounce
  };
  // Whether an object lies on the segment p + t·w, t in (0, t_far).
  bool blocked(const glm::dvec3& p, const glm::dvec3& w, double t_far) const;
  // `blocked` in the form reference_irradiance takes: black objects.
  ExtraOccluder objects_as_occluder() const;
  // Objects that send back their one-bounce radiance (object_radiance per vertex), but
  // object `self`, black: a point's light from the others.
  ExtraOccluder objects_reflecting_onto(int self) const;

  const RoomRadiance& room_;
  CompositeReferenceSettings settings_;
  std::vector<Object> objects_;
  std::unique_ptr<RayScene> rays_;  // the objects, one static mesh each, in world space
};

}  // namespace lumar
