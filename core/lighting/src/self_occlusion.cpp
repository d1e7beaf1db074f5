#include "lumar/lighting/self_occlusion.h"

#include <tbb/parallel_for.h>

#include <random>

#include "hemisphere_sampling.h"
#include "lumar/base/error.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar {

std::vector<VertexOcclusion> bake_self_occlusion(const Mesh& model, const SelfOcclusionSettings& settings) {
  RayScene scene;
  if (model.triangle_count() > 0) scene.add_static(model);
  scene.commit();
  return bake_self_occlusion(model, scene, settings);
}

std::vector<VertexOcclusion> bake_self_occlusion(const Mesh& model, const RayScene& scene,
                                                 const SelfOcclusionSettings& settings) {
  if (model.normals.size() != model.positions.size())
    throw InputError("bake_self_occlusion: the mesh needs one normal per vertex; load it with load_mesh");
  if (settings.strata < 1) throw InputError("bake_self_occlusion: strata must be at least 1");
  const std::size_t n = model.positions.size();
  std::vector<VertexOcclusion> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i].bent_normal = model.normals[i];
  if (model.triangle_count() == 0) return out;
  const auto [lo, hi] = model.bounds();
  const float offset = float(settings.offset * glm::length(glm::dvec3(hi) - glm::dvec3(lo)));
  const int s = settings.strata, count = s * s;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Ray> rays(static_cast<std::size_t>(count));
    std::vector<std::uint8_t> blocked(rays.size());
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const glm::dvec3 normal(model.normals[i]);
      if (!(glm::length(normal) > 0.5)) continue;  // a degenerate normal: leave it open
      const glm::dvec3 nn = glm::normalize(normal);
      glm::dvec3 t, b;
      orthonormal_basis(nn, t, b);
      // Seeded by the vertex, so the bake is the same in any order on any thread.
      std::mt19937 rng(query_seed(glm::dvec3(model.positions[i]), nn));
      std::uniform_real_distribution<double> jitter(0.0, 1.0);
      const glm::vec3 origin = model.positions[i] + glm::vec3(nn) * offset;
      for (int k = 0; k < count; ++k) {
        const double u1 = (k / s + jitter(rng)) / s, u2 = (k % s + jitter(rng)) / s;
        Ray& ray = rays[std::size_t(k)];
        ray.origin = origin;
        ray.direction = glm::vec3(cosine_direction(nn, t, b, u1, u2));
      }
      scene.occluded(rays, blocked);
      glm::dvec3 sum(0.0);
      int open = 0;
      for (int k = 0; k < count; ++k)
        if (!blocked[std::size_t(k)]) sum += glm::dvec3(rays[std::size_t(k)].direction), ++open;
      out[i].open = float(open) / float(count);
      if (open > 0) out[i].bent_normal = glm::vec3(glm::normalize(sum));
    }
  });
  return out;
}

}  // namespace lumar
