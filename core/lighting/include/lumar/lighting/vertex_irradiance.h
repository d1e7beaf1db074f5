#pragma once
// An object's light per vertex: open share x E(bent normal) at each posed vertex, the exact
// lights unblocked by the object itself at its own normal, from
// the irradiance volume the renderer otherwise evaluates at every pixel. The cheap end of
// the objects' shading knob (docs/irradiance.md, "Shading per vertex"): the cost is per
// vertex, not per covered pixel, and an object that does not move pays it once.
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/self_occlusion.h"
#include "lumar/scene/mesh.h"

namespace lumar {

// One irradiance per vertex of `model` (mesh order) posed by T_world_model. `occlusion`:
// the object's own (bake_self_occlusion), one per vertex, or empty for open everywhere;
// it darkens the volume's probes' light, and `lights_blocked` (LightSelfShadow::blocked
// for this pose, one per vertex, or empty for none) its exact lights, at the vertex's
// own normal. Throws InputError when either has another length.
std::vector<glm::vec3> vertex_irradiance(const Mesh& model, const glm::dmat4& T_world_model,
                                         std::span<const VertexOcclusion> occlusion,
                                         std::span<const float> lights_blocked, const IrradianceVolume& volume);

}  // namespace lumar
