// lumar irradiance: irradiance at query points (world position and normal) from a scene's
// room and map, or from a distant map alone.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/lighting/irradiance_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/scene/query_points.h"

namespace lumar::app {

namespace {

struct IrradianceOptions {
  std::string scene, envmap, query, out, method, cache;
  bool no_cache = false;
  int strata = 64;
};

void write_results(const std::string& path, const std::vector<glm::dvec3>& e) {
  std::string csv = "r,g,b\n";
  char buf[96];
  for (const glm::dvec3& v : e) {
    std::snprintf(buf, sizeof(buf), "%.9g,%.9g,%.9g\n", v.r, v.g, v.b);
    csv += buf;
  }
  write_file_atomically(path, csv);
}

void run(const IrradianceOptions& o) {
  if (o.scene.empty() == o.envmap.empty())
    throw InputError("lumar irradiance: give either --scene S or --envmap MAP.exr");
  refuse_output_over_input(o.out, {o.query, o.scene, o.envmap});
  const QueryPoints q = read_query_points(o.query);
  // A scene, or a distant map alone: either way its files are decoded once, here.
  Scene manifest;
  if (!o.scene.empty()) {
    manifest = load_scene(o.scene);
  } else {
    manifest.manifest = o.envmap;
    manifest.environment_map = o.envmap;
    manifest.distant_map = true;
  }
  const LoadedScene scene = load_scene_files(manifest);
  const std::string method = o.method.empty() ? manifest.lighting.method : o.method;
  std::vector<glm::dvec3> e;
  if (method == "reference") {
    const auto radiance = scene_radiance(scene, reference_radiance_settings());
    if (radiance->distant()) {
      e = texel_sum_irradiance(radiance->working_map(), q.normals);
    } else {
      e = reference_irradiance(*radiance, q.points, q.normals, o.strata);
      spdlog::info("reference: {} rays, {} used the fallback", radiance->traced_rays(), radiance->fallback_rays());
    }
  } else {
    bool loaded = false;
    const IrradianceVolume volume = scene_irradiance_volume(scene, method, !o.no_cache, o.cache, &loaded);
    const auto& st = volume.stats();
    spdlog::info(
        "irradiance volume ({}): {} {} probes ({} moved, {} disabled), {} cells ({} refined), {:.0f} ms, "
        "{} rays, {} fallback",
        volume.settings().describe(), loaded ? "loaded" : "built", st.probes, st.moved, st.disabled, st.cells,
        st.refined_cells, st.build_ms, st.rays, st.fallback_rays);
    for (std::size_t i = 0; i < q.points.size(); ++i) e.push_back(volume.evaluate(q.points[i], q.normals[i]));
  }
  write_results(o.out, e);
}

}  // namespace

void register_irradiance(CLI::App& app) {
  auto o = std::make_shared<IrradianceOptions>();
  auto* cmd = app.add_subcommand("irradiance", "Irradiance at query points from the scene's room and map");
  auto* scene = cmd->add_option("--scene", o->scene, "Scene manifest (scene.json)");
  cmd->add_option("--envmap", o->envmap, "A distant HDR map alone, instead of --scene")->excludes(scene);
  cmd->add_option("--query", o->query, "CSV with header and columns x,y,z,nx,ny,nz")->required();
  cmd->add_option("--out", o->out, "Output CSV: header r,g,b, one line per query")->required();
  cmd->add_option("--method", o->method,
                  "reference, volume (default), sh9, octahedral, lights or greger2004 (the scene's lighting.method "
                  "when not given)");
  cmd->add_option("--cache", o->cache, "Volume cache folder (default $XDG_CACHE_HOME/lumar)");
  cmd->add_flag("--no-cache", o->no_cache, "Build the volume without reading or writing the cache");
  cmd->add_option("--strata", o->strata, "Reference: strata per axis (strata^2 rays per query)")
      ->check(CLI::Range(2, 1024))
      ->capture_default_str();
  add_action(cmd, [o] { run(*o); });
}

}  // namespace lumar::app
