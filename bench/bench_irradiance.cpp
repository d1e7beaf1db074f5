// Irradiance representations: error against the reference, build time and memory, for
// each representation and resolution, with the 2004 configuration (64 rays per probe,
// no bright texels, bilevel grid, no visibility) as the baseline in the same run.
//  - room: the sample scene (data/scenes/room), 60 points across the movement box with
//    random normals, against the brute-force reference (full-resolution map, exact
//    bright texels, 32x32 stratified rays);
//  - distant: the four shared real maps, 500 random normals, against the texel sum.
// Writes bench/results/irradiance_{room,distant,memory}.{json,png} and
// docs/irradiance_error_vs_cost.png (room: error against build time).
#include <chrono>
#include <cstdio>
#include <random>

#include "bench_report.h"
#include "lumar/base/latlong.h"
#include "lumar/lighting/irradiance_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/irradiance_volume.h"
#include "test_geometry.h"

using namespace lumar;

namespace {

struct Config {
  std::string name;
  VolumeSettings settings;
};

std::vector<Config> configs() {
  std::vector<Config> out;
  out.push_back({"greger2004", volume_settings_for("greger2004")});
  out.push_back({"sh9", volume_settings_for("sh9")});
  for (int n : {8, 16, 24}) {
    VolumeSettings s = volume_settings_for("octahedral");
    s.octahedral_resolution = n;
    out.push_back({"oct" + std::to_string(n), s});
  }
  out.push_back({"sh9+lights", volume_settings_for("lights")});
  for (int n : {6, 8, 12, 16}) {
    VolumeSettings s = volume_settings_for("volume");
    s.octahedral_resolution = n;
    out.push_back({"sh9+oct" + std::to_string(n) + "+lights" + (n == 12 ? " (default)" : ""), s});
  }
  return out;
}

double mean_error_percent(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& ref) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    sum += std::abs(luminance(a[i]) - luminance(ref[i])) / std::max(luminance(ref[i]), 1e-12);
  return 100.0 * sum / double(a.size());
}

}  // namespace

int main() {
  const std::filesystem::path source(LUMAR_SOURCE_DIR);
  const LoadedScene loaded = load_scene_files(source / "data/scenes/room/scene.json");
  const Scene& scene = loaded.manifest;

  // Room: reference points.
  const auto reference_room = scene_radiance(loaded, reference_radiance_settings());
  std::mt19937 rng(17);
  std::vector<glm::dvec3> points, normals = lumar::test::random_normals(60, 5);
  for (int i = 0; i < 60; ++i) {
    glm::dvec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = std::uniform_real_distribution<double>(scene.movement_min[a], scene.movement_max[a] + 1e-9)(rng);
    p.y = std::max(p.y, 0.02);
    points.push_back(p);
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto reference = reference_irradiance(*reference_room, points, normals, 32);
  const double reference_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / double(points.size());

  const auto report = [](const char* name, const char* title, const char* error_label) {
    bench::BenchReport r;
    r.name = name, r.title = title, r.baseline = "greger2004", r.error_label = error_label;
    return r;
  };
  bench::BenchReport room = report("irradiance_room", "Irradiance volume, sample room: error vs build time",
                                   "mean relative irradiance error vs reference (%)");
  bench::BenchReport memory = report("irradiance_memory", "Irradiance volume, sample room: error vs memory",
                                     "mean relative irradiance error vs reference (%)");
  memory.x_label = "volume size (KiB)";
  room.highlight = memory.highlight = "sh9+oct12+lights (default)";
  room.note = memory.note = "60 points x random normals in the movement box; reference " +
                            std::to_string(int(reference_ms)) + " ms per point";
  for (const Config& c : configs()) {
    const auto radiance = scene_radiance(loaded, c.settings.radiance);
    const IrradianceVolume v = IrradianceVolume::build(*radiance, scene.movement_min, scene.movement_max, c.settings);
    std::vector<glm::dvec3> e;
    for (std::size_t i = 0; i < points.size(); ++i) e.push_back(v.evaluate(points[i], normals[i]));
    const double err = mean_error_percent(e, reference);
    bench::BenchEntry entry;
    entry.name = c.name, entry.time_ms = v.stats().build_ms, entry.error = err;
    room.entries.push_back(entry);
    entry.x = double(v.stats().bytes) / 1024.0;
    memory.entries.push_back(entry);
    std::printf("room  %-28s %5d probes  build %7.1f ms  %8.1f KiB  error %6.2f %%\n", c.name.c_str(), v.stats().probes,
                v.stats().build_ms, double(v.stats().bytes) / 1024.0, err);
  }

  // Distant maps.
  bench::BenchReport distant = report("irradiance_distant", "Distant maps: error vs build time",
                                      "mean relative irradiance error vs texel sum, 4 maps (%)");
  distant.highlight = room.highlight;
  const std::vector<glm::dvec3> dn = lumar::test::random_normals(500, 9);
  std::vector<EnvironmentMap> maps;
  std::vector<std::vector<glm::dvec3>> refs;
  for (const char* name : {"city", "courtyard", "interior", "studio"}) {
    maps.push_back(load_environment_map(source.parent_path() / "shared/data/envmaps" / (std::string(name) + ".exr")));
    refs.push_back(texel_sum_irradiance(maps.back(), dn));
  }
  for (const Config& c : configs()) {
    double err = 0.0, ms = 0.0;
    for (std::size_t m = 0; m < maps.size(); ++m) {
      RoomRadiance radiance(maps[m], c.settings.radiance);
      const IrradianceVolume v = IrradianceVolume::build_distant(radiance, c.settings);
      std::vector<glm::dvec3> e;
      for (const glm::dvec3& n : dn) e.push_back(v.evaluate({0, 0, 0}, n));
      err += mean_error_percent(e, refs[m]) / double(maps.size());
      ms += v.stats().build_ms / double(maps.size());
    }
    bench::BenchEntry entry;
    entry.name = c.name, entry.time_ms = ms, entry.error = err;
    distant.entries.push_back(entry);
    std::printf("distant %-28s build %7.1f ms  error %6.2f %%\n", c.name.c_str(), ms, err);
  }

  for (auto* r : {&room, &memory, &distant}) {
    r->compute_ratios();
    r->save(bench::results_dir());
  }
  room.write_chart(source / "docs/irradiance_error_vs_cost.png");
  memory.write_chart(source / "docs/irradiance_error_vs_memory.png");
  return 0;
}
