#pragma once
// Points on surfaces where `lumar irradiance` and `lumar shadows` are asked for an answer:
// a CSV whose header names the columns x, y, z, nx, ny, nz in any order (other columns
// are allowed and ignored), one point per line; normals need not be unit length.
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

namespace lumar {

struct QueryPoints {
  std::vector<glm::dvec3> points, normals;  // normals unit length
};

// InputError naming the file and line: no such file, a missing column, a value that is
// not a finite number, a point beyond kMaxCoordinateM (scene.h) on any axis, a zero
// normal, or no points after the header.
QueryPoints read_query_points(const std::filesystem::path& path);

}  // namespace lumar
