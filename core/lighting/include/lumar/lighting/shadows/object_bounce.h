#pragma once
// The light virtual objects reflect onto the real receivers (one bounce): differential
// rendering adds it as well as removing what the objects block, so a red box tints the
// white floor beside it (docs/shadows.md, "Bounce").
//
// Each object's surface is cut into `clusters` clusters of about equal area (median cuts
// of its triangles by position and normal, once, in model space). Per
// frame, after a move, a cluster's radiance is albedo/π × open × E(bent normal): E from
// the irradiance volume (or SH9) that shades the object, open and the bent normal from
// its baked self-occlusion, averaged over the cluster. A receiver x with normal n gets
//   from a far cluster:  L · open · A cos θ_c cos θ_x / r²   (a point at its centre),
//   from a near one (r < 3 × the cluster's radius): the same over its 8 children, and
//   from a child that is near in turn, over its triangles, each a point too unless
//   near: then L · open · π F_t, F_t the exact form factor of the triangle clipped to
//   x's horizon (Lambert's contour integral). So the light under an object resting on
//   the floor does not depend on how coarse the clusters are.
// Visibility is the facing of clusters and triangles, exact for a convex object; on a
// concave one a cluster's open share stands in for the part of its outgoing light the
// object itself stops. The proxy and the other objects are not in the way (the
// receivers lie beside the object). Receivers farther than `reach` bounding radii get
// nothing: a sphere on the floor sends (R/d)³ of what it blocks, 0.2 % at 8 radii.
//
// The result is E_bounce / E_without per receiver and channel, added to the shadow's
// E_with / E_without (shadow_occlusion.h): values above 1 are light the room did not have.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "lumar/lighting/self_occlusion.h"
#include "lumar/lighting/sh.h"
#include "lumar/scene/mesh.h"

namespace lumar {

class IrradianceVolume;

struct BounceSettings {
  int clusters = 128;       // surface clusters per object: the quality knob (bench_bounce)
  double near_radii = 3.0;  // a cluster nearer than this many of its radii is summed by triangles
  double reach = 8.0;       // in bounding radii of the object
};

// A patch of a mesh: a run of its triangles in SurfaceClusters::order.
struct SurfaceCluster {
  std::uint32_t first = 0, count = 0;              // in SurfaceClusters::order
  float area = 0;                                  // model units²
  glm::vec3 centre{0.0f};                          // area-weighted centre of its triangles
  glm::vec3 normal{0.0f};                          // area-weighted mean of the vertex normals, unit
  float radius = 0;                                // from the centre to its farthest vertex
  std::uint32_t first_child = 0, child_count = 0;  // its patches in SurfaceClusters::children
};

struct SurfaceClusters {
  std::vector<std::uint32_t> order;      // triangle indices, cluster after cluster
  std::vector<SurfaceCluster> clusters;  // in order of their first triangle
  std::vector<SurfaceCluster> children;  // each cluster cut again, the same way
};

// A mesh's (one normal per vertex) triangles cut into `count` clusters of about equal
// area (fewer when it has fewer triangles), and each of them into about `children`
// smaller ones: the largest run is split along the widest of its triangles' centre
// coordinates and normal components (normals scaled to a quarter of the mesh's size),
// where it halves the area or, better, at a clear gap, so that a box's faces part
// before they are halved. Deterministic.
SurfaceClusters surface_clusters(const Mesh& mesh, int count, int children = 8);

struct BounceStats {
  bool recomputed = false;
  std::size_t receivers_reached = 0;  // receivers within reach of at least one object
  std::size_t pairs = 0;              // (receiver or vertex, cluster) pairs summed as points
  std::size_t near_pairs = 0;         // (receiver or vertex, cluster) pairs summed triangle by triangle
  double ms = 0;                      // wall time of the update
  double onto_objects_ms = 0;         // of which onto each other's vertices
};

class ObjectBounce {
 public:
  // The receivers: ray positions on the proxy, unit normals, and their unshadowed
  // irradiance E_without (RGB). InputError when the three differ in count.
  ObjectBounce(std::vector<glm::vec3> positions, std::vector<glm::vec3> normals, std::vector<glm::vec3> unshadowed,
               const BounceSettings& settings = {});

