#include "lumar/lighting/shadows/shadow_methods.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <optional>

#include "lumar/base/error.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/self_occlusion.h"
#include "lumar/lighting/sh.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/lighting/shadows/shadow_receivers.h"

namespace lumar {

namespace {

glm::vec3 ratio(const glm::vec3& with, const glm::vec3& without) {
  glm::vec3 a(1.0f);
  for (int c = 0; c < 3; ++c)
    if (without[c] > 0) a[c] = std::clamp(with[c] / without[c], 0.0f, 1.0f);
  return a;
}

void check_points(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals) {
  if (positions.size() != normals.size()) throw InputError("shadows: receiver positions and normals differ in count");
}

}  // namespace

BoundingSphere bounding_sphere(const Mesh& model, const glm::dmat4& T) {
  BoundingSphere s;
  if (model.positions.empty()) return s;
  glm::vec3 lo(1e30f), hi(-1e30f);
  std::vector<glm::vec3> world(model.positions.size());
  for (std::size_t i = 0; i < world.size(); ++i) {
    world[i] = glm::vec3(T * glm::dvec4(glm::dvec3(model.positions[i]), 1.0));
    lo = glm::min(lo, world[i]);
    hi = glm::max(hi, world[i]);
  }
  s.centre = 0.5f * (lo + hi);
  for (const glm::vec3& p : world) s.radius = std::max(s.radius, glm::length(p - s.centre));
  return s;
}

std::vector<glm::vec3> reference_attenuation(const std::vector<glm::vec3>& positions,
                                             const std::vector<glm::vec3>& normals, const Emitters& emitters,
                                             const RayScene& proxy, const RayScene& occluders) {
  check_points(positions, normals);
  std::vector<glm::vec3> out(positions.size(), glm::vec3(1.0f));
  const float t_far = shadow_ray_t_far(emitters.distant);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4), [&](const auto& range) {
    std::vector<Ray> rays;
    std::vector<glm::vec3> transfer;
    std::vector<std::uint8_t> by_proxy, by_object;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      rays.clear(), transfer.clear();
      const glm::vec3 o = shadow_ray_origin(positions[i], normals[i]);
      for (const EmitterPoint& e : emitters.texels) {
        const glm::vec3 E = emitter_irradiance(e, emitters.distant, positions[i], normals[i]);
        if (!(std::max(E.r, std::max(E.g, E.b)) > 0)) continue;
        rays.push_back(Ray{o, 0.0f, emitter_line_end(e, emitters.distant, o) - o, t_far});
        transfer.push_back(E);
      }
      by_proxy.assign(rays.size(), 0);
      by_object.assign(rays.size(), 0);
      if (!proxy.empty()) proxy.occluded(rays, by_proxy);
      if (!occluders.empty()) occluders.occluded(rays, by_object);
      glm::dvec3 with(0.0), without(0.0);
      for (std::size_t k = 0; k < rays.size(); ++k) {
        if (by_proxy[k]) continue;
        without += glm::dvec3(transfer[k]);
        if (!by_object[k]) with += glm::dvec3(transfer[k]);
      }
      out[i] = ratio(glm::vec3(with), glm::vec3(without));
    }
  });
  return out;
}

