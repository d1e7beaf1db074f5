#include "lumar/lighting/light_self_shadow.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "hemisphere_sampling.h"
#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/self_occlusion.h"

namespace lumar {

namespace {

constexpr int kProbes = 6;  // samples on the disk's rim, cast first: 60° apart

// Sample k of `count` on a unit disk, even area per sample: the first kProbes on a ring
// through the outer annulus they own, at even angles, so that an edge across the light
// reaches one of them; the rest on a Vogel spiral inside it.
glm::dvec2 disk_sample(int k, int count) {
  const int ring = std::min(kProbes, count);
  if (k < ring) {
    // Turned by 0.5 rad: not along a mesh's own symmetry planes (a UV sphere's meridians),
    // where a ray may slip through the crack between two triangles.
    const double r = std::sqrt(1.0 - 0.5 * ring / count), a = 2.0 * kPi * k / ring + 0.5;
    return {r * std::cos(a), r * std::sin(a)};
  }
  const int j = k - ring;
  const double r = std::sqrt((j + 0.5) / count), a = j * 2.39996322972865332;
  return {r * std::cos(a), r * std::sin(a)};
}

// A light's samples: points on the proxy (on_proxy) or directions (distant), world space.
struct LightSamples {
  std::vector<glm::dvec3> points;
  bool points_are_directions = false;
};

LightSamples light_samples(const VolumeLight& l, const glm::dvec3& capture, int count) {
  LightSamples out;
  out.points_are_directions = !l.on_proxy;
  glm::dvec3 axis = l.on_proxy ? l.normal : l.direction, t, b;
  if (!(glm::length(axis) > 0.0)) axis = {0, 1, 0};
  axis = glm::normalize(axis);
  orthonormal_basis(axis, t, b);
  double radius = 0.0;
  if (l.on_proxy) {
    // The texels' area, as their solid angle from the capture point says, as a disk.
    radius = std::sqrt(patch_area(capture, l.position, axis, std::max(l.solid_angle, 0.0)) / kPi);
  } else {
    // A cone of the light's solid angle, as a disk at unit distance.
    const double cos_half = std::clamp(1.0 - std::max(l.solid_angle, 0.0) / (2.0 * kPi), -1.0, 1.0);
    radius = cos_half > 1e-3 ? std::sqrt(1.0 - cos_half * cos_half) / cos_half : 0.0;
  }
  if (!(radius > 0.0)) count = 1;
  const glm::dvec3 centre = l.on_proxy ? l.position : axis;
  for (int k = 0; k < count; ++k) {
    const glm::dvec2 d = count == 1 ? glm::dvec2(0.0) : disk_sample(k, count) * radius;
    out.points.push_back(centre + d.x * t + d.y * b);
  }
  return out;
}

}  // namespace

LightSelfShadow::LightSelfShadow(const Mesh& model, const LightSelfShadowSettings& settings)
    : model_(model), settings_(settings), scene_(std::make_unique<RayScene>()) {
  if (model.normals.size() != model.positions.size())
    throw InputError("LightSelfShadow: the mesh needs one normal per vertex; load it with load_mesh");
  if (settings.samples < 1 || settings.samples > LightSelfShadowSettings::kMaxSamples)
    throw InputError("LightSelfShadow: samples per light must be 1 to " +
                     std::to_string(LightSelfShadowSettings::kMaxSamples) + ", not " +
                     std::to_string(settings.samples));
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
  std::vector<LightSamples> samples;
  for (const VolumeLight& l : lights) samples.push_back(light_samples(l, capture, settings_.samples));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Ray> rays;
    std::vector<std::uint8_t> hit;
    struct Lit {
      std::size_t light;
      double weight;
      std::size_t first;  // its probes' rays in the first batch
    };
    std::vector<Lit> lit;
    std::vector<double> share;  // per lit light, the blocked share of its samples
    std::vector<Ray> more;
    std::vector<std::size_t> more_of;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const glm::dvec3 n_model(model_.normals[i]);
      const glm::dvec3 n_world = normal_matrix * n_model;
      if (!(glm::length(n_model) > 0.5) || !(glm::length(n_world) > 0.0)) continue;
      const glm::dvec3 p = glm::dvec3(T_world_model * glm::dvec4(glm::dvec3(model_.positions[i]), 1.0));
      const glm::dvec3 nw = glm::normalize(n_world);
      const glm::vec3 origin = model_.positions[i] + glm::vec3(glm::normalize(n_model)) * offset_;
      const auto ray_to = [&](const LightSamples& s, std::size_t k) {
        const glm::dvec3 w = s.points_are_directions ? s.points[k] : s.points[k] - p;
        return Ray{origin, 0.0f, glm::vec3(to_model * w), s.points_are_directions ? 1e30f : 1.0f};
      };
      // First the ring's samples of every light that reaches the normal's side.
      rays.clear(), lit.clear();
      for (std::size_t l = 0; l < lights.size(); ++l) {
        glm::dvec3 toward;
        const double e = luminance(light_irradiance(lights[l], capture, p, nw, &toward));
        if (!(e > 0.0)) continue;
        lit.push_back({l, e, rays.size()});
        const std::size_t probes = std::min<std::size_t>(kProbes, samples[l].points.size());
        for (std::size_t k = 0; k < probes; ++k) rays.push_back(ray_to(samples[l], k));
      }
      if (lit.empty()) continue;
      hit.assign(rays.size(), 0);
      scene_->occluded(rays, hit);
      // Where they agree, the light is all blocked or all open; elsewhere cast the rest.
      share.assign(lit.size(), 0.0);
      more.clear(), more_of.clear();
      for (std::size_t j = 0; j < lit.size(); ++j) {
        const LightSamples& s = samples[lit[j].light];
        const std::size_t probes = std::min<std::size_t>(kProbes, s.points.size());
        std::size_t blocked = 0;
        for (std::size_t k = 0; k < probes; ++k) blocked += hit[lit[j].first + k];
        if (blocked == 0 || blocked == probes) {
          share[j] = blocked == 0 ? 0.0 : 1.0;
          continue;
        }
        share[j] = double(blocked) / double(s.points.size());
        for (std::size_t k = probes; k < s.points.size(); ++k) more.push_back(ray_to(s, k)), more_of.push_back(j);
      }
      if (!more.empty()) {
        hit.assign(more.size(), 0);
        scene_->occluded(more, hit);
        for (std::size_t k = 0; k < more.size(); ++k)
          if (hit[k]) share[more_of[k]] += 1.0 / double(samples[lit[more_of[k]].light].points.size());
      }
      double total = 0, blocked = 0;
      for (std::size_t j = 0; j < lit.size(); ++j) total += lit[j].weight, blocked += share[j] * lit[j].weight;
      out[i] = float(blocked / total);
    }
  });
  return out;
}

}  // namespace lumar
