// The shadow lines' disk cache: a second start loads exactly the lines the first built, a
// damaged file is rebuilt with a warning, and the key follows every input.
#include "lumar/lighting/shadows/shadow_line_cache.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "lumar/base/error.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

struct Inputs {
  std::unique_ptr<ShadowScene> scene;
  Mesh receivers;
  Emitters emitters;
};

Inputs sample_inputs() {
  Scene manifest = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  manifest.shadows.receiver_vertices = 400;
  Inputs in;
  in.scene = std::make_unique<ShadowScene>(load_scene_files(manifest));
  in.receivers = in.scene->receivers();
  EmitterOptions options;
  options.max_patches = 16;
  in.emitters = in.scene->emitters(in.receivers.positions, in.receivers.normals, options);
  return in;
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expect_same(const ShadowLines& a, const ShadowLines& b) {
  EXPECT_EQ(a.distant, b.distant);
  EXPECT_EQ(a.patch_count, b.patch_count);
  EXPECT_EQ(a.candidate_lines, b.candidate_lines);
  EXPECT_TRUE(same_bytes(a.origins, b.origins));
  EXPECT_TRUE(same_bytes(a.samples, b.samples));
  EXPECT_TRUE(same_bytes(a.lines, b.lines));
  EXPECT_TRUE(same_bytes(a.sample_first, b.sample_first));
  EXPECT_TRUE(same_bytes(a.unshadowed, b.unshadowed));
  EXPECT_TRUE(same_bytes(a.dropped, b.dropped));
  EXPECT_TRUE(same_bytes(a.grids.grids, b.grids.grids));
  EXPECT_TRUE(same_bytes(a.grids.order, b.grids.order));
  EXPECT_TRUE(same_bytes(a.grids.bucket_first, b.grids.bucket_first));
}

TEST(ShadowLineCache, ASecondStartLoadsTheLinesTheFirstBuilt) {
  const test::Scratch scratch("shadow-line-cache");
  const Inputs in = sample_inputs();
  const auto build = [&](bool& loaded) {
    return cached_shadow_lines(in.receivers.positions, in.receivers.normals, in.emitters, in.scene->proxy(),
                               in.scene->room(), {}, scratch.dir, &loaded);
  };
  bool loaded = true;
  const ShadowLines first = build(loaded);
  EXPECT_FALSE(loaded);
  ASSERT_GT(first.lines.size(), 1000u);
  const ShadowLines second = build(loaded);
  EXPECT_TRUE(loaded);
  expect_same(first, second);
  // The same as building without the cache.
  expect_same(first, build_shadow_lines(in.receivers.positions, in.receivers.normals, in.emitters, in.scene->proxy()));

  // A damaged file (cut in half, or one index out of range) is rebuilt, not trusted.
  const auto files = std::vector<std::filesystem::path>(std::filesystem::directory_iterator(scratch.dir), {});
  ASSERT_EQ(files.size(), 1u);
  const auto size = std::filesystem::file_size(files[0]);
  std::filesystem::resize_file(files[0], size / 2);
  EXPECT_THROW(load_shadow_lines(files[0]), InputError);
  expect_same(first, build(loaded));
  EXPECT_FALSE(loaded);
  {
    // The first line's receiver index, past the header and the origins and samples.
    std::fstream f(files[0], std::ios::in | std::ios::out | std::ios::binary);
    const std::streamoff at = 8 + 1 + 4 + 8 + 8 + std::streamoff(first.origins.size() * sizeof(glm::vec3)) + 8 +
                              std::streamoff(first.samples.size() * sizeof(EmitterPoint)) + 8;
    const std::uint32_t bad = 0xffffffffu;
    f.seekp(at);
    f.write(reinterpret_cast<const char*>(&bad), sizeof(bad));
  }
  EXPECT_THROW(load_shadow_lines(files[0]), InputError);
  expect_same(first, build(loaded));
  EXPECT_FALSE(loaded);
  EXPECT_THROW(load_shadow_lines(scratch.dir / "none.bin"), InputError);
}

TEST(ShadowLineCache, TheKeyFollowsEveryInput) {
  const Inputs in = sample_inputs();
  const auto key = [&](const std::vector<glm::vec3>& positions, const Emitters& emitters, const Mesh& proxy,
                       double dropped) {
    ShadowLineOptions options;
    options.max_dropped_fraction = dropped;
    return shadow_lines_key(positions, in.receivers.normals, emitters, proxy, options);
  };
  const std::uint64_t k = key(in.receivers.positions, in.emitters, in.scene->room(), 0.002);
  EXPECT_EQ(k, key(in.receivers.positions, in.emitters, in.scene->room(), 0.002));
  std::vector<glm::vec3> moved = in.receivers.positions;
  moved[7].x += 1e-4f;
  EXPECT_NE(k, key(moved, in.emitters, in.scene->room(), 0.002));
  Emitters brighter = in.emitters;
  brighter.samples[3].flux *= 1.01f;
  EXPECT_NE(k, key(in.receivers.positions, brighter, in.scene->room(), 0.002));
  Mesh room = in.scene->room();
  room.positions[0].y += 0.01f;
  EXPECT_NE(k, key(in.receivers.positions, in.emitters, room, 0.002));
  EXPECT_NE(k, key(in.receivers.positions, in.emitters, in.scene->room(), 0.001));
}

}  // namespace
}  // namespace lumar
