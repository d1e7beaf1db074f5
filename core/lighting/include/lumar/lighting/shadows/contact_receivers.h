#pragma once
// Contact receivers: a dense patch of receivers where an object rests on a receiver
// surface. The scene's receivers lie about 5 cm apart (shadow_receivers.h), coarser than
// the gap between a foot and the floor, so interpolation between them washes out the
// contact shadow. The patch, about 1 cm apart, carries only what the coarse mesh misses:
// per vertex, its own E_with / E_without divided by the coarse receivers' value
// interpolated at that point, so drawn multiplied over the coarse shadow it leaves the
// shadow as it was wherever the coarse mesh already resolves it, and the patch has no seam.
// An object that slides or turns along the surface it stands on carries its part of the
// patch, and the shadow on it, with it (ContactPatch::carried): no lines are traced again.
#include <array>
#include <span>
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/mesh.h"
#include "lumar/scene/scene.h"

namespace lumar {

struct ContactSettings {
  double reach = 0.05;      // metres: an object's vertices this near a receiver surface touch it
  double spacing = 0.01;    // metres between the patch's receivers
  int max_vertices = 4096;  // per scene; beyond it the spacing grows
};

// Where one object touches a receiver surface; `object` indexes the models given to
// contact_regions, or is -1 where the boxes of two or more objects overlapped and were merged.
struct ContactRegion {
  SceneBox box;
  int object = -1;
};

// Where the objects (model meshes posed by T_world_model) come within `reach` of the
// receiver regions' surfaces: per region, the box around the vertices that do, widened by
// `reach`, clipped to the region. Overlapping boxes are merged, so no point is covered
// twice. A region's surface is its middle along its thinnest axis (receiver regions are
// thin slabs around a floor or table top).
std::vector<ContactRegion> contact_regions(const std::vector<SceneBox>& receiver_regions,
                                           const std::vector<const Mesh*>& models,
                                           const std::vector<glm::dmat4>& T_world_model, double reach);

// A patch of receivers and where each of its vertices lies in the coarse receiver mesh.
struct ContactPatch {
  Mesh receivers;
  // Per patch vertex: the coarse triangle's corners it lies in and its barycentric
  // weights; weights all 0 where no coarse triangle holds it (the coarse mesh draws
  // nothing there).
  std::vector<std::array<std::uint32_t, 3>> coarse_corners;
  std::vector<glm::vec3> coarse_weights;
  // Per patch vertex: the object whose contact it is (ContactRegion::object).
  std::vector<int> owner;

  bool empty() const { return receivers.triangle_count() == 0; }
  // What to draw over the coarse shadow: patch_attenuation / the coarse attenuation
  // interpolated at each patch vertex, per channel (1 where the coarse one is ~0 or absent).
  std::vector<glm::vec3> correction(const std::vector<glm::vec3>& patch_attenuation,
                                    const std::vector<glm::vec3>& coarse_attenuation) const;
  // The patch carried with the objects that moved since it was built, and located in
  // `coarse` where it lies now: `moved[k]` takes object k from the pose it was built at to
  // its pose now. A vertex goes with its object when that keeps it on its surface (the
  // object slid or turned along it: its normal turned by under `max_turn_rad`, and it
  // left the surface's plane by under `tolerance` metres); else the triangles that use it
  // are dropped, as are those of merged regions (owner -1) once any object moved.
  // Vertices keep their order: the attenuation the patch's lines give where it was built
  // is its attenuation carried (`correction` of it against the coarse shadow now).
  ContactPatch carried(std::span<const glm::dmat4> moved, const Mesh& coarse, double tolerance = 1e-3,
                       double max_turn_rad = 0.01) const;
};

// The correction a carried patch draws, per vertex: where the patch corrected the coarse
// shadow strongly when it was built (at the contact, a shadow the coarse mesh cannot
// hold, and which moves with the object), `now`, its own attenuation carried against the
// coarse shadow where it lies now (ContactPatch::correction of the carried patch); where
// its correction was near 1 (the coarse mesh held the shadow there, and holds it where
// the object is now), `built`, that correction. Blended by |1 - built| / `width` (green).
// The width is measured in docs/shadows.md ("Carried with the object").
std::vector<glm::vec3> carried_correction(const std::vector<glm::vec3>& now, const std::vector<glm::vec3>& built,
                                          float width = 0.1f);

// The patch over `regions` (contact_regions), dropped onto `proxy` as build_receivers
// does, located in `coarse` (the scene's receiver mesh, built over the regions that
// contain these).
ContactPatch build_contact_patch(const RayScene& proxy, const Mesh& coarse, const std::vector<ContactRegion>& regions,
                                 const ContactSettings& settings = {});

}  // namespace lumar
