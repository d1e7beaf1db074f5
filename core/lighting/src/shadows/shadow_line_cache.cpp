#include "lumar/lighting/shadows/shadow_line_cache.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "binary_file.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar {

namespace {
constexpr char kMagic[8] = {'L', 'U', 'M', 'A', 'R', 'S', 'L', '1'};
}  // namespace

void save_shadow_lines(const ShadowLines& l, const std::filesystem::path& file) {
  const std::string name = file.string();
  OutputFile output(file);
  {
    BinaryWriter w{std::ofstream(output.temporary(), std::ios::binary | std::ios::trunc)};
    if (!w.out) throw RuntimeError(name + ": cannot write the shadow lines; check the folder's permissions");
    w.out.write(kMagic, sizeof(kMagic));
    w.value(std::uint8_t(l.distant)), w.value(l.patch_count), w.value(std::uint64_t(l.candidate_lines));
    w.vector(l.origins), w.vector(l.samples), w.vector(l.lines), w.vector(l.sample_first), w.vector(l.unshadowed);
    w.vector(l.dropped);
    w.vector(l.grids.grids), w.vector(l.grids.order), w.vector(l.grids.bucket_first);
    w.out.close();
    if (!w.out) throw RuntimeError(name + ": cannot write the shadow lines (disk full?)");
  }
  output.commit();
}

ShadowLines load_shadow_lines(const std::filesystem::path& file) {
  BinaryReader r(file, "shadow lines", kMagic);
  ShadowLines l;
  std::uint8_t distant = 0;
  std::uint64_t candidates = 0;
  r.value(distant), r.value(l.patch_count), r.value(candidates);
  l.distant = distant != 0;
  l.candidate_lines = std::size_t(candidates);
  r.vector(l.origins), r.vector(l.samples), r.vector(l.lines), r.vector(l.sample_first), r.vector(l.unshadowed);
  r.vector(l.dropped);
  r.vector(l.grids.grids), r.vector(l.grids.order), r.vector(l.grids.bucket_first);
  // Every index in range, or the culling would read out of bounds.
  const std::size_t receivers = l.origins.size(), samples = l.samples.size();
  bool ok = l.unshadowed.size() == receivers && l.dropped.size() == receivers && l.sample_first.size() == samples + 1 &&
            l.grids.order.size() == receivers && !l.grids.bucket_first.empty() &&
            l.sample_first.back() == l.lines.size();
  for (std::size_t s = 0; ok && s < samples; ++s) ok = l.sample_first[s] <= l.sample_first[s + 1];
  for (std::size_t i = 0; ok && i < l.lines.size(); ++i)
    ok = l.lines[i].receiver < receivers && l.lines[i].sample < samples;
  for (std::size_t i = 0; ok && i < receivers; ++i) ok = l.grids.order[i] < receivers;
  for (std::size_t b = 0; ok && b + 1 < l.grids.bucket_first.size(); ++b)
    ok = l.grids.bucket_first[b] <= l.grids.bucket_first[b + 1] && l.grids.bucket_first[b + 1] <= receivers;
  for (const ReceiverGrid& g : l.grids.grids)
    ok = ok && g.nu > 0 && g.nv > 0 &&
         std::size_t(g.first_bucket) + std::size_t(g.nu) * std::size_t(g.nv) < l.grids.bucket_first.size();
  if (!ok) r.fail("inconsistent");
  return l;
}

std::uint64_t shadow_lines_key(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               const Emitters& emitters, const Mesh& proxy_world, const ShadowLineOptions& options) {
  Fnv h;
  h.bytes(kMagic, sizeof(kMagic));
  h.vector(positions), h.vector(normals);
  h.value(std::uint8_t(emitters.distant)), h.vector(emitters.samples), h.vector(emitters.patches);
  h.vector(proxy_world.positions), h.vector(proxy_world.indices);
  h.value(options.max_dropped_fraction);
  return h.h;
}

ShadowLines cached_shadow_lines(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                                const Emitters& emitters, const RayScene& proxy, const Mesh& proxy_world,
                                const ShadowLineOptions& options, std::filesystem::path cache_dir, bool* loaded) {
  if (cache_dir.empty()) cache_dir = default_irradiance_cache_dir();
  char name[64];
  std::snprintf(name, sizeof(name), "shadow-lines-%016llx.bin",
                static_cast<unsigned long long>(shadow_lines_key(positions, normals, emitters, proxy_world, options)));
  const std::filesystem::path file = cache_dir / name;
  if (loaded) *loaded = false;
  std::error_code ec;
  if (std::filesystem::is_regular_file(file, ec)) {
    try {
      ShadowLines l = load_shadow_lines(file);
      if (loaded) *loaded = true;
      spdlog::debug("shadow lines loaded from {}", file.string());
      return l;
    } catch (const InputError& e) {
      spdlog::warn("{} (rebuilding)", e.what());
    }
  }
  ShadowLines l = build_shadow_lines(positions, normals, emitters, proxy, options);
  try {
    std::filesystem::create_directories(cache_dir);
    save_shadow_lines(l, file);
    spdlog::debug("shadow lines cached as {}", file.string());
  } catch (const std::exception& e) {
    spdlog::warn("shadow line cache {}: {} (continuing without caching)", cache_dir.string(), e.what());
  }
  return l;
}

}  // namespace lumar
