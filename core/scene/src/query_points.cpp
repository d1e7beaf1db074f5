#include "lumar/scene/query_points.h"

#include <cmath>
#include <string>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/scene/scene.h"

namespace lumar {

QueryPoints read_query_points(const std::filesystem::path& path) {
  QueryPoints q;
  const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  csv::for_each_row(path, read_input_file(path, "query file"), {{"x", "y", "z", "nx", "ny", "nz"}},
                    csv::LastLine::kRead, [&](const csv::Row& row) {
                      const glm::dvec3 p(row.real("x"), row.real("y"), row.real("z"));
                      const glm::dvec3 n(row.real("nx"), row.real("ny"), row.real("nz"));
                      for (int a = 0; a < 3; ++a)
                        if (std::abs(p[a]) > kMaxCoordinateM)
                          row.fail(std::string("the point lies beyond ±10000 m of the origin on ") + names[a]);
                      const double length = glm::length(n);
                      if (!(length > 1e-12) || !std::isfinite(length)) row.fail("the normal (nx, ny, nz) is zero");
                      q.points.push_back(p);
                      q.normals.push_back(n / length);
                    });
  if (q.points.empty()) throw InputError(path.string() + ": no points after the header; add x,y,z,nx,ny,nz rows");
  return q;
}

}  // namespace lumar
