#include "lumar/lighting/irradiance_reference.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>

#include "hemisphere_sampling.h"
#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"

namespace lumar {

glm::dvec3 texel_sum_irradiance(const EnvironmentMap& map, const glm::dvec3& normal) {
  const glm::dvec3 n = glm::normalize(normal);
  glm::dvec3 sum(0.0);
  for (int r = 0; r < map.height; ++r) {
    const double omega = latlong_pixel_solid_angle(r, map.width, map.height);
    glm::dvec3 row(0.0);
    for (int c = 0; c < map.width; ++c) {
      const double cosine = glm::dot(n, map.world_direction(latlong_pixel_direction(c, r, map.width, map.height)));
      if (cosine > 0.0) row += glm::dvec3(map.texel(c, r)) * cosine;
    }
    sum += row * omega;
  }
  return sum;
}

std::vector<glm::dvec3> texel_sum_irradiance(const EnvironmentMap& map, std::span<const glm::dvec3> normals) {
  // Directions and L·Ω once, as float columns, so the sum over every texel vectorises;
  // each row is summed in float and the rows in double.
  const std::size_t W = std::size_t(map.width), H = std::size_t(map.height);
  std::vector<float> dx(W * H), dy(W * H), dz(W * H), pr(W * H), pg(W * H), pb(W * H);
  for (std::size_t r = 0; r < H; ++r) {
    const double omega = latlong_pixel_solid_angle(int(r), map.width, map.height);
    for (std::size_t c = 0; c < W; ++c) {
      const std::size_t i = r * W + c;
      const glm::dvec3 d = map.world_direction(latlong_pixel_direction(int(c), int(r), map.width, map.height));
      dx[i] = float(d.x), dy[i] = float(d.y), dz[i] = float(d.z);
      const glm::vec3 L = map.texel(int(c), int(r));
      pr[i] = float(L.r * omega), pg[i] = float(L.g * omega), pb[i] = float(L.b * omega);
    }
  }
  std::vector<glm::dvec3> out(normals.size());
  tbb::parallel_for(std::size_t(0), normals.size(), [&](std::size_t k) {
    const glm::dvec3 n = glm::normalize(normals[k]);
    const float nx = float(n.x), ny = float(n.y), nz = float(n.z);
    glm::dvec3 sum(0.0);
    for (std::size_t r = 0; r < H; ++r) {
      float sr = 0.f, sg = 0.f, sb = 0.f;
      const std::size_t o = r * W;
      for (std::size_t c = 0; c < W; ++c) {
        const float cosine = std::max(0.f, nx * dx[o + c] + ny * dy[o + c] + nz * dz[o + c]);
        sr += cosine * pr[o + c], sg += cosine * pg[o + c], sb += cosine * pb[o + c];
      }
      sum += glm::dvec3(sr, sg, sb);
    }
    out[k] = sum;
  });
  return out;
}

RadianceSettings reference_radiance_settings() {
  RadianceSettings s;
  s.map_height = 0;
  s.bright_fraction = 0.02;
  s.max_lights = 0;
  return s;
}

glm::dvec3 reference_irradiance(const RoomRadiance& room, const glm::dvec3& point, const glm::dvec3& normal,
                                const glm::dvec3& off_surface, int strata, const ExtraOccluder& occluder) {
  const glm::dvec3 n = glm::normalize(normal);
  // Off the surface a little, so that rays leaving a point on the proxy do not hit it.
  const glm::dvec3 p = point + off_surface * 1e-4;
  glm::dvec3 bright(0.0);
  for (const BrightTexel& t : room.bright_texels()) {
    glm::dvec3 toward;
    const double omega =
        room.solid_angle_from(p, t.on_proxy, t.position, t.normal, t.direction, t.solid_angle, &toward);
    const double cosine = glm::dot(n, toward);
    if (omega <= 0.0 || cosine <= 0.0) continue;
    if (!room.sees(p, t.on_proxy, t.position, t.direction)) continue;
    if (occluder) {
      const double reach = t.on_proxy ? glm::length(t.position - p) - 2e-3 : std::numeric_limits<double>::infinity();
      if (occluder(p, toward, reach)) continue;  // its own light comes with the dim rays
    }
    bright += t.radiance * omega * cosine;
  }
  glm::dvec3 tangent, bitangent;
  orthonormal_basis(n, tangent, bitangent);
  std::mt19937 rng{query_seed(point, n)};
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  glm::dvec3 dim(0.0);
  for (int i = 0; i < strata; ++i)
    for (int j = 0; j < strata; ++j) {
      const double u1 = (i + jitter(rng)) / strata, u2 = (j + jitter(rng)) / strata;
      const glm::dvec3 w = cosine_direction(n, tangent, bitangent, u1, u2);
      const RoomRadiance::Sample sample = room.dim_radiance(p, w);
      if (occluder)
        if (const std::optional<glm::dvec3> back = occluder(p, w, sample.distance)) {
          dim += *back;
          continue;
        }
      dim += sample.radiance;
    }
  // Cosine-weighted sampling: pdf = cos / π, so E = π · mean(L).
  return bright + dim * (kPi / double(strata * strata));
}

glm::dvec3 reference_irradiance(const RoomRadiance& room, const glm::dvec3& point, const glm::dvec3& normal,
                                int strata) {
  const glm::dvec3 n = glm::normalize(normal);
  return reference_irradiance(room, point, n, n, strata, nullptr);
}

std::vector<glm::dvec3> reference_irradiance(const RoomRadiance& room, std::span<const glm::dvec3> points,
                                             std::span<const glm::dvec3> normals, int strata) {
  std::vector<glm::dvec3> out(points.size());
  tbb::parallel_for(std::size_t(0), points.size(),
                    [&](std::size_t i) { out[i] = reference_irradiance(room, points[i], normals[i], strata); });
  return out;
}

}  // namespace lumar
