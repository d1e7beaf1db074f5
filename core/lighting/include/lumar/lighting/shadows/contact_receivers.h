#pragma once
// Contact receivers: a dense patch of receivers where an object rests on a receiver
// surface. The scene's receivers lie about 5 cm apart (shadow_receivers.h), coarser than
// the gap between a foot and the floor, so interpolation between them washes out the
// contact shadow. The patch, about 1 cm apart, carries only what the coarse mesh misses:
// per vertex, its own E_with / E_without divided by the coarse receivers' value
// interpolated at that point, so drawn multiplied over the coarse shadow it leaves the
// shadow as it was wherever the coarse mesh already resolves it, and the patch has no seam.
#include <array>
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

// Where the objects (model meshes posed by T_world_model) come within `reach` of the
// receiver regions' surfaces: per region, the box around the vertices that do, widened by
// `reach`, clipped to the region. Overlapping boxes are merged, so no point is covered
// twice. A region's surface is its middle along its thinnest axis (receiver regions are
// thin slabs around a floor or table top).
std::vector<SceneBox> contact_regions(const std::vector<SceneBox>& receiver_regions,
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

  bool empty() const { return receivers.triangle_count() == 0; }
  // What to draw over the coarse shadow: patch_attenuation / the coarse attenuation
  // interpolated at each patch vertex, per channel (1 where the coarse one is ~0 or absent).
  std::vector<glm::vec3> correction(const std::vector<glm::vec3>& patch_attenuation,
                                    const std::vector<glm::vec3>& coarse_attenuation) const;
};

// The patch over `regions` (contact_regions), dropped onto `proxy` as build_receivers
// does, located in `coarse` (the scene's receiver mesh, built over the regions that
// contain these).
ContactPatch build_contact_patch(const RayScene& proxy, const Mesh& coarse, const std::vector<SceneBox>& regions,
                                 const ContactSettings& settings = {});

}  // namespace lumar
