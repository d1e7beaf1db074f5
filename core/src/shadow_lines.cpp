#include "lumar/core/shadow_lines.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "lumar/core/error.h"

namespace lumar {

namespace {

// Bounding-sphere tree over items split at the median of their keys along the longest
// axis; item i is bounded by points[first[i], first[i+1]).
class TreeBuilder {
 public:
  TreeBuilder(const std::vector<glm::vec3>& keys, const std::vector<std::uint32_t>& first,
              const std::vector<glm::vec3>& points, int leaf_size, bool leaf_is_item)
      : keys_(keys), first_(first), points_(points), leaf_size_(leaf_size), leaf_is_item_(leaf_is_item) {}

  void build(std::vector<ShadowTreeNode>& nodes, std::vector<std::uint32_t>& order,
             std::vector<std::uint32_t>& leaf_first) {
    order.resize(keys_.size());
    std::iota(order.begin(), order.end(), 0u);
    nodes.clear();
    leaf_first.clear();
    if (order.empty()) return;
    node(nodes, order, leaf_first, 0, order.size());
    leaf_first.push_back(std::uint32_t(order.size()));
  }

 private:
  std::int32_t node(std::vector<ShadowTreeNode>& nodes, std::vector<std::uint32_t>& order,
                    std::vector<std::uint32_t>& leaf_first, std::size_t b, std::size_t e) {
    const auto id = std::int32_t(nodes.size());
    nodes.emplace_back();
    glm::vec3 lo(1e30f), hi(-1e30f), klo(1e30f), khi(-1e30f);
    for (std::size_t i = b; i < e; ++i) {
      klo = glm::min(klo, keys_[order[i]]);
      khi = glm::max(khi, keys_[order[i]]);
      for (std::uint32_t k = first_[order[i]]; k < first_[order[i] + 1]; ++k) {
        lo = glm::min(lo, points_[k]);
        hi = glm::max(hi, points_[k]);
      }
    }
    const glm::vec3 c = 0.5f * (lo + hi);
    float r = 0;
    for (std::size_t i = b; i < e; ++i)
      for (std::uint32_t k = first_[order[i]]; k < first_[order[i] + 1]; ++k)
        r = std::max(r, glm::length(points_[k] - c));
    nodes[std::size_t(id)].centre = c;
    nodes[std::size_t(id)].radius = r * 1.0001f + 1e-6f;
    if (e - b <= std::size_t(leaf_size_)) {
      nodes[std::size_t(id)].leaf = leaf_is_item_ ? std::int32_t(order[b]) : std::int32_t(leaf_first.size());
      leaf_first.push_back(std::uint32_t(b));
      return id;
    }
    const glm::vec3 ext = khi - klo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::size_t mid = (b + e) / 2;
    std::nth_element(order.begin() + std::ptrdiff_t(b), order.begin() + std::ptrdiff_t(mid),
                     order.begin() + std::ptrdiff_t(e),
                     [&](std::uint32_t x, std::uint32_t y) { return keys_[x][axis] < keys_[y][axis]; });
    const std::int32_t left = node(nodes, order, leaf_first, b, mid);
    const std::int32_t right = node(nodes, order, leaf_first, mid, e);
    nodes[std::size_t(id)].child[0] = left;
    nodes[std::size_t(id)].child[1] = right;
    return id;
  }

  const std::vector<glm::vec3>& keys_;
  const std::vector<std::uint32_t>& first_;
  const std::vector<glm::vec3>& points_;
  int leaf_size_;
  bool leaf_is_item_;
};

float max_channel(const glm::vec3& v) { return std::max(v.r, std::max(v.g, v.b)); }

}  // namespace

ShadowLines build_shadow_lines(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               const Emitters& emitters, const RayScene& proxy, const ShadowLineOptions& options) {
  if (positions.size() != normals.size())
    throw InputError("build_shadow_lines: receiver positions and normals differ in count");
  if (options.receivers_per_cluster < 1) throw InputError("build_shadow_lines: receivers_per_cluster must be >= 1");
  ShadowLines out;
  out.distant = emitters.distant;
  out.samples = emitters.samples;
  out.patch_count = std::uint32_t(emitters.patches.size());
  const std::size_t n = positions.size();
  out.origins.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.origins[i] = shadow_ray_origin(positions[i], normals[i]);

  // Receiver clusters.
  {
    std::vector<std::uint32_t> first(n + 1);
    std::iota(first.begin(), first.end(), 0u);
    TreeBuilder(out.origins, first, out.origins, options.receivers_per_cluster, false)
        .build(out.receiver_tree, out.cluster_receivers, out.cluster_first);
  }
  // Emitter tree: one leaf per patch, bounding its sample points (directions when distant).
  {
    std::vector<glm::vec3> keys, points;
    std::vector<std::uint32_t> first;
    for (const EmitterPatch& p : emitters.patches) {
      first.push_back(std::uint32_t(points.size()));
      glm::vec3 k(0.0f);
      for (std::uint32_t s = p.first_sample; s < p.first_sample + p.sample_count; ++s) {
        points.push_back(emitters.samples[s].position);
        k += emitters.samples[s].position;
      }
      keys.push_back(k / float(std::max(1u, p.sample_count)));
    }
    first.push_back(std::uint32_t(points.size()));
    std::vector<std::uint32_t> order, leaves;
    TreeBuilder(keys, first, points, 1, true).build(out.emitter_tree, order, leaves);
  }

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

  // Group the lines by (receiver cluster, patch).
  const std::size_t clusters = out.cluster_count(), patches = out.patch_count;
  std::size_t total = 0;
  for (const auto& k : kept) total += k.size();
  out.lines.reserve(total);
  out.block_first.assign(clusters * patches + 1, 0);
  std::vector<std::size_t> cursor(n, 0);
  for (std::size_t c = 0; c < clusters; ++c)
    for (std::size_t p = 0; p < patches; ++p) {
      out.block_first[c * patches + p] = std::uint32_t(out.lines.size());
      const std::uint32_t end_sample = emitters.patches[p].first_sample + emitters.patches[p].sample_count;
      for (std::uint32_t k = out.cluster_first[c]; k < out.cluster_first[c + 1]; ++k) {
        const std::uint32_t r = out.cluster_receivers[k];
        const auto& mine = kept[r];
        std::size_t& j = cursor[r];
        while (j < mine.size() && mine[j].sample < end_sample) {
          out.lines.push_back({r, mine[j].sample, mine[j].fraction});
          ++j;
        }
      }
    }
  out.block_first[clusters * patches] = std::uint32_t(out.lines.size());
  return out;
}

}  // namespace lumar
