// The mesh loader (load_mesh, assimp behind the project's own size checks). Byte 0 picks
// the file's extension (.ply, .obj, .gltf), the rest is the file. Any bytes give a mesh or
// one InputError, and an accepted mesh has triangles, finite positions, unit normals and
// indices within its vertices.
#include <cmath>

#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/scene/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  if (size < 1) return 0;
  static const char* kExtensions[] = {"ply", "obj", "gltf"};
  const std::string name = std::string("mesh.") + kExtensions[data[0] % 3];
  const auto path = fuzz::input_file(data + 1, size - 1, name);
  try {
    const Mesh mesh = load_mesh(path);
    FUZZ_CHECK(mesh.triangle_count() > 0 && mesh.indices.size() % 3 == 0);
    FUZZ_CHECK(mesh.normals.size() == mesh.positions.size());
    for (const auto& p : mesh.positions) FUZZ_CHECK(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    for (const auto& n : mesh.normals) FUZZ_CHECK(std::abs(glm::length(n) - 1.0f) < 1e-3f);
    for (const auto i : mesh.indices) FUZZ_CHECK(i < mesh.positions.size());
  } catch (const InputError&) {
  }
  return 0;
}