std::vector<glm::vec3> sphere_attenuation(const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::vec3>& normals, const Emitters& emitters,
                                          const RayScene& proxy, const std::vector<BoundingSphere>& occluders) {
  check_points(positions, normals);
  std::vector<glm::vec3> out(positions.size(), glm::vec3(1.0f));
  const float t_far = shadow_ray_t_far(emitters.distant);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 16), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 o = shadow_ray_origin(positions[i], normals[i]);
      glm::vec3 with(0.0f), without(0.0f);
      for (const EmitterPatch& p : emitters.patches) {
        // One line per patch, to the patch's flux-weighted centre.
        EmitterPoint centre;
        glm::vec3 pos(0.0f), nrm(0.0f);
        float w = 0;
        for (std::uint32_t s = p.first_sample; s < p.first_sample + p.sample_count; ++s) {
          const EmitterPoint& e = emitters.samples[s];
          const float ws = e.flux.r + e.flux.g + e.flux.b + 1e-12f;
          pos += ws * e.position, nrm += ws * e.normal, w += ws;
        }
        centre.position = emitters.distant ? glm::normalize(pos) : pos / w;
        centre.normal = glm::length(nrm) > 0 ? glm::normalize(nrm) : nrm;
        centre.flux = p.flux;
        const glm::vec3 E = emitter_irradiance(centre, emitters.distant, positions[i], normals[i]);
        if (!(std::max(E.r, std::max(E.g, E.b)) > 0)) continue;
        const glm::vec3 end = emitter_line_end(centre, emitters.distant, o);
        if (!proxy.empty() && proxy.occluded(Ray{o, 0.0f, end - o, t_far})) continue;
        without += E;
        bool blocked = false;
        const glm::vec3 d = end - o;
        for (const BoundingSphere& s : occluders) {
          const float t = std::clamp(glm::dot(s.centre - o, d) / glm::dot(d, d), 0.0f, 1.0f);
          blocked = blocked || glm::length(o + t * d - s.centre) <= s.radius;
        }
        if (!blocked) with += E;
      }
      out[i] = ratio(with, without);
    }
  });
  return out;
}

EmitterOptions sphere_baseline_emitter_options() {
  EmitterOptions o;
  o.threshold_over_mean = 4.0;
  o.fixed_patches = 50;
  o.samples_per_patch = 1;
  return o;
}

ShadowMethod parse_shadow_method(const std::string& name) {
  if (name == "lines") return ShadowMethod::Lines;
  if (name == "reference") return ShadowMethod::Reference;
  if (name == "sphere") return ShadowMethod::Sphere;
  throw InputError("--method: unknown method '" + name + "'; use lines, reference or sphere");
}

ShadowScene::ShadowScene(std::shared_ptr<const LoadedScene> scene) : scene_(std::move(scene)) {
  proxy_ = std::make_unique<RayScene>();
  if (scene_->room.triangle_count() > 0) proxy_->add_static(scene_->room);
  proxy_->commit();
}

ShadowScene::ShadowScene(LoadedScene scene) : ShadowScene(std::make_shared<const LoadedScene>(std::move(scene))) {}

namespace {
LoadedScene scene_of_parts(EnvironmentMap map, bool distant, Mesh room_world, std::vector<LoadedObject> objects,
                           ShadowRegions regions) {
  LoadedScene s;
  s.manifest.distant_map = distant;
  s.manifest.shadows = std::move(regions);
  if (room_world.triangle_count() > 0) {
    const auto [lo, hi] = room_world.bounds();
    s.manifest.movement_min = glm::dvec3(lo), s.manifest.movement_max = glm::dvec3(hi);
  }
  s.map = std::move(map);
  s.room = std::move(room_world);
  s.objects = std::move(objects);
  return s;
}
}  // namespace

ShadowScene::ShadowScene(EnvironmentMap map, bool distant, Mesh room_world, std::vector<Object> objects,
                         ShadowRegions regions)
    : ShadowScene(
          scene_of_parts(std::move(map), distant, std::move(room_world), std::move(objects), std::move(regions))) {}

std::vector<SceneBox> ShadowScene::receiver_regions() const {
  if (!regions().receivers.empty()) return regions().receivers;
  return default_receiver_regions(scene_->manifest, scene_->room);
}

Mesh ShadowScene::receivers() const {
  return build_receivers(*proxy_, receiver_regions(), regions().receiver_vertices);
}

Emitters ShadowScene::emitters(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               EmitterOptions options) const {
  glm::dvec3 c(0.0), n(0.0);
  for (std::size_t i = 0; i < positions.size(); ++i) c += glm::dvec3(positions[i]), n += glm::dvec3(normals[i]);
  if (!positions.empty()) c /= double(positions.size());
  const glm::vec3 normal = glm::length(n) > 1e-9 ? glm::vec3(glm::normalize(n)) : glm::vec3(0, 1, 0);
  if (options.regions.empty()) options.regions = regions().emitters;
  return build_emitters(map(), *proxy_, distant(), glm::vec3(c), normal, options);
}

