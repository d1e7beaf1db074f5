// Precompute and per-frame pieces against independent references: the emitters'
// irradiance against the convention (uniform radiance 1 gives pi), the energy accounting
// of the lines and their order, culling against tracing every line, and the manifest's
// shadow keys.
#include <gtest/gtest.h>

#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "lumar/base/error.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/lighting/shadows/shadow_receivers.h"
#include "lumar/scene/scene.h"
#include "sample_room_lines.h"
#include "shadow_test_util.h"
#include "test_paths.h"

namespace lumar {
namespace {

EnvironmentMap uniform_map(int width, float radiance) {
  EnvironmentMap m;
  m.width = width;
  m.height = width / 2;
  m.rgb.assign(std::size_t(m.width) * m.height * 3, radiance);
  return m;
}

Mesh box_room(const glm::vec3& lo, const glm::vec3& hi) {
  // Six inward-facing quads (the normals are not used by RayScene).
  Mesh m;
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  m.positions.assign(c, c + 8);
  m.normals.assign(8, glm::vec3(0, 1, 0));
  const std::uint32_t q[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
  for (const auto& f : q) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

glm::vec3 sum_irradiance(const std::vector<EmitterPoint>& points, bool distant, const glm::vec3& x,
                         const glm::vec3& n) {
  glm::vec3 e(0.0f);
  for (const auto& p : points) e += emitter_irradiance(p, distant, x, n);
  return e;
}

TEST(ShadowEmitters, UniformRoomGivesPiIrradiance) {
  // Radiance 1 everywhere, mapped onto a closed room: any point inside receives pi.
  RayScene proxy;
  proxy.add_static(box_room({-3, 0, -2.5}, {3, 3, 2.5}));
  proxy.commit();
  EnvironmentMap map = uniform_map(256, 1.0f);
  map.capture_position = {0.0, 1.4, 0.0};
  const Emitters e = build_emitters(map, proxy, false, {0.3f, 0.0f, 0.2f}, {0, 1, 0});
  const glm::vec3 floor = sum_irradiance(e.texels, false, {0.3f, 0.0f, 0.2f}, {0, 1, 0});
  EXPECT_NEAR(floor.g, std::numbers::pi, 0.03 * std::numbers::pi);
  // The patches' samples carry exactly the texels' flux, and nearly the same irradiance.
  glm::dvec3 texel_flux(0.0), sample_flux(0.0);
  for (const auto& t : e.texels) texel_flux += glm::dvec3(t.flux);
  for (const auto& s : e.samples) sample_flux += glm::dvec3(s.flux);
  EXPECT_NEAR(sample_flux.g / texel_flux.g, 1.0, 1e-5);
  const glm::vec3 from_samples = sum_irradiance(e.samples, false, {0.3f, 0.0f, 0.2f}, {0, 1, 0});
  EXPECT_NEAR(from_samples.g, floor.g, 0.05 * floor.g);
  EXPECT_LE(int(e.patches.size()), 64);
  EXPECT_GE(int(e.patches.size()), 2);
}

TEST(ShadowEmitters, DistantUniformSkyGivesPi) {
  RayScene none;
  none.commit();
  const Emitters e = build_emitters(uniform_map(128, 1.0f), none, true, {0, 0, 0}, {0, 1, 0});
  EXPECT_NEAR(sum_irradiance(e.texels, true, {0, 0, 0}, {0, 1, 0}).r, std::numbers::pi, 0.01);
  EXPECT_NEAR(sum_irradiance(e.samples, true, {0, 0, 0}, {0, 1, 0}).r, std::numbers::pi, 0.1);
}

TEST(ShadowEmitters, SunPatchIsResolvedAndThresholdKeepsIt) {
  RayScene none;
  none.commit();
  const EnvironmentMap sky = test::make_sun_sky(256, 40.0, 0.0, 1.5, 20000.0f);
  const Emitters e = build_emitters(sky, none, true, {0, 0, 0}, {0, 1, 0});
  EXPECT_GE(e.resolved_fraction, 0.9);
  // The 2004 threshold keeps the sun and drops most of the sky.
  EmitterOptions o = sphere_baseline_emitter_options();
  const Emitters bright = build_emitters(sky, none, true, {0, 0, 0}, {0, 1, 0}, o);
  EXPECT_LT(bright.texels.size(), e.texels.size() / 10);
  EXPECT_EQ(bright.patches.size(), std::min<std::size_t>(50, bright.texels.size()));
}

TEST(ShadowLines, EnergyAccountingIsExact) {
  const test::SampleRoomLines room = test::sample_room_lines(400);
  const Mesh& rec = room.receivers;
  ASSERT_GT(rec.positions.size(), 300u);
  const ShadowLines& lines = room.lines;
  std::vector<glm::dvec3> kept(rec.positions.size(), glm::dvec3(0.0));
  for (const ShadowLine& l : lines.lines) kept[l.receiver] += glm::dvec3(l.fraction);
  std::size_t dark = 0;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    // Floor under the table block sees no light at all: no lines, attenuation 1.
    if (lines.unshadowed[i].g == 0.0f) {
      ++dark;
      EXPECT_EQ(kept[i], glm::dvec3(0.0));
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(kept[i][c], 1.0 + 1e-5);
      EXPECT_GE(kept[i][c] + lines.dropped[i], 1.0 - 1e-5);  // what is not kept was dropped, within budget
    }
    EXPECT_LE(lines.dropped[i], 0.002f + 1e-6f);
  }
  EXPECT_LT(dark, kept.size() / 10);
  // Lines are ordered by sample, then by receiver in grid order, one per (sample, receiver).
  std::vector<std::uint32_t> position(rec.positions.size());
  for (std::size_t k = 0; k < lines.grids.order.size(); ++k) position[lines.grids.order[k]] = std::uint32_t(k);
  ASSERT_EQ(lines.sample_first.size(), lines.samples.size() + 1);
  ASSERT_EQ(lines.sample_first.back(), lines.lines.size());
  for (std::size_t s = 0; s < lines.samples.size(); ++s)
    for (std::uint32_t k = lines.sample_first[s]; k < lines.sample_first[s + 1]; ++k) {
      ASSERT_EQ(lines.lines[k].sample, s);
      if (k > lines.sample_first[s]) {
        ASSERT_LT(position[lines.lines[k - 1].receiver], position[lines.lines[k].receiver]);
      }
    }
}

TEST(ShadowOcclusion, CullingChangesNothingAndSkipsWhenStill) {
  const test::SampleRoomLines room = test::sample_room_lines(1600);
  LineShadows shadows(room.lines);
  const auto& fig = room.figurine();
  shadows.add_object(fig.model, fig.T_world_model);
  for (int step = 0; step < 4; ++step) {
    const glm::dmat4 T = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.15 * step, 0.1, 0.1 * step)) * fig.T_world_model;
    shadows.set_object_pose(0, T);
    shadows.set_culling(true);
    ASSERT_TRUE(shadows.update());
    const auto culled = shadows.attenuation();
    const ShadowFrameStats stats = shadows.stats();
    shadows.set_culling(false);
    ASSERT_TRUE(shadows.update());
    const auto all = shadows.attenuation();
    float diff = 0;
    for (std::size_t i = 0; i < all.size(); ++i) diff = std::max(diff, glm::length(culled[i] - all[i]));
    EXPECT_LT(diff, 1e-5f) << "step " << step;  // same lines blocked; only the summation order differs
    EXPECT_LT(stats.rays_traced * 10, shadows.stats().rays_traced) << "culling traced " << stats.rays_traced;
    EXPECT_GT(stats.lines_blocked, 0u);
    EXPECT_EQ(stats.lines_blocked, shadows.stats().lines_blocked);
  }
  // Nothing moved: no work, same result.
  const auto before = shadows.attenuation();
  EXPECT_FALSE(shadows.update());
  EXPECT_EQ(shadows.attenuation(), before);
}

TEST(ShadowReceivers, DefaultFloorUnderMovementBox) {
  Scene s = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  const ShadowScene scene(load_scene_files(s));
  const Mesh rec = scene.receivers();
  EXPECT_NEAR(double(rec.positions.size()), 3200.0, 300.0);
  EXPECT_GT(rec.triangle_count(), 5000u);
  for (std::size_t i = 0; i < rec.positions.size(); ++i) {
    ASSERT_NEAR(rec.positions[i].y, 0.0f, 1e-5f);
    ASSERT_NEAR(rec.normals[i].y, 1.0f, 1e-5f);
    ASSERT_GE(rec.positions[i].x, s.movement_min.x - 0.5 - 1e-4);
    ASSERT_LE(rec.positions[i].z, s.movement_max.z + 0.5 + 1e-4);
  }
}

TEST(ShadowManifest, ReadsRegionsAndKeepsOldManifestsValid) {
  test::Scratch scratch("shadow_manifest");
  const auto src = test::source_dir() / "data/scenes/room/scene.json";
  std::ifstream in(src);
  nlohmann::json j = nlohmann::json::parse(in);
  const auto write = [&](const nlohmann::json& doc) {
    const auto p = scratch.dir / "scene.json";
    std::ofstream(p) << doc.dump();
    // Paths in the manifest are relative to its folder: copy the files beside it.
    return p;
  };
  j["room"]["mesh"] = (test::source_dir() / "data/scenes/room/room.obj").string();
  j["environment_map"]["path"] = (test::source_dir() / "data/envmaps/interior.exr").string();
  j["objects"][0]["mesh"] = (test::source_dir() / "data/models/parasaurolophus_6700.ply").string();
  EXPECT_TRUE(load_scene(write(j)).shadows.receivers.empty());  // no "shadows": defaults
  j["shadows"] = {{"receivers", {{{"min", {0.5, 0.7, -1.1}}, {"max", {1.25, 0.74, -0.25}}}}},
                  {"emitters", {{{"min", {-3, 2.9, -2.5}}, {"max", {3, 3, 2.5}}}}},
                  {"receiver_vertices", 500}};
  const Scene s = load_scene(write(j));
  ASSERT_EQ(s.shadows.receivers.size(), 1u);
  EXPECT_DOUBLE_EQ(s.shadows.receivers[0].max.y, 0.74);
  ASSERT_EQ(s.shadows.emitters.size(), 1u);
  EXPECT_EQ(s.shadows.receiver_vertices, 500);
  // The table top receives: its vertices lie at the table's height.
  const Mesh table = ShadowScene(load_scene_files(s)).receivers();
  ASSERT_GT(table.positions.size(), 300u);
  for (const auto& p : table.positions) ASSERT_NEAR(p.y, 0.72f, 1e-4f);
  j["shadows"]["recievers"] = nlohmann::json::array();
  try {
    load_scene(write(j));
    FAIL() << "a misspelt key must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shadows.recievers"), std::string::npos) << e.what();
  }
  j["shadows"].erase("recievers");
  j["shadows"]["receiver_vertices"] = -3;
  EXPECT_THROW(load_scene(write(j)), InputError);
}

}  // namespace
}  // namespace lumar
