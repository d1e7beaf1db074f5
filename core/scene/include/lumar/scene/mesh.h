#pragma once
// Indexed triangle meshes, loaded from OBJ, PLY or glTF through assimp.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <utility>
#include <vector>

namespace lumar {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;      // one unit normal per vertex
  std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise = front

  std::size_t triangle_count() const { return indices.size() / 3; }
  std::pair<glm::vec3, glm::vec3> bounds() const;  // (min, max); zero box when empty
};

// Loads every mesh of the file into one (file units, no scaling). Normals are taken
// from the file or computed (area-weighted) when absent. Throws InputError naming the
// file when it is missing, corrupt or holds no triangles.
Mesh load_mesh(const std::filesystem::path& path);

// The mesh with positions mapped by `m` and normals by its inverse transpose.
Mesh transformed(const Mesh& mesh, const glm::dmat4& m);

}  // namespace lumar