  // A model-space mesh (one normal per vertex), its albedo and pose (a similarity
  // transform). Returns its id. An object without triangles reflects nothing.
  int add_object(const Mesh& model, const glm::vec3& albedo, const glm::dmat4& T_world_model);
  // RuntimeError for an id add_object did not return.
  void set_object_pose(int id, const glm::dmat4& T_world_model);
  // The mesh's baked self-occlusion (one per vertex), or empty: open everywhere, the
  // vertex normal as the bent normal. InputError for a count that is not the mesh's.
  void set_object_occlusion(int id, std::span<const VertexOcclusion> occlusion);
  // Whether the object reflects onto the receivers (the manifest's "bounce").
  void set_object_enabled(int id, bool on);
  void set_object_albedo(int id, const glm::vec3& albedo);

  // Irradiance at a world point with a unit normal: what shades the objects.
  using Irradiance = std::function<glm::vec3(const glm::vec3& position, const glm::vec3& normal)>;
  // Recomputes if an object moved, was added or changed since the last call; returns
  // whether it did.
  bool update(const Irradiance& irradiance);
  // The light on the objects changed (the room was relit), and with it the receivers'
  // unshadowed irradiance (one per receiver): the next update recomputes.
  void relight(std::vector<glm::vec3> unshadowed);

  // Per receiver, E_bounce / E_without per channel (0 where nothing reaches it). E_without
  // is taken as at least kDarkReceiverShare of the receivers' median: below that it is
  // mostly the lines' own error (a point under a table block is reached only through
  // ties that Embree's kernels break differently on different CPUs), which the ratio would
  // amplify into a bright blot that the floor's interpolation spreads beyond the table.
  const std::vector<glm::vec3>& ratio() const { return ratio_; }
  static constexpr float kDarkReceiverShare = 0.1f;
  // Per vertex of object id's mesh (model order): the irradiance the OTHER objects
  // reflect onto it (virtual onto virtual: a red box tints the figurine beside it), by
  // the same transfer as onto the receivers; all 0 with one object. RuntimeError for a
  // bad id.
  const std::vector<glm::vec3>& object_bounce(int id) const;
  const BounceStats& stats() const { return stats_; }
  std::size_t receiver_count() const { return positions_.size(); }
  const BounceSettings& settings() const { return settings_; }

 private:
  struct Object {
    Mesh model;
    glm::vec3 albedo{0.8f};
    glm::dmat4 T_world_model{1.0};
    SurfaceClusters surface;
    glm::vec3 middle{0.0f};  // of the model's bounding box
    float radius = 0;        // half its diagonal
    bool enabled = true;
    // Model space, once: per cluster the area-weighted bent normal (unit) and open share
    // of its vertices (self-occlusion, or the normals and 1); per triangle its centre,
    // area, facing (mean vertex normal, unit) and radius.
    std::vector<glm::vec3> cluster_bent;
    std::vector<float> cluster_open;
    std::vector<glm::vec3> triangle_centre, triangle_facing;
    std::vector<float> triangle_area, triangle_radius;
    std::vector<glm::vec3> received;  // per vertex: what the other objects reflect onto it
    // Per cluster, in its current pose: albedo/π × open × E(bent normal) × open, the
    // radiance that leaves past the object (light_clusters).
    std::vector<glm::vec3> cluster_radiance;
  };
  static void shade_clusters(Object& o, std::span<const VertexOcclusion> occlusion);
  static void light_clusters(Object& o, const Irradiance& irradiance);
  // Adds what `o` reflects onto the points (world, unit normals) into `out`.
  void add_object_bounce(const Object& o, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                         std::span<glm::vec3> out);

  // E_without's floor per channel in ratio(): kDarkReceiverShare of the median.
  static glm::vec3 dark_floor(const std::vector<glm::vec3>& unshadowed);

  std::vector<glm::vec3> positions_, normals_, unshadowed_;
  glm::vec3 dark_floor_{0.0f};
  BounceSettings settings_;
  std::vector<Object> objects_;
  std::vector<glm::vec3> bounce_, ratio_;
  bool dirty_ = true;
  BounceStats stats_;
};

// What shades the objects, on the CPU: the irradiance volume when there is one (the
// scene's lighting.method is not "sh9"), else the map's SH9.
ObjectBounce::Irradiance object_irradiance(const IrradianceVolume* volume, const SH9& sh);

// The shadow's E_with / E_without per receiver plus the bounce's E_bounce / E_without.
std::vector<glm::vec3> with_bounce(std::vector<glm::vec3> attenuation, const ObjectBounce& bounce);

}  // namespace lumar
