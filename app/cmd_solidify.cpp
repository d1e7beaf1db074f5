// lumar solidify: a closed solid around an open scan (lumar/solid/solid_wrap.h), written as
// PLY, with the open edges before and after. Prepares a model once; docs/solid.md.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/solid/solid_wrap.h"

namespace lumar::app {

namespace {

struct SolidifyOptions {
  std::string in, out;
  SolidWrapSettings wrap;
};

void run_solidify(const SolidifyOptions& o) {
  if (!o.out.ends_with(".ply")) throw InputError("solidify: --out " + o.out + ": give a .ply file");
  refuse_output_over_input(o.out, {o.in});
  const auto start = std::chrono::steady_clock::now();
  const Mesh mesh = load_mesh(o.in);
  SolidWrapReport report;
  const Mesh solid =
      wrap_solid(mesh, o.wrap, &report, [](const std::string& stage) { spdlog::warn("solidify: {}", stage); });
  save_mesh_ply(o.out, solid);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "%s: %zu triangles, %zu open edges -> %s: %zu triangles (%zu as wrapped, %zu inside points), %zu open "
      "edges, %.1f s\n",
      o.in.c_str(), mesh.triangle_count(), open_edge_count(mesh), o.out.c_str(), solid.triangle_count(),
      report.wrapped_triangles, report.inside_points, open_edge_count(solid), seconds);
}

}  // namespace

void register_solidify(CLI::App& app) {
  auto o = std::make_shared<SolidifyOptions>();
  auto* cmd = app.add_subcommand("solidify",
                                 "Wrap an open scan (cracks, holes) in a closed solid of about its shape, as PLY "
                                 "(docs/solid.md)");
  cmd->add_option("MESH", o->in, "The model: OBJ, PLY or glTF")->required();
  cmd->add_option("--out", o->out, "The closed model to write (.ply)")->required();
  cmd->add_option("--alpha", o->wrap.alpha,
                  "Gaps narrower than about this share of the model's diagonal are closed; smaller keeps finer "
                  "detail and takes longer")
      ->capture_default_str();
  cmd->add_option("--offset", o->wrap.offset, "How far outside the model the surface lies, as a share of its diagonal")
      ->capture_default_str();
  cmd->add_option("--triangles", o->wrap.max_triangles, "Simplify to at most this many triangles (0: as wrapped)")
      ->capture_default_str();
  add_action(cmd, [o] { run_solidify(*o); });
}

}  // namespace lumar::app
