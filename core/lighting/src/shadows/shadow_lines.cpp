#include "lumar/lighting/shadows/shadow_lines.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "lumar/base/color.h"
#include "lumar/base/error.h"

namespace lumar {

ShadowLines build_shadow_lines(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               const Emitters& emitters, const RayScene& proxy, const ShadowLineOptions& options) {
  if (positions.size() != normals.size())
    throw InputError("build_shadow_lines: receiver positions and normals differ in count");
  ShadowLines out;
  out.distant = emitters.distant;
  out.samples = emitters.samples;
  out.patch_count = std::uint32_t(emitters.patches.size());
  const std::size_t n = positions.size();
  out.origins.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.origins[i] = shadow_ray_origin(positions[i], normals[i]);

  out.grids = build_receiver_grids(out.origins, normals);
  // Per receiver: transfer and proxy visibility of every sample, then significance.
  struct Kept {
    std::uint32_t sample;
    glm::vec3 fraction;
  };
  std::vector<std::vector<Kept>> kept(n);
  out.unshadowed.assign(n, glm::vec3(0.0f));
  out.dropped.assign(n, 0.0f);
  std::vector<std::size_t> candidates(n, 0);
  const float t_far = shadow_ray_t_far(emitters.distant);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Ray> rays;
    std::vector<std::uint8_t> blocked;
    std::vector<std::uint32_t> which;
    std::vector<glm::vec3> transfer;
    std::vector<std::pair<float, std::size_t>> order;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      rays.clear(), which.clear(), transfer.clear();
      const glm::vec3 o = out.origins[i];
      for (std::uint32_t s = 0; s < out.samples.size(); ++s) {
        const glm::vec3 e = emitter_irradiance(out.samples[s], emitters.distant, positions[i], normals[i]);
        if (!(max_channel(e) > 0)) continue;
        const glm::vec3 end = emitter_line_end(out.samples[s], emitters.distant, o);
        rays.push_back(Ray{o, 0.0f, end - o, t_far});
        which.push_back(s);
        transfer.push_back(e);
      }
      blocked.assign(rays.size(), 0);
      if (!proxy.empty()) proxy.occluded(rays, blocked);
      glm::vec3 total(0.0f);
      for (std::size_t k = 0; k < rays.size(); ++k)
        if (!blocked[k]) total += transfer[k];
      out.unshadowed[i] = total;
      const glm::vec3 inv(total.r > 0 ? 1.0f / total.r : 0.0f, total.g > 0 ? 1.0f / total.g : 0.0f,
                          total.b > 0 ? 1.0f / total.b : 0.0f);
      order.clear();
      for (std::size_t k = 0; k < rays.size(); ++k)
        if (!blocked[k]) order.push_back({max_channel(transfer[k] * inv), k});
      candidates[i] = order.size();
      // Drop the smallest lines while their summed share stays within the budget.
      std::sort(order.begin(), order.end());
      float dropped = 0;
      std::size_t start = 0;
      while (start < order.size() && dropped + order[start].first <= options.max_dropped_fraction)
        dropped += order[start++].first;
      out.dropped[i] = dropped;
      auto& mine = kept[i];
      for (std::size_t k = start; k < order.size(); ++k) {
        const std::size_t j = order[k].second;
        mine.push_back({which[j], transfer[j] * inv});
      }
      std::sort(mine.begin(), mine.end(), [](const Kept& a, const Kept& b) { return a.sample < b.sample; });
    }
  });
  out.candidate_lines = std::accumulate(candidates.begin(), candidates.end(), std::size_t(0));

  // Order the lines by sample, then by receiver in grid order; each receiver's kept
  // lines are sorted by sample, so one cursor per receiver walks them in order.
  const std::size_t samples = out.samples.size();
  std::size_t total = 0;
  for (const auto& k : kept) total += k.size();
  out.lines.reserve(total);
  out.sample_first.assign(samples + 1, 0);
  std::vector<std::size_t> cursor(n, 0);
  for (std::uint32_t s = 0; s < samples; ++s) {
    out.sample_first[s] = std::uint32_t(out.lines.size());
    for (const std::uint32_t r : out.grids.order) {
      const auto& mine = kept[r];
      std::size_t& j = cursor[r];
      if (j < mine.size() && mine[j].sample == s) {
        out.lines.push_back({r, s, mine[j].fraction});
        ++j;
      }
    }
  }
  out.sample_first[samples] = std::uint32_t(out.lines.size());
  return out;
}

}  // namespace lumar
