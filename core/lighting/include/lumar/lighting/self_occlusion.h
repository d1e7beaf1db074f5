#pragma once
// An object's occlusion of itself, baked once per mesh in model space, so that it moves
// with the object: per vertex, the cosine-weighted share of the hemisphere its own mesh
// leaves open (ambient occlusion) and the mean open direction (bent normal). The
// renderer shades a vertex with open × E(bent normal) from the irradiance volume, which
// knows the room but not the object (docs/ground_truth.md, "What closes the gap").
#include <vector>

#include "lumar/scene/mesh.h"

namespace lumar {

struct VertexOcclusion {
  glm::vec3 bent_normal{0.0f, 0.0f, 1.0f};  // unit, model space
  float open = 1.0f;                        // cosine-weighted open share, [0, 1]
};

struct SelfOcclusionSettings {
  int strata = 16;  // strata² cosine-weighted rays per vertex
  // Where a ray starts: this share of the mesh's bounding-box diagonal along the normal,
  // so that it does not meet the triangles around its own vertex.
  double offset = 1e-4;
};

class RayScene;

// One value per vertex (mesh order); the mesh needs one normal per vertex (InputError
// otherwise). A mesh without triangles is open everywhere. Deterministic for a mesh.
std::vector<VertexOcclusion> bake_self_occlusion(const Mesh& model, const SelfOcclusionSettings& settings = {});
// The same against a ray scene already built of `model` alone, in model space (as
// LightSelfShadow's), so that one mesh is not built into two.
std::vector<VertexOcclusion> bake_self_occlusion(const Mesh& model, const RayScene& model_scene,
                                                 const SelfOcclusionSettings& settings = {});

}  // namespace lumar
