#include "lumar/lighting/shadows/shadow_emitters.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>

#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"

namespace lumar {

namespace {

// The map box-filtered to width x width/2 (radiance averaged with solid-angle weights).
std::vector<glm::vec3> downsample(const EnvironmentMap& map, int width) {
  const int height = width / 2;
  std::vector<glm::dvec3> sum(std::size_t(width) * height, glm::dvec3(0.0));
  std::vector<double> weight(sum.size(), 0.0);
  for (int r = 0; r < map.height; ++r) {
    const double w = latlong_pixel_solid_angle(r, map.width, map.height);
    const int orow = std::min(height - 1, int(std::int64_t(r) * height / map.height));
    for (int c = 0; c < map.width; ++c) {
      const int ocol = std::min(width - 1, int(std::int64_t(c) * width / map.width));
      const std::size_t o = std::size_t(orow) * width + ocol;
      sum[o] += w * glm::dvec3(map.texel(c, r));
      weight[o] += w;
    }
  }
  std::vector<glm::vec3> out(sum.size(), glm::vec3(0.0f));
  for (std::size_t i = 0; i < out.size(); ++i)
    if (weight[i] > 0) out[i] = glm::vec3(sum[i] / weight[i]);
  return out;
}

// Median cut (Debevec 2005) over texels, split where the clusters matter most for the
// receivers: a cluster is a list of texel indices.
class Clustering {
 public:
  Clustering(const std::vector<EmitterPoint>& texels, bool distant, const glm::vec3& centre, const glm::vec3& normal)
      : texels_(texels), distant_(distant), centre_(centre) {
    importance_.resize(texels.size());
    for (std::size_t i = 0; i < texels.size(); ++i)
      importance_[i] = luminance(emitter_irradiance(texels[i], distant, centre, normal));
  }

  struct Cluster {
    std::vector<std::uint32_t> texels;
    double importance = 0;      // unoccluded irradiance (luminance) at the receiver centre
    double flux = 0;            // luminance of the flux
    double angular_radius = 0;  // radians, seen from the receiver centre
  };

  Cluster make(std::vector<std::uint32_t> idx) const {
    Cluster c;
    c.texels = std::move(idx);
    glm::dvec3 mean(0.0);
    for (std::uint32_t t : c.texels) {
      c.importance += importance_[t];
      c.flux += luminance(texels_[t].flux);
      mean += (luminance(texels_[t].flux) + 1e-12) * glm::dvec3(direction(t));
    }
    const glm::dvec3 m = glm::length(mean) > 0 ? glm::normalize(mean) : glm::dvec3(0, 1, 0);
    double min_cos = 1.0;
    for (std::uint32_t t : c.texels) min_cos = std::min(min_cos, glm::dot(m, glm::dvec3(direction(t))));
    c.angular_radius = std::acos(std::clamp(min_cos, -1.0, 1.0));
    return c;
  }

  // Splits at the flux-weighted median along the longest axis of the texels' positions.
  std::pair<Cluster, Cluster> split(const Cluster& c) const {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (std::uint32_t t : c.texels) {
      lo = glm::min(lo, texels_[t].position);
      hi = glm::max(hi, texels_[t].position);
    }
    const glm::vec3 ext = hi - lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    std::vector<std::uint32_t> idx = c.texels;
    std::sort(idx.begin(), idx.end(),
              [&](std::uint32_t a, std::uint32_t b) { return texels_[a].position[axis] < texels_[b].position[axis]; });
    double total = 0;
    for (std::uint32_t t : idx) total += luminance(texels_[t].flux);
    std::size_t cut = idx.size() / 2;
    if (total > 0) {
      double run = 0;
      for (std::size_t i = 0; i < idx.size(); ++i) {
        run += luminance(texels_[idx[i]].flux);
        if (run >= 0.5 * total) {
          cut = i + 1;
          break;
        }
      }
    }
    cut = std::clamp<std::size_t>(cut, 1, idx.size() - 1);
    return {make({idx.begin(), idx.begin() + std::ptrdiff_t(cut)}),
            make({idx.begin() + std::ptrdiff_t(cut), idx.end()})};
  }

