#include "lumar/lighting/composite_reference.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "hemisphere_sampling.h"
#include "lumar/base/constants.h"
#include "lumar/lighting/irradiance_reference.h"

namespace lumar {

namespace {

glm::dvec3 vertex(const Mesh& m, std::uint32_t triangle, int k) {
  return glm::dvec3(m.positions[m.indices[3 * triangle + k]]);
}

}  // namespace

RadianceSettings truth_radiance_settings() {
  RadianceSettings s = reference_radiance_settings();
  s.map_height = 128;
  return s;
}

CompositeReference::CompositeReference(const RoomRadiance& room, std::span<const LoadedObject> objects,
                                       const CompositeReferenceSettings& settings)
    : room_(room), settings_(settings), rays_(std::make_unique<RayScene>()) {
  for (const LoadedObject& o : objects) {
    Object object;
    object.world = transformed(o.model, o.T_world_model);
    object.albedo = glm::dvec3(o.albedo);
    const auto [lo, hi] = object.world.bounds();
    object.centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
    object.radius = 0.5 * glm::length(glm::dvec3(hi) - glm::dvec3(lo));
    rays_->add_static(object.world);
    objects_.push_back(std::move(object));
  }
  rays_->commit();
  if (!settings_.bounce) return;
  // Each object's own light per vertex, with every object in place: what it sends onto
  // the room. The vertex sits on the surface, so its rays leave along its normal.
  for (Object& object : objects_) {
    const Mesh& m = object.world;
    object.vertex_irradiance.resize(m.positions.size());
    tbb::parallel_for(std::size_t(0), m.positions.size(), [&](std::size_t i) {
      object.vertex_irradiance[i] =
          irradiance_with_objects(glm::dvec3(m.positions[i]), glm::dvec3(m.normals[i]), settings_.vertex_strata);
    });
  }
}

CompositeReference::~CompositeReference() = default;

std::optional<ObjectHit> CompositeReference::hit_object(const glm::dvec3& origin, const glm::dvec3& direction,
                                                        double t_far) const {
  const glm::dvec3 forward = glm::normalize(direction);
  const auto cast = [&](const glm::dvec3& w) -> std::optional<ObjectHit> {
    Ray ray;
    ray.origin = glm::vec3(origin);
    ray.direction = glm::vec3(w);
    ray.t_far = float(std::min(t_far, 1e30));
    const auto hit = rays_->intersect(ray);
    if (!hit) return std::nullopt;
    ObjectHit h;
    h.object = int(hit->mesh);
    h.t = hit->t;
    h.triangle = hit->triangle;
    h.point = origin + w * double(hit->t);
    h.facing = glm::dvec3(hit->normal);
    // Barycentric weights of the hit point in its triangle, for the vertex normals.
    const Mesh& m = objects_[std::size_t(h.object)].world;
    const glm::dvec3 a = vertex(m, h.triangle, 0), b = vertex(m, h.triangle, 1), c = vertex(m, h.triangle, 2);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double area2 = glm::dot(n, n);
    if (area2 > 0) {
      const double wb = glm::dot(glm::cross(h.point - a, c - a), n) / area2;
      const double wc = glm::dot(glm::cross(b - a, h.point - a), n) / area2;
      h.weights = glm::clamp(glm::dvec3(1.0 - wb - wc, wb, wc), 0.0, 1.0);
    } else {
      h.weights = glm::dvec3(1.0 / 3.0);
    }
    glm::dvec3 shading(0.0);
    for (int k = 0; k < 3; ++k) shading += h.weights[k] * glm::dvec3(m.normals[m.indices[3 * h.triangle + k]]);
    h.normal = glm::dot(shading, shading) > 0 ? glm::normalize(shading) : h.facing;
    return h;
  };
  // Every ray starts outside the objects, so meeting a surface from inside (its vertex
  // normals turned away from the ray's origin, whatever the winding) means the ray slipped
  // through a crack between two triangles: Embree is not watertight by default, and rays
  // along a UV sphere's meridian edges do it. Nudge the ray and cast it again.
  const auto from_inside = [&](const ObjectHit& h) { return glm::dot(h.facing, h.normal) < 0.0; };
  auto hit = cast(forward);
  glm::dvec3 side, up;
  orthonormal_basis(forward, side, up);
  for (int attempt = 1; hit && from_inside(*hit) && attempt <= 4; ++attempt)
    hit = cast(glm::normalize(forward + (attempt % 2 ? side : up) * (attempt <= 2 ? 1e-5 : -1e-5)));
  return hit;
}

ExtraOccluder CompositeReference::objects_as_occluder() const {
  return [this](const glm::dvec3& q, const glm::dvec3& w, double t_far) -> std::optional<glm::dvec3> {
    if (blocked(q, w, t_far)) return glm::dvec3(0.0);
    return std::nullopt;
  };
}

ExtraOccluder CompositeReference::objects_reflecting_onto(int self) const {
  return [this, self](const glm::dvec3& q, const glm::dvec3& w, double t_far) -> std::optional<glm::dvec3> {
    const std::optional<ObjectHit> hit = hit_object(q, w, t_far);
    if (!hit) return std::nullopt;
    if (hit->object == self || objects_[std::size_t(hit->object)].vertex_irradiance.empty()) return glm::dvec3(0.0);
    return object_radiance(*hit, false);
  };
}

bool CompositeReference::blocked(const glm::dvec3& p, const glm::dvec3& w, double t_far) const {
  Ray ray;
  ray.origin = glm::vec3(p);
  ray.direction = glm::vec3(w);
  ray.t_far = float(std::min(t_far, 1e30));
  return rays_->occluded(ray);
}

glm::dvec3 CompositeReference::irradiance_with_objects(const glm::dvec3& p, const glm::dvec3& n, int strata) const {
  return reference_irradiance(room_, p, n, n, strata > 0 ? strata : settings_.object_strata, objects_as_occluder());
}

glm::dvec3 CompositeReference::object_radiance(const ObjectHit& hit, bool per_point) const {
  const Object& object = objects_[std::size_t(hit.object)];
  glm::dvec3 E(0.0);
  if (per_point || object.vertex_irradiance.empty()) {
    // Seen from inside (through a hole in a scanned shell: the figurine's crest, arm and
    // toes), the vertex normals face away: the surface's own normal, towards the viewer.
    const glm::dvec3 n = glm::dot(hit.normal, hit.facing) > 0.0 ? hit.normal : hit.facing;
    E = reference_irradiance(room_, hit.point, n, hit.facing, settings_.object_strata,
                             settings_.bounce ? objects_reflecting_onto(hit.object) : objects_as_occluder());
  } else {
    const Mesh& m = object.world;
    for (int k = 0; k < 3; ++k) E += hit.weights[k] * object.vertex_irradiance[m.indices[3 * hit.triangle + k]];
  }
  return object.albedo / kPi * E;
}

glm::dvec3 CompositeReference::room_ratio(const glm::dvec3& point, const glm::dvec3& normal) const {
  const glm::dvec3 n = glm::normalize(normal);
  const glm::dvec3 p = point + n * 1e-4;
  // What changes, object by object: within the object's cone (or the hemisphere, from
  // inside its bounding sphere), the directions whose nearest hit is that object lose the
  // room's radiance and gain the object's. Each direction is counted by one object only.
  glm::dvec3 change(0.0);
  struct Cone {
    glm::dvec3 axis;
    double cos_max;
  };
  std::vector<Cone> cones;  // of the objects within reach
  std::mt19937 rng{query_seed(point, n) ^ 0x9e3779b9u};
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  const int strata = settings_.cone_strata;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    const Object& object = objects_[o];
    const glm::dvec3 to_centre = object.centre - p;
    const double d = glm::length(to_centre);
    if (d > settings_.reach * object.radius) continue;
    // Wholly below the horizon: the object cannot be seen from here.
    if (glm::dot(to_centre, n) < -object.radius) continue;
    const bool inside = d <= object.radius * 1.001;
    glm::dvec3 axis = inside ? n : to_centre / d, t, b;
    orthonormal_basis(axis, t, b);
    const double cos_max = inside ? 0.0 : std::sqrt(std::max(0.0, 1.0 - (object.radius / d) * (object.radius / d)));
    cones.push_back({axis, inside ? -1.0 : cos_max});
    glm::dvec3 sum(0.0);
    for (int i = 0; i < strata; ++i)
      for (int j = 0; j < strata; ++j) {
        const double u1 = (i + jitter(rng)) / strata, u2 = (j + jitter(rng)) / strata;
        const glm::dvec3 w =
            inside ? cosine_direction(axis, t, b, u1, u2) : cone_direction(axis, t, b, cos_max, u1, u2);
        const double cosine = glm::dot(w, n);
        if (cosine <= 0.0) continue;
        const RoomRadiance::Sample room = room_.dim_radiance(p, w);
        const auto hit = hit_object(p, w, room.distance);
        if (!hit || hit->object != int(o)) continue;
        glm::dvec3 g = -room.radiance;
        if (settings_.bounce) g += object_radiance(*hit, false);
        // Cosine-weighted over the hemisphere: E = π mean(L); uniform in the cone:
        // E = Ω mean(L cos).
        sum += inside ? g : g * cosine;
      }
    const double samples = double(strata * strata);
    change += inside ? sum * (kPi / samples) : sum * (2.0 * kPi * (1.0 - cos_max) / samples);
  }
  if (cones.empty()) return glm::dvec3(1.0);
  // Bright texels are summed exactly in E_without; those an object hides are taken out
  // (only those within an object's cone can be).
  for (const BrightTexel& texel : room_.bright_texels()) {
    glm::dvec3 toward;
    const double omega = room_.solid_angle_from(p, texel.on_proxy, texel.position, texel.normal, texel.direction,
                                                texel.solid_angle, &toward);
    const double cosine = glm::dot(n, toward);
    if (omega <= 0.0 || cosine <= 0.0) continue;
    if (std::none_of(cones.begin(), cones.end(), [&](const Cone& c) { return glm::dot(toward, c.axis) >= c.cos_max; }))
      continue;
    const double reach =
        texel.on_proxy ? glm::length(texel.position - p) - 2e-3 : std::numeric_limits<double>::infinity();
    if (!blocked(p, toward, reach)) continue;
    if (room_.sees(p, texel.on_proxy, texel.position, texel.direction)) change -= texel.radiance * omega * cosine;
  }
  const glm::dvec3 without = reference_irradiance(room_, point, n, settings_.room_strata);
  glm::dvec3 ratio(1.0);
  for (int c = 0; c < 3; ++c)
    if (without[c] > 0) ratio[c] = std::max(0.0, (without[c] + change[c]) / without[c]);
  return ratio;
}

}  // namespace lumar
