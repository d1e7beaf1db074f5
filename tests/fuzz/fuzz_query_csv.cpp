// The query CSV reader (read_query_points) used by `lumar irradiance` and `lumar shadows`:
// any bytes give points or one InputError, and accepted points are within ±kMaxCoordinateM
// with unit normals.
#include <cmath>

#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/scene/query_points.h"
#include "lumar/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  const auto path = fuzz::input_file(data, size, "query.csv");
  try {
    const QueryPoints q = read_query_points(path);
    FUZZ_CHECK(!q.points.empty() && q.points.size() == q.normals.size());
    for (const auto& p : q.points)
      for (int a = 0; a < 3; ++a) FUZZ_CHECK(std::abs(p[a]) <= kMaxCoordinateM);
    for (const auto& n : q.normals) FUZZ_CHECK(std::abs(glm::length(n) - 1.0) < 1e-9);
  } catch (const InputError&) {
  }
  return 0;
}