  // Splits until `done` says stop; `priority` picks the cluster to split next.
  template <class Priority, class Done>
  std::vector<Cluster> run(std::vector<std::uint32_t> all, Priority priority, Done done) const {
    std::vector<Cluster> clusters;
    clusters.push_back(make(std::move(all)));
    while (!done(clusters)) {
      std::size_t best = clusters.size();
      double best_p = 0;
      for (std::size_t i = 0; i < clusters.size(); ++i) {
        if (clusters[i].texels.size() < 2) continue;
        const double p = priority(clusters[i]);
        if (p > best_p) best_p = p, best = i;
      }
      if (best == clusters.size()) break;  // nothing left worth splitting
      auto [a, b] = split(clusters[best]);
      clusters[best] = std::move(a);
      clusters.push_back(std::move(b));
    }
    return clusters;
  }

  EmitterPoint merge(const Cluster& c) const {
    glm::dvec3 pos(0.0), nrm(0.0), flux(0.0);
    double w_sum = 0;
    for (std::uint32_t t : c.texels) {
      const double w = luminance(texels_[t].flux) + 1e-12;
      pos += w * glm::dvec3(texels_[t].position);
      nrm += w * glm::dvec3(texels_[t].normal);
      flux += glm::dvec3(texels_[t].flux);
      w_sum += w;
    }
    EmitterPoint e;
    e.position = glm::vec3(pos / w_sum);
    if (distant_) e.position = glm::normalize(e.position);
    e.normal = glm::length(nrm) > 0 ? glm::vec3(glm::normalize(nrm)) : glm::vec3(0.0f);
    e.flux = glm::vec3(flux);
    return e;
  }

 private:
  glm::vec3 direction(std::uint32_t t) const {
    if (distant_) return texels_[t].position;
    const glm::vec3 d = texels_[t].position - centre_;
    const float len = glm::length(d);
    return len > 0 ? d / len : glm::vec3(0, 1, 0);
  }

  const std::vector<EmitterPoint>& texels_;
  bool distant_;
  glm::vec3 centre_;
  std::vector<double> importance_;
};

}  // namespace

glm::vec3 emitter_irradiance(const EmitterPoint& e, bool distant, const glm::vec3& x, const glm::vec3& n) {
  if (distant) return e.flux * std::max(0.0f, glm::dot(n, e.position));
  const glm::vec3 d = e.position - x;
  const float r2 = glm::dot(d, d);
  if (!(r2 > 1e-8f)) return glm::vec3(0.0f);
  const float r = std::sqrt(r2);
  const float cos_x = glm::dot(n, d) / r;
  const float cos_e = -glm::dot(e.normal, d) / r;
  if (cos_x <= 0 || cos_e <= 0) return glm::vec3(0.0f);
  // Close to the emitter the point-light form factor blows up; cap the solid angle at 2*pi.
  return e.flux * (cos_x * cos_e / std::max(r2, 1e-4f));
}

glm::vec3 emitter_line_end(const EmitterPoint& e, bool distant, const glm::vec3& x) {
  return distant ? x + kDistantLineLength * e.position : e.position;
}

Emitters build_emitters(const EnvironmentMap& map, const RayScene& proxy, bool distant,
                        const glm::vec3& receiver_centre, const glm::vec3& receiver_normal,
                        const EmitterOptions& options) {
  if (map.width <= 0 || map.height * 2 != map.width)
    throw InputError("build_emitters: environment map is empty or not 2:1; load it with load_environment_map");
  if (options.map_width < 8 || options.map_width % 2 != 0 || options.samples_per_patch < 1)
    throw InputError("build_emitters: map_width must be an even number >= 8 and samples_per_patch >= 1");
  const int W = std::min(options.map_width, map.width), H = W / 2;
  const std::vector<glm::vec3> radiance = downsample(map, W);

  double mean_lum = 0;
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c)
      mean_lum += latlong_pixel_solid_angle(r, W, H) * luminance(radiance[std::size_t(r) * W + c]);
  mean_lum /= 4.0 * kPi;
  const double threshold = options.threshold_over_mean * mean_lum;

