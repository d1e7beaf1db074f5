// The irradiance volume on disk: a versioned binary file, written atomically, and a cache
// of such files keyed by a hash of everything the volume depends on.
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <fstream>

#include "binary_file.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar {

namespace {

// Version 6: a distant map's evenly bright opening (a courtyard's sky) is tiled into
// lights, as a room's window was. Version 5: probes on a proxy surface (a lattice node on
// the floor) are moved off it. Version 4: the shadow maps' resolution is a setting.
// Version 3: probes inside geometry are found with back faces winning ties between
// coincident faces (RayScene::intersect).
constexpr char kMagic[8] = {'L', 'U', 'M', 'A', 'R', 'I', 'V', '6'};

// Settings as plain numbers, in a fixed order (the file and the hash use it).
template <class F>
void visit_settings(VolumeSettings& s, F&& f) {
  int storage = int(s.storage), sep = s.separate_lights, refine = s.refine, vis = s.visibility;
  f(storage), f(s.octahedral_resolution), f(sep), f(s.rays_per_probe), f(s.depth_resolution), f(s.spacing);
  f(refine), f(vis), f(s.radiance.map_height), f(s.radiance.bright_fraction), f(s.radiance.bright_min_ratio);
  f(s.radiance.max_lights), f(s.radiance.max_light_solid_angle), f(s.shadow_map_resolution);
  s.storage = ProbeStorage(storage), s.separate_lights = sep, s.refine = refine, s.visibility = vis;
}

}  // namespace

void IrradianceVolume::save(const std::filesystem::path& file) const {
  const std::string name = file.string();
  OutputFile output(file);
  {
    BinaryWriter w{std::ofstream(output.temporary(), std::ios::binary | std::ios::trunc)};
    if (!w.out) throw RuntimeError(name + ": cannot write the irradiance volume; check the folder's permissions");
    w.out.write(kMagic, sizeof(kMagic));
    VolumeSettings s = settings_;
    visit_settings(s, [&](auto& v) { w.value(v); });
    w.value(stats_);
    w.value(std::uint8_t(distant_));
    w.value(box_min), w.value(box_max), w.value(cells), w.value(cell_size);
    w.vector(refined), w.vector(node_probe), w.vector(node_weight), w.vector(probes);
    w.value(irradiance_n), w.value(depth_n), w.value(atlas_columns);
    w.vector(irradiance_atlas), w.vector(depth_atlas), w.vector(sh), w.vector(lights), w.vector(light_visibility);
    w.value(capture_position), w.value(normal_bias);
    w.value(shadow_n), w.vector(light_shadow);
    w.out.close();
    if (!w.out) throw RuntimeError(name + ": cannot write the irradiance volume (disk full?)");
  }
  output.commit();
}

IrradianceVolume IrradianceVolume::load(const std::filesystem::path& file) {
  BinaryReader r(file, "irradiance volume", kMagic);
  IrradianceVolume v;
  visit_settings(v.settings_, [&](auto& x) { r.value(x); });
  r.value(v.stats_);
  std::uint8_t distant = 0;
  r.value(distant);
  v.distant_ = distant != 0;
  r.value(v.box_min), r.value(v.box_max), r.value(v.cells), r.value(v.cell_size);
  r.vector(v.refined), r.vector(v.node_probe), r.vector(v.node_weight), r.vector(v.probes);
  r.value(v.irradiance_n), r.value(v.depth_n), r.value(v.atlas_columns);
  r.vector(v.irradiance_atlas), r.vector(v.depth_atlas), r.vector(v.sh), r.vector(v.lights),
      r.vector(v.light_visibility);
  r.value(v.capture_position), r.value(v.normal_bias);
  r.value(v.shadow_n), r.vector(v.light_shadow);
  // Sizes must agree, or evaluate would read out of bounds.
  const std::size_t P = v.probes.size();
  const std::size_t F = std::size_t(2 * v.cells.x + 1) * (2 * v.cells.y + 1) * (2 * v.cells.z + 1);
  bool ok = P > 0 && v.atlas_columns > 0 && v.node_probe.size() == v.node_weight.size() &&
            v.light_visibility.size() == P * v.lights.size() && v.shadow_n >= 0 && v.shadow_n <= 4096 &&
            v.light_shadow.size() == std::size_t(v.shadow_n) * std::size_t(v.shadow_n) * v.lights.size();
  if (!v.distant_)
    ok = ok && v.node_probe.size() == F && v.refined.size() == std::size_t(v.cells.x) * v.cells.y * v.cells.z;
  if (v.settings_.storage != ProbeStorage::sh9)
    ok = ok &&
         v.irradiance_atlas.size() == std::size_t(v.atlas_width(v.irradiance_n)) * v.atlas_height(v.irradiance_n) * 3;
  if (v.settings_.storage != ProbeStorage::octahedral) ok = ok && v.sh.size() == P * 27;
  if (!v.distant_)
    ok = ok && v.depth_atlas.size() == std::size_t(v.atlas_width(v.depth_n)) * v.atlas_height(v.depth_n) * 2;
  for (const auto& node : v.node_probe)
    for (int k : node) ok = ok && k < int(P);
  if (!ok) r.fail("inconsistent");
  return v;
}

