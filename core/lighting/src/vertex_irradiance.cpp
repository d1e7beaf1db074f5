#include "lumar/lighting/vertex_irradiance.h"

#include <tbb/parallel_for.h>

#include <string>

#include "lumar/base/error.h"

namespace lumar {

std::vector<glm::vec3> vertex_irradiance(const Mesh& model, const glm::dmat4& T_world_model,
                                         std::span<const VertexOcclusion> occlusion,
                                         std::span<const float> lights_blocked, const IrradianceVolume& volume) {
  const std::size_t n = model.positions.size();
  if (!occlusion.empty() && occlusion.size() != n)
    throw InputError("vertex irradiance: " + std::to_string(occlusion.size()) + " occlusion values for " +
                     std::to_string(n) + " vertices");
  if (!lights_blocked.empty() && lights_blocked.size() != n)
    throw InputError("vertex irradiance: " + std::to_string(lights_blocked.size()) + " light self-shadow values for " +
                     std::to_string(n) + " vertices");
  if (model.normals.size() != n) throw InputError("vertex irradiance: the mesh needs one normal per vertex");
  // As the shaded-object shader does: normals by the inverse transpose, bent normals too.
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(T_world_model)));
  std::vector<glm::vec3> out(n, glm::vec3(0.0f));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const glm::dvec3 p = glm::dvec3(T_world_model * glm::dvec4(glm::dvec3(model.positions[i]), 1.0));
      const glm::dvec3 normal = normal_matrix * glm::dvec3(model.normals[i]);
      glm::dvec3 bent = normal;
      double open = 1.0;
      if (!occlusion.empty() && glm::dot(occlusion[i].bent_normal, occlusion[i].bent_normal) > 1e-12f) {
        bent = normal_matrix * glm::dvec3(occlusion[i].bent_normal);
        open = glm::clamp(double(occlusion[i].open), 0.0, 1.0);
      }
      const double lights = lights_blocked.empty() ? 1.0 : 1.0 - glm::clamp(double(lights_blocked[i]), 0.0, 1.0);
      // No normal: no light, as the shader's normalize would give nothing useful.
      if (!(glm::length(normal) > 0.0) || !(glm::length(bent) > 0.0)) continue;
      out[i] = glm::vec3(volume.evaluate(p, bent, normal, open, lights));
    }
  });
  return out;
}

}  // namespace lumar
