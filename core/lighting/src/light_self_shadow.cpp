#include "lumar/lighting/light_self_shadow.h"

#include <tbb/parallel_for.h>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/self_occlusion.h"

namespace lumar {

LightSelfShadow::LightSelfShadow(const Mesh& model) : model_(model), scene_(std::make_unique<RayScene>()) {
  if (model.normals.size() != model.positions.size())
    throw InputError("LightSelfShadow: the mesh needs one normal per vertex; load it with load_mesh");
  scene_->add_static(model_);
  scene_->commit();
  // Where the self-occlusion bake starts its rays.
  const auto [lo, hi] = model_.bounds();
  offset_ = float(SelfOcclusionSettings{}.offset * glm::length(glm::dvec3(hi) - glm::dvec3(lo)));
}

LightSelfShadow::~LightSelfShadow() = default;
LightSelfShadow::LightSelfShadow(LightSelfShadow&&) noexcept = default;
LightSelfShadow& LightSelfShadow::operator=(LightSelfShadow&&) noexcept = default;

std::vector<float> LightSelfShadow::blocked(const glm::dmat4& T_world_model, std::span<const VolumeLight> lights,
                                            const glm::dvec3& capture) const {
  const std::size_t n = model_.positions.size();
  std::vector<float> out(n, 0.0f);
  if (lights.empty() || scene_->empty()) return out;
  const glm::dmat3 linear(T_world_model);
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const glm::dmat3 to_model = glm::inverse(linear);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Ray> rays;
    std::vector<double> weight;
    std::vector<std::uint8_t> hit;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const glm::dvec3 n_model(model_.normals[i]);
      const glm::dvec3 n_world = normal_matrix * n_model;
      if (!(glm::length(n_model) > 0.5) || !(glm::length(n_world) > 0.0)) continue;
      const glm::dvec3 p = glm::dvec3(T_world_model * glm::dvec4(glm::dvec3(model_.positions[i]), 1.0));
      const glm::dvec3 nw = glm::normalize(n_world);
      const glm::vec3 origin = model_.positions[i] + glm::vec3(glm::normalize(n_model)) * offset_;
      rays.clear(), weight.clear();
      for (const VolumeLight& l : lights) {
        glm::dvec3 toward;
        const double e = luminance(light_irradiance(l, capture, p, nw, &toward));
        if (!(e > 0.0)) continue;
        rays.push_back(Ray{origin, 0.0f, glm::vec3(to_model * toward), 1e30f});
        weight.push_back(e);
      }
      if (rays.empty()) continue;
      hit.assign(rays.size(), 0);
      scene_->occluded(rays, hit);
      double total = 0, blocked = 0;
      for (std::size_t k = 0; k < rays.size(); ++k) total += weight[k], blocked += hit[k] ? weight[k] : 0.0;
      out[i] = float(blocked / total);
    }
  });
  return out;
}

}  // namespace lumar
