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

// Unit vertex normals, each the area-weighted sum of its triangles' normals.
std::vector<glm::vec3> area_weighted_normals(const std::vector<glm::vec3>& positions,
                                             const std::vector<std::uint32_t>& indices);

// Edges that only one triangle uses (vertices at one position count as one): cracks and
// holes. A closed surface has none. A scan stitched from patches has many, and the
// renderer shows back faces, and a ray the hollow inside, through them (docs/solid.md).
std::size_t open_edge_count(const Mesh& mesh);

// Writes the mesh as binary PLY (positions, normals, triangles), whole or not at all.
void save_mesh_ply(const std::filesystem::path& path, const Mesh& mesh);

}  // namespace lumar
