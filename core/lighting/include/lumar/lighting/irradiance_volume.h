#pragma once
// The irradiance volume (docs/irradiance.md): probes on a grid over the scene's movement
// box, each with a directional irradiance representation, interpolated with DDGI-style
// visibility (per-probe distance moments, Chebyshev test) so light does not leak through
// walls. After Greger et al. 1998 (grid of directional samples), Ramamoorthi & Hanrahan
// 2001 (SH9) and Majercik et al. 2019 (octahedral probes, moments).
//
// Grid: a uniform grid of cells no larger than `spacing` (at least 2 per axis), then one
// adaptive level: cells near proxy geometry split into 8, so neighbours differ at most
// 2:1. Nodes of split cells that lie on the face or edge of an unsplit cell are not
// probes but the linear blend of that face's corners, which keeps interpolation
// continuous across cells of different size. Probes inside geometry (most of their rays
// hit back faces) or touching it are moved a little; if no nearby spot works, disabled.
//
// The GPU evaluates the same arithmetic (core/render/src/irradiance_textures.cpp).
#include <array>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "lumar/lighting/room_radiance.h"

namespace lumar {

// sh9: nine coefficients. octahedral: irradiance at N x N directions, bilinear.
// sh9_octahedral: SH9 plus an N x N octahedral map of what SH9 misses (the residual is
// small and smooth, so a coarse map corrects it well).
enum class ProbeStorage : int { sh9 = 0, octahedral = 1, sh9_octahedral = 2 };

struct VolumeSettings {
  ProbeStorage storage = ProbeStorage::sh9_octahedral;
  int octahedral_resolution = 12;   // texels per side of the octahedral map
  bool separate_lights = true;      // dominant lights evaluated per pixel (shadow maps), not stored
  int shadow_map_resolution = 128;  // texels per side of each exact light's shadow map: ~1.4 degrees at 128
  int rays_per_probe = 512;         // for the radiance below the bright threshold
  int depth_resolution = 8;         // distance-moment texels per side
  double spacing = 0.3;             // largest cell edge of the uniform level, metres
  bool refine = true;               // one adaptive level near geometry
  bool visibility = true;           // Chebyshev and back-face weights
  RadianceSettings radiance;        // bright texels and dominant lights

  std::string describe() const;
};

// Named settings: "volume" (the default: SH9 + 12x12 correction + up to 16 lights), "sh9",
// "octahedral" (16x16, lights baked in), "lights" (SH9 + up to 16 lights),
// "greger2004" (64 rays per probe, no bright texels, no visibility, bilevel grid).
// Throws InputError for another name.
VolumeSettings volume_settings_for(const std::string& method);

// The most exact lights the renderer's shader evaluates (its arrays' size).
inline constexpr int kMaxExactLights = 16;

// A dominant light as the volume evaluates it at a shading point.
struct VolumeLight {
  glm::dvec3 radiance{0.0};  // mean radiance (power / solid angle from the capture point)
  double solid_angle = 0.0;
  glm::dvec3 direction{0.0};
  bool on_proxy = false;
  glm::dvec3 position{0.0}, normal{0.0};
};

// The irradiance light l gives at world point p with unit normal n before anything blocks
// it (0 behind the point or the light), and the unit direction it comes from.
glm::dvec3 light_irradiance(const VolumeLight& l, const glm::dvec3& capture, const glm::dvec3& p, const glm::dvec3& n,
                            glm::dvec3* toward);

class IrradianceVolume {
 public:
  // One probe, no grid: a distant map (position is ignored by evaluate).
  static IrradianceVolume build_distant(const RoomRadiance& radiance, const VolumeSettings& settings);
  // Probes over [box_min, box_max] in the room.
  static IrradianceVolume build(const RoomRadiance& radiance, const glm::dvec3& box_min, const glm::dvec3& box_max,
                                const VolumeSettings& settings);

  // (1 - t) from + t to: irradiance is linear in the light, so this is the volume of the
  // blended light. Both must share one layout (built over one box with one settings from
  // RoomRadiance relit from one another); RuntimeError otherwise.
  static IrradianceVolume blend(const IrradianceVolume& from, const IrradianceVolume& to, double t);

