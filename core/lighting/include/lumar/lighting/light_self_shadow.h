#pragma once
// An object's shadow on itself from the irradiance volume's exact lights (the sun, a
// lamp), for its current pose: per vertex, the share of those lights' irradiance that the
// object's own mesh blocks, ray traced against it towards points spread over each light.
// The rest of the room's light is darkened by the baked open share (self_occlusion.h),
// which knows no direction: applied to a sun too, it darkens the sunlit side as much as
// the side turned away (docs/ground_truth.md, "Under a sun").
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <vector>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/scene/mesh.h"

namespace lumar {

class RayScene;

struct LightSelfShadowSettings {
  // Rays per vertex and light, towards points spread over the light (a disk on the proxy
  // the size of its texels, or a cone of its solid angle): what the light's edge and a
  // coarse mesh's shadow terminator let through comes out as a share, not all or nothing.
  // Six on its rim go first; only where they disagree are the others cast. 1: the
  // light's centre only. From 1 to kMaxSamples.
  int samples = 16;
  static constexpr int kMaxSamples = 64;
};

class LightSelfShadow {
 public:
  // The model-space mesh (one normal per vertex; InputError otherwise), traced in model
  // space so that the ray scene is built once whatever the pose.
  explicit LightSelfShadow(const Mesh& model, const LightSelfShadowSettings& settings = {});
  ~LightSelfShadow();
  LightSelfShadow(LightSelfShadow&&) noexcept;
  LightSelfShadow& operator=(LightSelfShadow&&) noexcept;

  // Per vertex (mesh order), posed by T_world_model (a similarity): Σ blocked E_l / Σ E_l
  // over the lights, E_l the irradiance light l gives the vertex's own normal before
  // anything blocks it (light_irradiance); 0 where no light reaches the normal's side.
  // A vertex casts settings.samples rays per light (fewer where the six on the rim agree).
  std::vector<float> blocked(const glm::dmat4& T_world_model, std::span<const VolumeLight> lights,
                             const glm::dvec3& capture) const;

  // The model's ray scene, in model space (for bake_self_occlusion).
  const RayScene& scene() const { return *scene_; }

 private:
  Mesh model_;
  LightSelfShadowSettings settings_;
  std::unique_ptr<RayScene> scene_;
  float offset_ = 0;  // model units along the normal where a ray starts
};

}  // namespace lumar
