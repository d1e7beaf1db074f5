#include "lumar/scene/mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include "decode_counter.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/output_file.h"
#include "ply_check.h"

namespace lumar {

namespace {

bool is_finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

std::pair<glm::vec3, glm::vec3> Mesh::bounds() const {
  if (positions.empty()) return {glm::vec3(0.f), glm::vec3(0.f)};
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const auto& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

Mesh load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  check_input_file(path, "mesh file");
  check_ply(path);

  // Pre-transforming bakes the node hierarchy's transforms into the vertices, so a glTF
  // or OBJ whose parts are placed by nodes loads where its author put it. Normals are
  // not generated here: assimp's are not area-weighted, and the file's own are kept.
  Assimp::Importer importer;
  const unsigned flags =
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  const aiScene* scene = importer.ReadFile(name, flags);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode) {
    std::string why = importer.GetErrorString();
    if (why.empty()) why = "incomplete scene";
    throw InputError(name + ": cannot read mesh (" + why + "); export it as OBJ, PLY or glTF");
  }

  Mesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    if (!(part->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // points, lines
    const auto base = std::uint32_t(mesh.positions.size());

    std::vector<std::uint32_t> part_indices;
    part_indices.reserve(std::size_t(part->mNumFaces) * 3);
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) part_indices.push_back(face.mIndices[k]);
    }
    if (part_indices.empty()) continue;

    std::vector<glm::vec3> part_positions(part->mNumVertices);
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      part_positions[v] = {p.x, p.y, p.z};
      if (!is_finite(part_positions[v]))
        throw InputError(name + ": vertex " + std::to_string(base + v) +
                         " has a non-finite position; repair the model");
    }

    // File normals where present and usable; computed ones fill the rest.
    const std::vector<glm::vec3> computed = area_weighted_normals(part_positions, part_indices);
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      glm::vec3 n = computed[v];
      if (part->HasNormals()) {
        const glm::vec3 file_n(part->mNormals[v].x, part->mNormals[v].y, part->mNormals[v].z);
        const float len = glm::length(file_n);
        if (std::isfinite(len) && len > 1e-12f) n = file_n / len;
      }
      mesh.normals.push_back(n);
    }
    mesh.positions.insert(mesh.positions.end(), part_positions.begin(), part_positions.end());
    for (std::uint32_t i : part_indices) mesh.indices.push_back(base + i);
  }
  if (mesh.indices.empty()) throw InputError(name + ": mesh holds no triangles; export the model with its faces");
  // A mesh whose every triangle has no area (all vertices equal, or in one line) has no
  // surface to light or to shadow with, and no size to place by.
  double area = 0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const glm::dvec3 p0 = mesh.positions[mesh.indices[t]], p1 = mesh.positions[mesh.indices[t + 1]],
                     p2 = mesh.positions[mesh.indices[t + 2]];
    area += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  if (!(area > 0) || !std::isfinite(area))
    throw InputError(name + ": mesh is degenerate (no triangle of the " + std::to_string(mesh.triangle_count()) +
                     " has an area, or the area is infinite); repair the model");
  count_decode(path);
  return mesh;
}

Mesh transformed(const Mesh& mesh, const glm::dmat4& m) {
  Mesh out;
  out.positions.reserve(mesh.positions.size());
  out.normals.reserve(mesh.normals.size());
  for (const auto& p : mesh.positions) {
    const glm::dvec4 q = m * glm::dvec4(glm::dvec3(p), 1.0);
    out.positions.emplace_back(glm::dvec3(q) / q.w);
  }
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(m)));
  for (const auto& n : mesh.normals) {
    const glm::dvec3 t = normal_matrix * glm::dvec3(n);
    out.normals.emplace_back(glm::length(t) > 0.0 ? glm::normalize(t) : t);  // a missing normal stays zero
  }
  out.indices = mesh.indices;
  // A mirroring transform turns counter-clockwise triangles clockwise; swap two corners
  // so that the winding still agrees with the (correctly transformed) normals.
  if (glm::determinant(glm::dmat3(m)) < 0.0)
    for (std::size_t t = 0; t + 2 < out.indices.size(); t += 3) std::swap(out.indices[t + 1], out.indices[t + 2]);
  return out;
}

// The unnormalised cross product of a triangle's edges
// has length twice its area, so summing them weights each face by its area.
std::vector<glm::vec3> area_weighted_normals(const std::vector<glm::vec3>& positions,
                                             const std::vector<std::uint32_t>& indices) {
  std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::dvec3 a = positions[indices[t]], b = positions[indices[t + 1]], c = positions[indices[t + 2]];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) sum[indices[t + k]] += n;
  }
  std::vector<glm::vec3> normals(positions.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double len = glm::length(sum[i]);
    // A vertex on no (or only degenerate) triangles has no direction; any unit vector will do.
    normals[i] = len > 0.0 ? glm::vec3(sum[i] / len) : glm::vec3(0.f, 1.f, 0.f);
  }
  return normals;
}

std::size_t open_edge_count(const Mesh& mesh) {
  // Vertices at the same position are one: a box's corners are repeated with each face's
  // normal, and the seam between them is not a crack.
  std::map<std::tuple<float, float, float>, std::uint32_t> at;
  std::vector<std::uint32_t> id(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3& p = mesh.positions[v];
    id[v] = at.try_emplace({p.x, p.y, p.z}, std::uint32_t(at.size())).first->second;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t v[3] = {id[mesh.indices[t]], id[mesh.indices[t + 1]], id[mesh.indices[t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;  // a fan's tip at a pole: no area, no edge
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(v[k], v[(k + 1) % 3])];
  }
  return std::size_t(std::count_if(uses.begin(), uses.end(), [](const auto& e) { return e.second == 1; }));
}

void save_mesh_ply(const std::filesystem::path& path, const Mesh& mesh) {
  // aiScene owns (and frees) what is attached to it.
  aiScene scene;
  scene.mRootNode = new aiNode();
  scene.mRootNode->mNumMeshes = 1;
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMeshes = 1;
  scene.mMeshes = new aiMesh* [1] { new aiMesh() };
  aiMesh& out = *scene.mMeshes[0];
  out.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out.mNumVertices = unsigned(mesh.positions.size());
  out.mVertices = new aiVector3D[out.mNumVertices];
  out.mNormals = new aiVector3D[out.mNumVertices];
  for (unsigned v = 0; v < out.mNumVertices; ++v) {
    const glm::vec3 p = mesh.positions[v], n = v < mesh.normals.size() ? mesh.normals[v] : glm::vec3(0.f);
    out.mVertices[v] = aiVector3D(p.x, p.y, p.z);
    out.mNormals[v] = aiVector3D(n.x, n.y, n.z);
  }
  out.mNumFaces = unsigned(mesh.triangle_count());
  out.mFaces = new aiFace[out.mNumFaces];
  for (unsigned f = 0; f < out.mNumFaces; ++f) {
    out.mFaces[f].mNumIndices = 3;
    out.mFaces[f].mIndices = new unsigned[3]{mesh.indices[3 * f], mesh.indices[3 * f + 1], mesh.indices[3 * f + 2]};
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, "plyb");
  if (!blob) throw RuntimeError(path.string() + ": cannot write the mesh (" + exporter.GetErrorString() + ")");
  write_file_atomically(path, std::string_view(static_cast<const char*>(blob->data), blob->size));
}

}  // namespace lumar