std::unique_ptr<RayScene> ShadowScene::occluders() const {
  auto s = std::make_unique<RayScene>();
  for (const Object& o : objects()) s->add_instance(o.model, o.T_world_model);
  s->commit();
  return s;
}

namespace {

// The ground truth with the objects' bounce (composite_reference.h), per point.
std::vector<glm::vec3> reference_with_bounce(const ShadowScene& scene, const std::vector<glm::vec3>& positions,
                                             const std::vector<glm::vec3>& normals) {
  const std::unique_ptr<RoomRadiance> room = scene_radiance(scene.scene(), RadianceSettings{});
  std::vector<LoadedObject> objects;
  for (const LoadedObject& o : scene.objects())
    if (o.bounce) objects.push_back(o);
  // Objects that reflect nothing still block: albedo 0.
  for (const LoadedObject& o : scene.objects())
    if (!o.bounce) objects.push_back(o), objects.back().albedo = glm::vec3(0.0f);
  const CompositeReference reference(*room, objects);
  std::vector<glm::vec3> out(positions.size());
  tbb::parallel_for(std::size_t(0), positions.size(), [&](std::size_t i) {
    out[i] = glm::vec3(reference.room_ratio(glm::dvec3(positions[i]), glm::dvec3(normals[i])));
  });
  return out;
}

}  // namespace

void check_shadow_options(ShadowMethod method, const ShadowMethodOptions& options) {
  if (options.bounce && method == ShadowMethod::Sphere)
    throw InputError("--bounce: the sphere method (2004) has no bounce; use lines or reference");
}

std::vector<glm::vec3> shadow_attenuation(const ShadowScene& scene, const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::vec3>& normals, ShadowMethod method,
                                          const ShadowMethodOptions& options) {
  check_points(positions, normals);
  check_shadow_options(method, options);
  switch (method) {
    case ShadowMethod::Reference: {
      if (options.bounce) return reference_with_bounce(scene, positions, normals);
      const Emitters e = scene.emitters(positions, normals, options.emitters);
      return reference_attenuation(positions, normals, e, scene.proxy(), *scene.occluders());
    }
    case ShadowMethod::Sphere: {
      EmitterOptions eo = sphere_baseline_emitter_options();
      eo.map_width = options.emitters.map_width;
      const Emitters e = scene.emitters(positions, normals, eo);
      std::vector<BoundingSphere> spheres;
      for (const auto& o : scene.objects()) spheres.push_back(bounding_sphere(o.model, o.T_world_model));
      return sphere_attenuation(positions, normals, e, scene.proxy(), spheres);
    }
    case ShadowMethod::Lines:
    default: {
      const Emitters e = scene.emitters(positions, normals, options.emitters);
      LineShadows shadows(build_shadow_lines(positions, normals, e, scene.proxy(), options.lines));
      for (const auto& o : scene.objects()) shadows.add_object(o.model, o.T_world_model);
      shadows.update();
      if (!options.bounce) return shadows.attenuation();
      ObjectBounce bounce(shadows.lines().origins, normals, shadows.lines().unshadowed, options.bounce_settings);
      for (const auto& o : scene.objects()) {
        const int id = bounce.add_object(o.model, o.albedo, o.T_world_model);
        bounce.set_object_enabled(id, o.bounce);
        if (o.bounce) bounce.set_object_occlusion(id, bake_self_occlusion(o.model));
      }
      // The objects shaded as the overlay shades them: the scene's volume, or SH9.
      const std::string& lighting = scene.scene().manifest.lighting.method;
      std::optional<IrradianceVolume> volume;
      if (lighting != "sh9") volume = scene_irradiance_volume(scene.scene(), lighting, options.volume_cache);
      bounce.update(object_irradiance(volume ? &*volume : nullptr, volume ? SH9{} : project_radiance_sh9(scene.map())));
      return with_bounce(shadows.attenuation(), bounce);
    }
  }
}

}  // namespace lumar
