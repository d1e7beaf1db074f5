// lumar shadows: how much the scene's virtual objects (in their manifest poses) darken
// given points on real surfaces: E_with / E_without per RGB channel (docs/shadows.md).
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

namespace lumar::app {

namespace {

struct ShadowsOptions {
  std::string scene, query, out, method = "lines";
};

// IN.csv: a header, then x,y,z,nx,ny,nz per line (normals need not be unit).
void read_query(const std::filesystem::path& path, std::vector<glm::vec3>& positions, std::vector<glm::vec3>& normals) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(path.string() + ": query file not found; check the path");
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the query file for reading");
  std::string line;
  if (!std::getline(in, line) || line.find('x') == std::string::npos)
    throw InputError(path.string() + ": line 1: expected the header x,y,z,nx,ny,nz");
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::stringstream ss(line);
    std::string cell;
    double v[6];
    int n = 0;
    while (std::getline(ss, cell, ',')) {
      std::size_t used = 0;
      double d = 0;
      try {
        d = std::stod(cell, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || cell.find_first_not_of(" \t", used) != std::string::npos || !std::isfinite(d) || n >= 6) {
        n = -1;
        break;
      }
      v[n++] = d;
    }
    if (n != 6)
      throw InputError(path.string() + ": line " + std::to_string(number) +
                       ": expected 6 finite numbers x,y,z,nx,ny,nz separated by commas");
    const glm::dvec3 nrm(v[3], v[4], v[5]);
    if (glm::length(nrm) < 1e-12)
      throw InputError(path.string() + ": line " + std::to_string(number) + ": the normal must not be zero");
    positions.emplace_back(v[0], v[1], v[2]);
    normals.push_back(glm::vec3(glm::normalize(nrm)));
  }
  if (positions.empty()) throw InputError(path.string() + ": no points after the header; add x,y,z,nx,ny,nz rows");
}

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
  add_action(cmd, [o] {
    const ShadowMethod method = parse_shadow_method(o->method);
    LoadedScene scene = load_scene_files(std::filesystem::path(o->scene));
    std::vector<glm::vec3> positions, normals;
    read_query(o->query, positions, normals);
    const ShadowScene shadows(std::move(scene));
    const auto attenuation = shadow_attenuation(shadows, positions, normals, method);
    write_result(o->out, attenuation);
    spdlog::info("shadows ({}): {} points, {} occluder(s) -> {}", o->method, positions.size(), shadows.objects().size(),
                 o->out);
  });
}

}  // namespace lumar::app
