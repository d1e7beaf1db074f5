#pragma once
// Radiance arriving at a point from the real room: the environment map projected onto
// the proxy model from the map's capture point (docs/irradiance.md). A ray from p along
// ω hits the proxy at x; the radiance is the map's texel in the direction x − capture.
// When the capture point cannot see x, that texel shows whatever hid x, so it is not
// used: the documented fallback is the map's mean radiance over its non-bright texels
// (a typical room surface, never a light), and such rays are counted. A distant map
// has no proxy: radiance depends on the direction only.
//
// The brightest texels (the sun, lamps, windows) are not left to rays, which would miss
// them: they are "bright texels", summed exactly as small area lights placed where the
// capture point sees them on the proxy, with a visibility ray each. Small clusters of
// them are the "dominant lights" that the lights representation evaluates per pixel.
#include <atomic>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <vector>

#include "lumar/base/color.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"

namespace lumar {

struct RadianceSettings {
  // Height of the working map (lat-long, box-filtered by solid angle from the loaded
  // map); 0 or a value that does not divide the map's height = full resolution.
  int map_height = 128;
  // Bright texels cover at most this share of the sphere and are at least
  // bright_min_ratio times the map's mean luminance. 0 = no bright texels (all by rays).
  double bright_fraction = 0.02;
  double bright_min_ratio = 2.0;
  // Dominant lights: connected clusters of bright texels no larger than this solid
  // angle, brightest first, at most max_lights (the GPU path takes 16). Larger clusters
  // are split at a higher threshold; an evenly bright one (a window, a courtyard's sky)
  // is cut into tiles of about this solid angle. What is left stays texel sums.
  int max_lights = 16;
  double max_light_solid_angle = 0.02;
};

// A texel integrated exactly: a small area light where the capture point sees it.
struct BrightTexel {
  glm::dvec3 radiance{0.0};
  double solid_angle = 0.0;   // seen from the capture point, sr
  glm::dvec3 direction{0.0};  // world, unit, from the capture point
  bool on_proxy = false;      // false: at infinity (distant map, or the ray escaped)
  glm::dvec3 position{0.0};   // on the proxy
  glm::dvec3 normal{0.0};     // proxy normal at position, facing the capture point
  int light = -1;             // dominant light it belongs to, -1 none
};

// A cluster of bright texels, evaluated as one point source at its power-weighted centre.
struct DominantLight {
  glm::dvec3 power{0.0};      // Σ L Ω over its texels, seen from the capture point
  glm::dvec3 direction{0.0};  // world, unit, from the capture point
  double solid_angle = 0.0;
  bool on_proxy = false;
  glm::dvec3 position{0.0}, normal{0.0};
  std::vector<int> texels;  // indices into bright_texels()
};

// A patch of the proxy at `position` (unit normal `normal`, facing the capture point)
// that subtends `solid_angle` from the capture point: its area, Ω_c |x−c|² / cos_c, with
// cos_c kept above 10⁻³ for a patch seen edge-on.
double patch_area(const glm::dvec3& capture, const glm::dvec3& position, const glm::dvec3& normal, double solid_angle);
// The same patch's solid angle seen from p, A cos_p / |x−p|², at most a hemisphere; 0 when
// p is behind it. `toward` (if given): the unit direction from p to it.
double patch_solid_angle_from(const glm::dvec3& p, const glm::dvec3& capture, const glm::dvec3& position,
                              const glm::dvec3& normal, double solid_angle, glm::dvec3* toward);

class RoomRadiance {
 public:
  // Distant map: radiance by direction only.
  RoomRadiance(const EnvironmentMap& map, const RadianceSettings& settings);
  // Map captured at map.capture_position inside the proxy (world coordinates, metres).
  RoomRadiance(const EnvironmentMap& map, const Mesh& proxy_world, const RadianceSettings& settings);
  // The same room relit: `like`'s proxy, bright texels and dominant lights (which texels
  // they are, where they are), with the radiance of `map` (its working-map size: the
  // full-size map is filtered to it). A lamp that goes out stays a light, of power 0, so
  // that volumes built before and after the change have the same layout and can be
  // blended (IrradianceVolume::blend).
  RoomRadiance(const RoomRadiance& like, const EnvironmentMap& map);
  ~RoomRadiance();
  RoomRadiance(const RoomRadiance&) = delete;
  RoomRadiance& operator=(const RoomRadiance&) = delete;

  bool distant() const { return !rays_; }
  const EnvironmentMap& working_map() const { return map_; }
  const RadianceSettings& settings() const { return settings_; }
  const Mesh& proxy() const { return proxy_; }
  const RayScene* ray_scene() const { return rays_.get(); }
  const std::vector<BrightTexel>& bright_texels() const { return bright_; }
  const std::vector<DominantLight>& lights() const { return lights_; }
  bool is_bright(int col, int row) const { return bright_index_[std::size_t(row) * map_.width + col] >= 0; }
  double bright_threshold() const { return threshold_; }  // luminance
  glm::dvec3 fallback_radiance() const { return fallback_; }

  struct Sample {
    glm::dvec3 radiance{0.0};
    double distance = std::numeric_limits<double>::infinity();  // to the hit; inf = escaped
    bool back_face = false;  // hit the back of a proxy triangle (p is inside geometry)
    bool fallback = false;   // the capture point cannot see the hit
  };
  // Radiance from direction w (unit) at p, with bright texels contributing nothing
  // (they are summed exactly by bright_irradiance). Nearest texel.
  Sample dim_radiance(const glm::dvec3& p, const glm::dvec3& w) const;
  // All radiance, bright texels included (for baselines that only cast rays).
  Sample radiance(const glm::dvec3& p, const glm::dvec3& w) const;

  // Solid angle of a bright texel (or light: pass its data) seen from p, and the unit
  // direction from p to it. 0 when p is behind its surface.
  double solid_angle_from(const glm::dvec3& p, bool on_proxy, const glm::dvec3& position, const glm::dvec3& normal,
                          const glm::dvec3& direction, double solid_angle, glm::dvec3* toward) const;
  // Whether p sees the point (or, off the proxy, the direction to infinity).
  bool sees(const glm::dvec3& p, bool on_proxy, const glm::dvec3& position, const glm::dvec3& direction) const;

  // Rays whose hit the capture point could not see (fallback used), since construction.
  std::uint64_t fallback_rays() const { return fallback_rays_.load(); }
  std::uint64_t traced_rays() const { return traced_rays_.load(); }

 private:
  void prepare(const EnvironmentMap& map);
  void set_fallback();
  Sample lookup(const glm::dvec3& p, const glm::dvec3& w, bool dim) const;

  RadianceSettings settings_;
  EnvironmentMap map_;
  Mesh proxy_;
  std::unique_ptr<RayScene> rays_;
  std::vector<BrightTexel> bright_;
  std::vector<int> bright_index_;  // per working-map texel: index into bright_ or -1
  std::vector<DominantLight> lights_;
  double threshold_ = std::numeric_limits<double>::infinity();
  glm::dvec3 fallback_{0.0};
  mutable std::atomic<std::uint64_t> fallback_rays_{0}, traced_rays_{0};
};

// The map box-filtered by solid angle to `height` rows (a divisor of its height; otherwise
// the map unchanged). Power (Σ L Ω) is preserved.
EnvironmentMap downsample_environment_map(const EnvironmentMap& map, int height);

}  // namespace lumar