  Emitters out;
  out.distant = distant;
  const glm::vec3 capture(map.capture_position);
  const bool have_proxy = !proxy.empty();
  for (int r = 0; r < H; ++r) {
    const float omega = float(latlong_pixel_solid_angle(r, W, H));
    for (int c = 0; c < W; ++c) {
      const glm::vec3 L = radiance[std::size_t(r) * W + c];
      const double lum = luminance(L);
      if (!(lum > 0) || lum < threshold) continue;
      const glm::vec3 d(map.world_direction(latlong_pixel_direction(c, r, W, H)));
      EmitterPoint e;
      if (distant) {
        e.position = glm::normalize(d);
        e.normal = -e.position;
        e.flux = L * omega;
      } else {
        std::optional<RayHit> hit;
        if (have_proxy) hit = proxy.intersect(Ray{capture, 0.0f, d, 1e30f});
        float t = 50.0f;  // a hole in the proxy: the light stays on a far sphere
        glm::vec3 n = -d;
        if (hit) t = hit->t, n = hit->normal;
        const float cos_e = std::max(0.05f, std::abs(glm::dot(n, d)));
        e.position = capture + t * d;
        e.normal = n;
        e.flux = L * (omega * t * t / cos_e);
        if (!options.regions.empty()) {
          bool inside = false;
          for (const SceneBox& b : options.regions) inside = inside || b.contains(glm::dvec3(e.position));
          if (!inside) continue;
        }
      }
      out.texels.push_back(e);
    }
  }
  if (out.texels.empty()) return out;

  const Clustering clustering(out.texels, distant, receiver_centre, receiver_normal);
  std::vector<std::uint32_t> all(out.texels.size());
  std::iota(all.begin(), all.end(), 0u);
  const double resolved_angle = options.resolved_angle_deg * kPi / 180.0;
  const auto resolved_share = [&](const std::vector<Clustering::Cluster>& cs) {
    double total = 0, resolved = 0;
    for (const auto& c : cs) {
      total += c.importance;
      if (c.angular_radius <= resolved_angle || c.texels.size() < 2) resolved += c.importance;
    }
    return total > 0 ? resolved / total : 1.0;
  };
  std::vector<Clustering::Cluster> patches;
  if (options.fixed_patches > 0) {
    patches = clustering.run(
        all, [](const auto& c) { return (c.importance + 1e-9 * c.flux) * (c.angular_radius + 1e-6); },
        [&](const auto& cs) { return int(cs.size()) >= options.fixed_patches; });
  } else {
    patches = clustering.run(
        all, [&](const auto& c) { return c.angular_radius > resolved_angle ? c.importance * c.angular_radius : 0.0; },
        [&](const auto& cs) {
          return int(cs.size()) >= options.max_patches || resolved_share(cs) >= options.resolved_fraction;
        });
  }
  out.resolved_fraction = resolved_share(patches);

  for (const auto& p : patches) {
    EmitterPatch patch;
    patch.first_sample = std::uint32_t(out.samples.size());
    const auto subs = clustering.run(
        p.texels, [](const auto& c) { return (c.flux + 1e-12) * (c.angular_radius + 1e-6); },
        [&](const auto& cs) { return int(cs.size()) >= options.samples_per_patch; });
    for (const auto& s : subs) {
      out.samples.push_back(clustering.merge(s));
      patch.flux += out.samples.back().flux;
    }
    patch.sample_count = std::uint32_t(out.samples.size()) - patch.first_sample;
    out.patches.push_back(patch);
  }
  return out;
}

}  // namespace lumar