std::filesystem::path default_irradiance_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "lumar";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "lumar";
  return std::filesystem::temp_directory_path() / "lumar-cache";
}

std::uint64_t irradiance_volume_key(const RoomRadiance& radiance, const glm::dvec3& box_min, const glm::dvec3& box_max,
                                    const VolumeSettings& settings) {
  Fnv h;
  h.bytes(kMagic, sizeof(kMagic));
  const EnvironmentMap& m = radiance.working_map();
  h.value(m.width), h.value(m.height);
  h.bytes(m.rgb.data(), m.rgb.size() * sizeof(float));
  h.value(m.capture_position), h.value(m.azimuth_offset_deg);
  h.value(std::uint8_t(radiance.distant()));
  const Mesh& proxy = radiance.proxy();
  h.bytes(proxy.positions.data(), proxy.positions.size() * sizeof(glm::vec3));
  h.bytes(proxy.indices.data(), proxy.indices.size() * sizeof(std::uint32_t));
  h.value(box_min), h.value(box_max);
  VolumeSettings s = settings;
  visit_settings(s, [&](auto& v) { h.value(v); });
  return h.h;
}

IrradianceVolume cached_irradiance_volume(const RoomRadiance& radiance, const glm::dvec3& box_min,
                                          const glm::dvec3& box_max, const VolumeSettings& settings,
                                          std::filesystem::path cache_dir, bool* loaded) {
  if (cache_dir.empty()) cache_dir = default_irradiance_cache_dir();
  char name[64];
  std::snprintf(name, sizeof(name), "irradiance-%016llx.bin",
                static_cast<unsigned long long>(irradiance_volume_key(radiance, box_min, box_max, settings)));
  const std::filesystem::path file = cache_dir / name;
  if (loaded) *loaded = false;
  std::error_code ec;
  if (std::filesystem::is_regular_file(file, ec)) {
    try {
      IrradianceVolume v = IrradianceVolume::load(file);
      if (loaded) *loaded = true;
      spdlog::debug("irradiance volume loaded from {}", file.string());
      return v;
    } catch (const InputError& e) {
      spdlog::warn("{} (rebuilding)", e.what());
    }
  }
  IrradianceVolume v = radiance.distant() ? IrradianceVolume::build_distant(radiance, settings)
                                          : IrradianceVolume::build(radiance, box_min, box_max, settings);
  try {
    std::filesystem::create_directories(cache_dir);
    v.save(file);
    // Said once, when the file is made: later runs load it without a word.
    spdlog::info(
        "irradiance volume built in {:.1f} s and cached as {} (later runs load it; XDG_CACHE_HOME moves the "
        "cache, --no-cache skips it)",
        v.stats().build_ms * 1e-3, file.string());
  } catch (const std::exception& e) {
    spdlog::warn("irradiance cache {}: {} (continuing without caching)", cache_dir.string(), e.what());
  }
  return v;
}

}  // namespace lumar
