// lumar shadows: how much the scene's virtual objects (in their manifest poses) darken
// given points on real surfaces: E_with / E_without per RGB channel, or with --bounce
// (E_with + E_bounce) / E_without, the light they reflect included (docs/shadows.md).
#include <spdlog/spdlog.h>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/scene/query_points.h"

namespace lumar::app {

namespace {

struct ShadowsOptions {
  std::string scene, query, out, method = "lines";
  bool bounce = false;
  int bounce_clusters = BounceSettings{}.clusters;
};

void write_result(const std::filesystem::path& path, const std::vector<glm::vec3>& attenuation) {
  std::string csv = "r,g,b\n";
  char buf[96];
  for (const glm::vec3& a : attenuation) {
    std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.6f\n", a.r, a.g, a.b);
    csv += buf;
  }
  write_file_atomically(path, csv);
}

}  // namespace

void register_shadows(CLI::App& app) {
  auto o = std::make_shared<ShadowsOptions>();
  auto* cmd = app.add_subcommand("shadows", "Shadow attenuation of points on real surfaces by the scene's objects");
  cmd->add_option("--scene", o->scene, "Scene manifest (scene.json); its objects in their poses are the occluders")
      ->required();
  cmd->add_option("--query", o->query, "CSV with a header and x,y,z,nx,ny,nz per point")->required();
  cmd->add_option("--out", o->out, "CSV to write: a header and r,g,b = E_with / E_without per point")->required();
  cmd->add_option("--method", o->method, "lines (default), reference (brute force) or sphere (the 2004 method)")
      ->capture_default_str();
  cmd->add_flag(
      "--bounce", o->bounce,
      "Add the light the objects reflect onto the points: (E_with + E_bounce) / E_without, which may exceed 1 "
      "(lines or reference)");
  cmd->add_option("--bounce-clusters", o->bounce_clusters, "lines --bounce: surface clusters per object")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  add_action(cmd, [o] {
    const ShadowMethod method = parse_shadow_method(o->method);
    ShadowMethodOptions options;
    options.bounce = o->bounce;
    options.bounce_settings.clusters = o->bounce_clusters;
    check_shadow_options(method, options);  // before the scene's warnings
    LoadedScene scene = load_scene_files(std::filesystem::path(o->scene));
    refuse_output_over_input(o->out, {o->query, o->scene});
    const QueryPoints q = read_query_points(o->query);
    const std::vector<glm::vec3> positions(q.points.begin(), q.points.end()),
        normals(q.normals.begin(), q.normals.end());
    const ShadowScene shadows(std::move(scene));
    const auto attenuation = shadow_attenuation(shadows, positions, normals, method, options);
    write_result(o->out, attenuation);
    spdlog::info("shadows ({}{}): {} points, {} occluder(s) -> {}", o->method, o->bounce ? ", with bounce" : "",
                 positions.size(), shadows.objects().size(), o->out);
  });
}

}  // namespace lumar::app
