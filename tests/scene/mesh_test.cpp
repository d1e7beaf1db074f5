// Meshes: the real scanned PLY against an independent parse of its ASCII text, small
// OBJ and glTF files written here, the error cases, and transformed() by hand.
#include "lumar/scene/mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <set>
#include <sstream>

#include "lumar/base/error.h"
#include "test_paths.h"

namespace lumar {
namespace {

using test::Scratch;
using ::testing::HasSubstr;

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    unsigned v = unsigned(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= unsigned(std::uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= unsigned(std::uint8_t(bytes[i + 2]));
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

template <typename T>
void append_bytes(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Rotates a triangle so its smallest index comes first; keeps the winding.
std::array<int, 3> canonical(int a, int b, int c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

void expect_throws_naming(const std::filesystem::path& path) {
  try {
    load_mesh(path);
    FAIL() << "no InputError for " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "message must be one line";
  }
}

TEST(Mesh, RealPlyMatchesItsText) {
  const auto path = test::shared_dir() / "data/models/parasaurolophus_6700.ply";
  const Mesh mesh = load_mesh(path);
  ASSERT_EQ(mesh.positions.size(), 6700u);
  ASSERT_EQ(mesh.normals.size(), 6700u);
  ASSERT_EQ(mesh.triangle_count(), 9140u);

  // Independent reading of the ASCII PLY: header, then "x y z nx ny nz", then "3 a b c".
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line != "end_header") {
  }
  std::vector<glm::vec3> file_positions(6700), file_normals(6700);
  for (int i = 0; i < 6700; ++i) {
    auto& p = file_positions[i];
    auto& n = file_normals[i];
    in >> p.x >> p.y >> p.z >> n.x >> n.y >> n.z;
  }
  std::set<std::array<int, 3>> file_triangles;
  for (int f = 0; f < 9140; ++f) {
    int count, a, b, c;
    in >> count >> a >> b >> c;
    ASSERT_EQ(count, 3);
    file_triangles.insert(canonical(a, b, c));
  }
  ASSERT_TRUE(in.good());

  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const auto& p : file_positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  // assimp's float parser and the standard library's may differ in the last bit.
  const auto [mlo, mhi] = mesh.bounds();
  EXPECT_NEAR(glm::distance(mlo, lo), 0.f, 1e-4f);
  EXPECT_NEAR(glm::distance(mhi, hi), 0.f, 1e-4f);
  // Millimetres, far from the origin: about 230 x 263 x 103 mm around (60, -60, -634).
  EXPECT_NEAR(mlo.x, -55.1494, 1e-3);
  EXPECT_NEAR(mhi.z, -582.992, 1e-3);

  // Match each loaded vertex to the file vertex at (nearly) the same place.
  std::vector<int> by_x(6700);
  for (int i = 0; i < 6700; ++i) by_x[i] = i;
  std::sort(by_x.begin(), by_x.end(), [&](int a, int b) { return file_positions[a].x < file_positions[b].x; });
  std::vector<int> file_index(6700);
  std::set<int> matched;
  for (std::size_t v = 0; v < 6700; ++v) {
    const glm::vec3 p = mesh.positions[v];
    auto it = std::lower_bound(by_x.begin(), by_x.end(), p.x - 1e-3f,
                               [&](int i, float x) { return file_positions[i].x < x; });
    int best = -1;
    float best_distance = 1e-3f;
    for (; it != by_x.end() && file_positions[*it].x <= p.x + 1e-3f; ++it)
      if (const float d = glm::distance(file_positions[*it], p); d < best_distance) {
        best = *it;
        best_distance = d;
      }
    ASSERT_GE(best, 0) << "vertex " << v << " is not a file vertex";
    file_index[v] = best;
    matched.insert(best);
    const glm::vec3 expected = glm::normalize(file_normals[best]);
    EXPECT_NEAR(glm::length(mesh.normals[v]), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(mesh.normals[v], expected), 0.f, 1e-5f) << "vertex " << v;
  }
  EXPECT_EQ(matched.size(), 6700u) << "every file vertex kept exactly once";
  std::set<std::array<int, 3>> loaded_triangles;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
    loaded_triangles.insert(canonical(file_index[mesh.indices[3 * t]], file_index[mesh.indices[3 * t + 1]],
                                      file_index[mesh.indices[3 * t + 2]]));
  EXPECT_EQ(loaded_triangles, file_triangles) << "same triangles with the same winding";
}

TEST(Mesh, ObjQuadsAreTriangulatedWithAreaWeightedNormals) {
  const Scratch scratch("mesh-obj");
  const auto& dir = scratch.dir;
  // Two faces meeting at a right angle along the edge x = 0..1, y = 0, z = 0:
  // a 1 x 1 quad in the floor (normal +Y) and a 1 x 3 quad in the wall (normal -Z).
  write_text(dir / "fold.obj",
             "# test\n"
             "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
             "v 0 3 0\nv 1 3 0\n"
             "f 1 4 3 2\n"
             "f 1 5 6 2\n");
  const Mesh mesh = load_mesh(dir / "fold.obj");
  ASSERT_EQ(mesh.triangle_count(), 4u);
  ASSERT_EQ(mesh.positions.size(), 6u) << "shared corners are joined";
  const auto [lo, hi] = mesh.bounds();
  EXPECT_EQ(lo, glm::vec3(0, 0, 0));
  EXPECT_EQ(hi, glm::vec3(1, 3, 1));
  // Every triangle faces the way its quad's normal says (counter-clockwise = front).
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                    c = mesh.positions[mesh.indices[3 * t + 2]];
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const bool floor = a.y == 0 && b.y == 0 && c.y == 0;
    EXPECT_NEAR(glm::distance(n, floor ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1)), 0.f, 1e-6f);
  }
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3 p = mesh.positions[v];
    glm::vec3 expected;
    if (p.z > 0.5f) {
      expected = {0, 1, 0};  // floor only
    } else if (p.y > 0.5f) {
      expected = {0, 0, -1};  // wall only
    } else {
      // On the fold. Each corner of the shared edge touches one floor triangle or two,
      // and one wall triangle or two, depending on the diagonal; weigh by area.
      double floor_area = 0, wall_area = 0;
      for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t* tri = &mesh.indices[3 * t];
        if (tri[0] != v && tri[1] != v && tri[2] != v) continue;
        const glm::dvec3 a = mesh.positions[tri[0]], b = mesh.positions[tri[1]], c = mesh.positions[tri[2]];
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        (a.y == 0 && b.y == 0 && c.y == 0 ? floor_area : wall_area) += area;
      }
      expected = glm::normalize(glm::vec3(0, float(floor_area), float(-wall_area)));
      EXPECT_GT(wall_area, floor_area) << "the wall's triangles are three times larger";
    }
    EXPECT_NEAR(glm::distance(mesh.normals[v], expected), 0.f, 1e-6f)
        << "vertex at " << p.x << "," << p.y << "," << p.z;
  }
}

TEST(Mesh, GltfWithEmbeddedBufferAppliesNodeTransform) {
  const Scratch scratch("mesh-gltf");
  const auto& dir = scratch.dir;
  std::string buffer;
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (float f : positions) append_bytes(buffer, f);
  for (std::uint16_t i : {0, 1, 2}) append_bytes(buffer, i);
  std::ostringstream gltf;
  gltf << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "translation": [1, 2, 3], "scale": [2, 2, 2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": )"
       << buffer.size() << R"(, "uri": "data:application/octet-stream;base64,)" << base64(buffer) << R"("}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
  write_text(dir / "triangle.gltf", gltf.str());

  const Mesh mesh = load_mesh(dir / "triangle.gltf");
  ASSERT_EQ(mesh.triangle_count(), 1u);
  ASSERT_EQ(mesh.positions.size(), 3u);
  // node: translate(1, 2, 3) * scale(2)
  const glm::vec3 expected[3] = {{1, 2, 3}, {3, 2, 3}, {1, 4, 3}};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(glm::distance(mesh.positions[mesh.indices[k]], expected[k]), 0.f, 1e-6f) << k;
    EXPECT_NEAR(glm::distance(mesh.normals[mesh.indices[k]], glm::vec3(0, 0, 1)), 0.f, 1e-6f) << k;
  }
}

TEST(Mesh, BadFilesThrowInputErrorNamingTheFile) {
  const Scratch scratch("mesh-bad");
  const auto& dir = scratch.dir;
  expect_throws_naming(dir / "missing.ply");
  write_text(dir / "garbage.ply", "this is not a mesh\x01\x02\x03");
  expect_throws_naming(dir / "garbage.ply");
  write_text(dir / "garbage.gltf", "{ not json at all");
  expect_throws_naming(dir / "garbage.gltf");
  write_text(dir / "no-faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect_throws_naming(dir / "no-faces.obj");
  write_text(dir / "points.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  expect_throws_naming(dir / "points.ply");
  write_text(dir / "infinite.obj", "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_throws_naming(dir / "infinite.obj");
}

std::string load_error(const std::filesystem::path& path) {
  try {
    load_mesh(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// What fuzz_mesh found assimp trusting (an abort in an assertion, an out-of-bounds read):
// the PLY is checked against its header first.
TEST(Mesh, PlyDataThatDoesNotMatchItsHeaderIsRefused) {
  const Scratch scratch("mesh-ply-check");
  const auto& dir = scratch.dir;
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  write_text(dir / "good.ply", head + "3 0 1 2\n");
  EXPECT_EQ(load_mesh(dir / "good.ply").triangle_count(), 1u);
  write_text(dir / "index.ply", head + "3 0 1 3\n");
  EXPECT_THAT(load_error(dir / "index.ply"), HasSubstr("index.ply: PLY face 0 names vertex 3 of 3"));
  write_text(dir / "short.ply", head + "3 0 1\n");
  EXPECT_THAT(load_error(dir / "short.ply"), HasSubstr("short.ply: PLY data ends in face 0 of 1"));
  write_text(dir / "word.ply", head + "3 0 one 2\n");
  EXPECT_THAT(load_error(dir / "word.ply"), HasSubstr("word.ply: PLY value \"one\" is not a number"));
  std::string garbled = head + "3 0 1 2\n";
  garbled.replace(garbled.find("property float z"), 16, "prope\x8e\x8bt z");
  write_text(dir / "garbled.ply", garbled);
  EXPECT_THAT(load_error(dir / "garbled.ply"), HasSubstr("garbled.ply: PLY header line 6 is not a header line"));
  // assimp looped forever on a PLY whose magic was "pLy" (found by fuzz_mesh).
  write_text(dir / "case.ply", "pLy" + head.substr(3) + "3 0 1 2\n");
  EXPECT_THAT(load_error(dir / "case.ply"), HasSubstr("case.ply: not a PLY file"));
  std::string no_z = head + "3 0 1 2\n";
  no_z.replace(no_z.find("property float z\n"), 17, "");
  write_text(dir / "no-z.ply", no_z);
  EXPECT_THAT(load_error(dir / "no-z.ply"), HasSubstr("no-z.ply: PLY vertices have no 'z' property"));
  // Binary, big-endian: the same triangle, then a face whose index is 65538.
  std::string bin =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const unsigned char one[4] = {0x3f, 0x80, 0, 0};  // 1.0f
  std::string vertices(36, '\0');
  std::copy(one, one + 4, vertices.begin() + 12);  // (1, 0, 0)
  std::copy(one, one + 4, vertices.begin() + 28);  // (0, 1, 0)
  const std::string face_ok = std::string("\x03", 1) + std::string("\0\0\0\0\0\0\0\x01\0\0\0\x02", 12);
  write_text(dir / "big.ply", bin + vertices + face_ok);
  EXPECT_EQ(load_mesh(dir / "big.ply").triangle_count(), 1u);
  std::string face_bad = face_ok;
  face_bad[1 + 8 + 1] = '\x01';  // the third index becomes 0x00010002
  write_text(dir / "big-bad.ply", bin + vertices + face_bad);
  EXPECT_THAT(load_error(dir / "big-bad.ply"), HasSubstr("names vertex 65538 of 3"));
}

// A mesh with faces but no area (once accepted silently, exit 0): all vertices equal, or
// all on one line. A mesh with one real triangle among degenerate ones is fine.
TEST(Mesh, DegenerateMeshesAreRefused) {
  const Scratch scratch("mesh-degenerate");
  const auto& dir = scratch.dir;
  write_text(dir / "point.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
  EXPECT_THAT(load_error(dir / "point.obj"), HasSubstr("point.obj: mesh is degenerate"));
  write_text(dir / "line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  EXPECT_THAT(load_error(dir / "line.obj"), HasSubstr("line.obj: mesh is degenerate"));
  write_text(dir / "mixed.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  EXPECT_EQ(load_mesh(dir / "mixed.obj").triangle_count(), 2u);
  std::filesystem::create_directories(dir / "folder.obj");
  EXPECT_THAT(load_error(dir / "folder.obj"), HasSubstr("is a directory"));
  EXPECT_THAT(load_error("/dev/zero"), HasSubstr("/dev/zero: mesh file is a device"));
}

// Counts in a PLY header are checked against the bytes after it before assimp reads
// them: the ASCII file that declared 10^9 vertices in 198 bytes made assimp allocate
// 6.3 GB in 18 s and go on; the binary one with 2x10^9 faces ended in bad_alloc.
TEST(Mesh, PlyCountsBeyondTheFileAreRefusedAtOnce) {
  const Scratch scratch("mesh-ply-counts");
  const auto& dir = scratch.dir;
  const std::string header = "property float x\nproperty float y\nproperty float z\n";
  write_text(dir / "huge-ascii.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000\n" + header +
                                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                         "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_text(dir / "huge-binary.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n" + header +
                                          "element face 2000000000\nproperty list uchar int vertex_indices\n"
                                          "end_header\n" +
                                          std::string(36 + 13, '\0'));
  // One vertex short: 2 of the 3 declared follow.
  write_text(dir / "short-binary.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n" + header +
                                           "end_header\n" + std::string(24, '\0'));
  for (const char* file : {"huge-ascii.ply", "huge-binary.ply", "short-binary.ply"}) {
    try {
      load_mesh(dir / file);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("PLY header declares"), std::string::npos) << e.what();
    }
  }
  // The exact size passes the check, and assimp then reads it.
  std::string body;
  const auto put = [&body](const auto value) { body.append(reinterpret_cast<const char*>(&value), sizeof value); };
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(v);
  put(std::uint8_t(3));
  for (const std::int32_t i : {0, 1, 2}) put(i);
  write_text(dir / "exact.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n" + header +
                                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + body);
  EXPECT_EQ(load_mesh(dir / "exact.ply").triangle_count(), 1u);
}

TEST(Mesh, TransformedMapsNormalsByInverseTranspose) {
  Mesh mesh;
  mesh.positions = {{1, 1, 1}, {2, 1, 1}, {1, 2, 1}};
  const glm::vec3 n = glm::normalize(glm::vec3(1, 1, 0));
  mesh.normals = {n, n, glm::vec3(0, 0, 1)};
  mesh.indices = {0, 1, 2};

  // translate(1, 2, 3) * scale(2, 1, 1), written out column by column.
  glm::dmat4 m(1.0);
  m[0][0] = 2.0;
  m[3] = glm::dvec4(1, 2, 3, 1);
  const Mesh out = transformed(mesh, m);
  EXPECT_NEAR(glm::distance(out.positions[0], glm::vec3(3, 3, 4)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::distance(out.positions[1], glm::vec3(5, 3, 4)), 0.f, 1e-6f);
  // Inverse transpose of diag(2, 1, 1) is diag(0.5, 1, 1): (1, 1, 0) -> (0.5, 1, 0) -> (1, 2, 0)/sqrt(5).
  EXPECT_NEAR(glm::distance(out.normals[0], glm::vec3(1, 2, 0) / std::sqrt(5.f)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::distance(out.normals[2], glm::vec3(0, 0, 1)), 0.f, 1e-6f);
  EXPECT_EQ(out.indices, mesh.indices);

  // A mirror keeps the triangle facing along its (mirrored) normal.
  glm::dmat4 mirror(1.0);
  mirror[0][0] = -1.0;
  const Mesh flipped = transformed(mesh, mirror);
  const glm::vec3 a = flipped.positions[flipped.indices[0]], b = flipped.positions[flipped.indices[1]],
                  c = flipped.positions[flipped.indices[2]];
  EXPECT_GT(glm::dot(glm::cross(b - a, c - a), flipped.normals[2]), 0.f);
  EXPECT_NEAR(glm::distance(flipped.normals[0], glm::vec3(-n.x, n.y, 0)), 0.f, 1e-6f);
}

TEST(Mesh, EmptyMeshHasZeroBounds) {
  const auto [lo, hi] = Mesh{}.bounds();
  EXPECT_EQ(lo, glm::vec3(0));
  EXPECT_EQ(hi, glm::vec3(0));
}

}  // namespace
}  // namespace lumar