  // Irradiance at world point p with unit normal n.
  glm::dvec3 evaluate(const glm::dvec3& p, const glm::dvec3& n) const { return evaluate(p, n, n, 1.0, 1.0); }
  // The same in two parts: the probes' light (the room but the exact lights) at normal n
  // times rest_scale, plus the exact lights at normal n_lights times lights_scale. An
  // object's own occlusion darkens the two differently (self_occlusion.h for the rest,
  // light_self_shadow.h for the lights).
  glm::dvec3 evaluate(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& n_lights, double rest_scale,
                      double lights_scale) const;

  // Disk format (binary, versioned); save writes atomically. load throws InputError.
  void save(const std::filesystem::path& file) const;
  static IrradianceVolume load(const std::filesystem::path& file);

  struct Stats {
    int probes = 0, disabled = 0, moved = 0, cells = 0, refined_cells = 0;
    std::uint64_t rays = 0, fallback_rays = 0;
    double build_ms = 0.0;
    std::size_t bytes = 0;  // GPU-side data: atlases, SH, visibility, node table
  };
  const Stats& stats() const { return stats_; }
  const VolumeSettings& settings() const { return settings_; }
  bool distant() const { return distant_; }

  // The data the GPU uploads (and evaluate reads).
  glm::dvec3 box_min{0.0}, box_max{0.0};
  glm::ivec3 cells{1};  // uniform level
  glm::dvec3 cell_size{1.0};
  std::vector<std::uint8_t> refined;  // per cell, x fastest
  // Per node of the fine lattice (2 cells + 1 per axis, x fastest): 4 (probe, weight)
  // pairs; probe -1 = unused.
  std::vector<std::array<int, 4>> node_probe;
  std::vector<std::array<float, 4>> node_weight;
  std::vector<glm::vec4> probes;  // xyz position, w = 1 enabled / 0 disabled
  int irradiance_n = 0, depth_n = 0, atlas_columns = 1;
  std::vector<float> irradiance_atlas;  // RGB, (n+2)^2 block per probe
  std::vector<float> depth_atlas;       // RG: mean distance, mean squared distance
  std::vector<float> sh;                // 27 floats per probe (SH9 storage)
  std::vector<VolumeLight> lights;
  std::vector<float> light_visibility;  // lights.size() per probe
  // Per light on the proxy: shadow_n x shadow_n octahedral map of the distance from the
  // light to the nearest surface (no border; lights off the proxy leave theirs unused).
  // A lamp's shadow edge is sharper than the probe spacing, so per-probe visibility
  // smeared it over a cell; the map keeps it sharp.
  int shadow_n = 0;
  std::vector<float> light_shadow;
  glm::dvec3 capture_position{0.0};
  double normal_bias = 0.0;  // metres, along n before the Chebyshev test

  int atlas_width(int n) const { return atlas_columns * (n + 2); }
  int atlas_height(int n) const;
  // 0..1: how much of light l reaches p (bilinear blend of four depth tests).
  double light_shadow_visibility(std::size_t l, const glm::dvec3& p) const;

 private:
  VolumeSettings settings_;
  Stats stats_;
  bool distant_ = false;
};

// Builds the volume, or loads it from `cache_dir` when a file with the same inputs'
// hash (working map pixels, capture point, proxy, box and settings) is there. An empty
// cache_dir means $XDG_CACHE_HOME/lumar (else ~/.cache/lumar). `loaded` says which.
IrradianceVolume cached_irradiance_volume(const RoomRadiance& radiance, const glm::dvec3& box_min,
                                          const glm::dvec3& box_max, const VolumeSettings& settings,
                                          std::filesystem::path cache_dir = {}, bool* loaded = nullptr);
std::filesystem::path default_irradiance_cache_dir();
// 64-bit hash of everything the volume depends on.
std::uint64_t irradiance_volume_key(const RoomRadiance& radiance, const glm::dvec3& box_min, const glm::dvec3& box_max,
                                    const VolumeSettings& settings);

}  // namespace lumar
