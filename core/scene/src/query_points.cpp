#include "lumar/scene/query_points.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "lumar/base/error.h"
#include "lumar/scene/scene.h"

namespace lumar {

namespace {

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    cell.erase(0, cell.find_first_not_of(" \t\r"));
    cell.erase(cell.find_last_not_of(" \t\r") + 1);
    cells.push_back(cell);
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();  // a trailing empty cell
  return cells;
}

}  // namespace

QueryPoints read_query_points(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(name + ": query file not found (or not a file); give a CSV with the header x,y,z,nx,ny,nz");
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) throw InputError(name + ": empty query file; expected the header x,y,z,nx,ny,nz");
  const std::vector<std::string> header = cells_of(line);
  const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  std::size_t column[6];
  for (int k = 0; k < 6; ++k) {
    const auto it = std::find(header.begin(), header.end(), names[k]);
    if (it == header.end())
      throw InputError(name + ": line 1: the header has no column '" + names[k] + "'; expected x,y,z,nx,ny,nz");
    column[k] = std::size_t(it - header.begin());
  }
  QueryPoints q;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = name + ": line " + std::to_string(number) + ": ";
    const std::vector<std::string> cells = cells_of(line);
    if (cells.size() != header.size())
      throw InputError(where + "expected " + std::to_string(header.size()) + " values like the header, got " +
                       std::to_string(cells.size()));
    double v[6];
    for (int k = 0; k < 6; ++k) {
      const std::string& cell = cells[column[k]];
      char* end = nullptr;
      v[k] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || !std::isfinite(v[k]))
        throw InputError(where + names[k] + " = '" + cell + "' is not a finite number");
    }
    const glm::dvec3 p(v[0], v[1], v[2]), n(v[3], v[4], v[5]);
    for (int a = 0; a < 3; ++a)
      if (std::abs(p[a]) > kMaxCoordinateM)
        throw InputError(where + "the point lies beyond ±10000 m of the origin on " + names[a]);
    const double length = glm::length(n);
    if (!(length > 1e-12) || !std::isfinite(length)) throw InputError(where + "the normal (nx, ny, nz) is zero");
    q.points.push_back(p);
    q.normals.push_back(n / length);
  }
  if (q.points.empty()) throw InputError(name + ": no points after the header; add x,y,z,nx,ny,nz rows");
  return q;
}

}  // namespace lumar
