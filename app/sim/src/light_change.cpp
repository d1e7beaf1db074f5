#include "lumar/sim/light_change.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar::sim {

double LightChange::weight(double t_s) const {
  if (t_s < at_s) return 0.0;
  if (ramp_s <= 0.0) return 1.0;
  return std::min(1.0, (t_s - at_s) / ramp_s);
}

EnvironmentMap changed_environment_map(const LoadedScene& scene, const LightChange& change) {
  if (change.scale.r < 0 || change.scale.g < 0 || change.scale.b < 0 ||
      !std::isfinite(change.scale.r + change.scale.g + change.scale.b))
    throw InputError("light change: the scale must be finite and non-negative");
  if (scene.room.triangle_count() == 0) throw InputError("light change: the scene has no proxy room to place it on");
  RayScene rays;
  rays.add_static(scene.room);
  rays.commit();
  EnvironmentMap out = scene.map;
  const int W = out.width, H = out.height;
  int changed = 0;
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      Ray ray;
      ray.origin = glm::vec3(out.capture_position);
      ray.direction = glm::vec3(out.world_direction(latlong_pixel_direction(c, r, W, H)));
      const auto hit = rays.intersect(ray);
      if (!hit) continue;
      const glm::dvec3 x = out.capture_position + glm::dvec3(ray.direction) * double(hit->t);
      if (!change.region.contains(x) || luminance(out.texel(c, r)) < change.brighter_than) continue;
      float* p = &out.rgb[(std::size_t(r) * W + c) * 3];
      for (int k = 0; k < 3; ++k) p[k] = float(p[k] * change.scale[k]);
      ++changed;
    }
  if (changed == 0) throw InputError("light change: no texel of the map lies on the proxy inside the region");
  return out;
}

EnvironmentMap blend_environment_maps(const EnvironmentMap& a, const EnvironmentMap& b, double w) {
  if (a.width != b.width || a.height != b.height) throw RuntimeError("blend_environment_maps: maps of different sizes");
  EnvironmentMap out = a;
  const float fw = float(w);
  for (std::size_t i = 0; i < out.rgb.size(); ++i) out.rgb[i] = (1.0f - fw) * a.rgb[i] + fw * b.rgb[i];
  return out;
}

}  // namespace lumar::sim
