// The divided proxy room (a window in the map, a lamp, a table, a dividing wall with a
// doorway): radiance lookups, the reference, and the volume against the reference.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "../common/test_paths.h"
#include "irradiance_test_util.h"
#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar::test {
namespace {

struct Fixture {
  DividedRoom room = make_divided_room();
  RoomRadiance reference{room.map, room.proxy, reference_radiance_settings()};
  VolumeSettings settings = volume_settings_for("volume");
  RoomRadiance radiance{room.map, room.proxy, settings.radiance};
  IrradianceVolume volume = IrradianceVolume::build(radiance, room.box_min, room.box_max, settings);
};
const Fixture& fixture() {
  static Fixture f;
  return f;
}

bool inside_solid(const glm::dvec3& p) {
  const auto in = [&](glm::dvec3 lo, glm::dvec3 hi) {
    return glm::all(glm::greaterThan(p, lo - 0.03)) && glm::all(glm::lessThan(p, hi + 0.03));
  };
  return in({-2.2, -1, 0.4}, {-1.4, 0.8, 1.2}) || in({-0.05, -1, -2}, {0.05, 3, 1}) || in({-0.05, 2, 1}, {0.05, 3, 2});
}

TEST(IrradianceRoom, TheCapturePointSeesTheMapItself) {
  const DividedRoom room = make_divided_room();
  RadianceSettings s;
  s.map_height = 0;
  s.bright_fraction = 0.0;
  RoomRadiance radiance(room.map, room.proxy, s);
  for (int r = 3; r < room.map.height; r += 17)
    for (int c = 5; c < room.map.width; c += 23) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, room.map.width, room.map.height);
      const auto sample = radiance.radiance(room.map.capture_position, d);
      EXPECT_FALSE(sample.fallback);
      EXPECT_NEAR(sample.radiance.g, room.map.texel(c, r).g, 1e-6);
    }
  EXPECT_EQ(radiance.fallback_rays(), 0u);
}

TEST(IrradianceRoom, HiddenSurfacesUseTheFallbackAndAreCounted) {
  const DividedRoom room = make_divided_room();
  RoomRadiance radiance(room.map, room.proxy, RadianceSettings{});
  // From the dark half, looking at its far wall (x = 3), which the capture point cannot see.
  const auto sample = radiance.dim_radiance({1.5, 1.0, -1.0}, {1, 0, 0});
  EXPECT_TRUE(sample.fallback);
  EXPECT_NEAR(sample.radiance.g, radiance.fallback_radiance().g, 1e-12);
  EXPECT_LT(luminance(radiance.fallback_radiance()), 0.1);  // a dim surface, never the window
  EXPECT_EQ(radiance.fallback_rays(), 1u);
  // Inside the wall every ray meets a back face.
  EXPECT_TRUE(radiance.dim_radiance({0.0, 1.0, -1.0}, {0, 1, 0}).back_face);
}

TEST(IrradianceRoom, ReferenceOfAUniformRoomIsPi) {
  DividedRoom room = make_divided_room();
  std::fill(room.map.rgb.begin(), room.map.rgb.end(), 1.0f);
  RoomRadiance radiance(room.map, room.proxy, reference_radiance_settings());
  std::mt19937 rng(5);
  for (int i = 0; i < 10; ++i) {
    const glm::dvec3 p(std::uniform_real_distribution<double>(0.2, 2.5)(rng), 1.0, 0.0);
    const glm::dvec3 n = random_normals(1, unsigned(i))[0];
    EXPECT_NEAR(reference_irradiance(radiance, p, n, 32).g, kPi, 1e-6);
  }
}

TEST(IrradianceRoom, VolumeMatchesTheReferenceAcrossTheMovementBox) {
  const Fixture& f = fixture();
  const auto& st = f.volume.stats();
  std::printf("volume: %d probes (%d moved, %d disabled), %d cells (%d refined), %.0f ms, %llu rays, %llu fallback\n",
              st.probes, st.moved, st.disabled, st.cells, st.refined_cells, st.build_ms, (unsigned long long)st.rays,
              (unsigned long long)st.fallback_rays);
  EXPECT_GT(st.refined_cells, 0);
  EXPECT_LT(st.refined_cells, st.cells);
  EXPECT_GT(st.moved + st.disabled, 0);  // probes in the wall and the table
  std::mt19937 rng(11);
  std::vector<glm::dvec3> points, normals;
  while (points.size() < 80) {
    glm::dvec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = std::uniform_real_distribution<double>(f.room.box_min[a], f.room.box_max[a])(rng);
    if (inside_solid(p)) continue;
    points.push_back(p);
    normals.push_back(random_normals(1, unsigned(points.size() * 13))[0]);
  }
  const auto reference = reference_irradiance(f.reference, points, normals, 48);
  std::vector<glm::dvec3> ours;
  for (std::size_t i = 0; i < points.size(); ++i) ours.push_back(f.volume.evaluate(points[i], normals[i]));
  const ErrorStats e = luminance_errors(ours, reference);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double err = std::abs(luminance(ours[i]) - luminance(reference[i])) / luminance(reference[i]);
    if (err > 0.1)
      std::printf("  point (%.2f %.2f %.2f) n (%.2f %.2f %.2f): volume %.4f reference %.4f\n", points[i].x, points[i].y,
                  points[i].z, normals[i].x, normals[i].y, normals[i].z, luminance(ours[i]), luminance(reference[i]));
  }
  std::printf("volume vs reference at %zu points: mean %.2f %%, p99 %.1f %%, max %.1f %%\n", points.size(),
              100 * e.mean, 100 * e.p99, 100 * e.max);
  EXPECT_LE(e.mean, 0.03);  // issue 7
}

// The movement box starts on the floor, so a row of lattice nodes lies on it. A ray that
// starts exactly on a plane may pass through it: those probes looked clear, kept their
// place, and their lower half saw beneath the floor (the map's view of the floor from the
// capture point instead of the floor below them).
TEST(IrradianceRoom, ProbesOnTheFloorAreLiftedOffIt) {
  const Fixture& f = fixture();
  int on_floor = 0, near_floor = 0;
  for (const glm::vec4& q : f.volume.probes) {
    if (q.w == 0.0f) continue;
    on_floor += std::abs(q.y - f.room.box_min.y) < 1e-3;
    near_floor += q.y - f.room.box_min.y < 0.05;
  }
  EXPECT_EQ(on_floor, 0);
  EXPECT_GT(near_floor, 20);  // lifted a little, not disabled
}

// A surface a few centimetres above the sample room's floor and facing down sees the
// floor just below it, as the probes lifted off the floor do. (Closer than the probes,
// the floor's pattern varies faster than they are spaced: 1-3 cm above it the error is
// 13 % on average.)
TEST(IrradianceRoom, ADownwardNormalJustAboveTheFloorSeesTheFloorBelowIt) {
  const LoadedScene scene = load_scene_files(source_dir() / "data/scenes/room/scene.json");
  const IrradianceVolume volume = scene_irradiance_volume(scene, "volume", false);
  const auto reference = scene_radiance(scene, truth_radiance_settings());
  std::vector<glm::dvec3> points, normals;
  for (double x : {-0.3, -0.1, 0.0, 0.1, 0.3})
    for (double z : {0.0, 0.3, 0.6})
      for (double h : {0.04, 0.06, 0.1}) points.push_back({x, h, z}), normals.push_back({0, -1, 0});
  const auto expected = reference_irradiance(*reference, points, normals, 48);
  std::vector<glm::dvec3> ours;
  for (std::size_t i = 0; i < points.size(); ++i) ours.push_back(volume.evaluate(points[i], normals[i]));
  const ErrorStats e = luminance_errors(ours, expected);
  std::printf("facing the floor from 4-10 cm: volume vs reference at %zu points: mean %.1f %%, max %.1f %%\n",
              points.size(), 100 * e.mean, 100 * e.max);
  EXPECT_LT(e.mean, 0.08);  // 5.0 %; 49 % with the probes on the floor
  EXPECT_LT(e.max, 0.35);   // 23 %; 162 %
}

TEST(IrradianceRoom, LightShadowMapsAgreeWithRays) {
  const Fixture& f = fixture();
  // The window is one evenly bright opening: it is tiled into lights, none of it left over.
  int window_lights = 0;
  for (const DominantLight& l : f.radiance.lights())
    window_lights += l.on_proxy && l.position.x < -2.99 && luminance(l.power / l.solid_angle) < 100.0;
  EXPECT_GE(window_lights, 6);
  double left = 0.0, total = 0.0;
  for (const BrightTexel& t : f.radiance.bright_texels()) {
    total += luminance(t.radiance) * t.solid_angle;
    if (t.light < 0) left += luminance(t.radiance) * t.solid_angle;
  }
  std::printf("%zu lights (%d on the window); %.1f %% of the bright power left to the probes\n",
              f.radiance.lights().size(), window_lights, 100 * left / total);
  EXPECT_LE(left, 0.10 * total);  // the window's partly covered rim texels stay with the probes
  ASSERT_EQ(f.volume.lights.size(), f.radiance.lights().size());
  // Each light's shadow map against an exact visibility ray, at points across both halves.
  std::mt19937 rng(17);
  int tested = 0, wrong = 0;
  while (tested < 400) {
    glm::dvec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = std::uniform_real_distribution<double>(f.room.box_min[a], f.room.box_max[a])(rng);
    if (inside_solid(p)) continue;
    const std::size_t l = std::size_t(tested) % f.volume.lights.size();
    const DominantLight& light = f.radiance.lights()[l];
    if (glm::dot(p - light.position, light.normal) <= 0.0) continue;
    const bool seen = f.radiance.sees(p, light.on_proxy, light.position, light.direction);
    wrong += (f.volume.light_shadow_visibility(l, p) > 0.5) != seen;
    ++tested;
  }
  std::printf("light shadow maps: %d of %d points disagree with a visibility ray\n", wrong, tested);
  EXPECT_LE(wrong, tested / 50);
}

TEST(IrradianceRoom, NoLightLeaksThroughTheDividingWall) {
  const Fixture& f = fixture();
  std::mt19937 rng(3);
  const auto pick = [&](double x0, double x1, double z0, double z1, std::vector<glm::dvec3>& p,
                        std::vector<glm::dvec3>& n) {
    while (p.size() < 20) {
      const glm::dvec3 q(std::uniform_real_distribution<double>(x0, x1)(rng),
                         std::uniform_real_distribution<double>(0.2, 1.5)(rng),
                         std::uniform_real_distribution<double>(z0, z1)(rng));
      if (inside_solid(q)) continue;
      p.push_back(q);
      n.push_back(random_normals(1, unsigned(p.size() * 7 + 1))[0]);
    }
  };
  std::vector<glm::dvec3> bright_p, bright_n, dark_p, dark_n;
  pick(-2.5, -0.3, -1.5, 0.3, bright_p, bright_n);
  pick(0.4, 2.5, -1.5, 0.3, dark_p, dark_n);  // away from the doorway (z in [1, 2])
  const auto bright = reference_irradiance(f.reference, bright_p, bright_n, 32);
  const auto dark = reference_irradiance(f.reference, dark_p, dark_n, 32);
  double bright_mean = 0.0, worst = 0.0;
  for (const auto& e : bright) bright_mean += luminance(e) / double(bright.size());
  for (std::size_t i = 0; i < dark_p.size(); ++i)
    worst = std::max(worst, luminance(f.volume.evaluate(dark_p[i], dark_n[i])) - luminance(dark[i]));
  std::printf("bright side mean %.3f; worst excess on the dark side %.4f (%.2f %% of bright)\n", bright_mean, worst,
              100 * worst / bright_mean);
  EXPECT_LE(worst, 0.02 * bright_mean);
}

TEST(IrradianceRoom, ContinuousAcrossCellBoundaries) {
  const Fixture& f = fixture();
  const glm::dvec3 n = glm::normalize(glm::dvec3(-0.3, 0.8, 0.2));
  // Up from the (refined) floor into unrefined cells, and across the bright half.
  for (auto [a, b] : {std::pair{glm::dvec3(-1.0, 0.02, -1.0), glm::dvec3(-1.0, 1.58, -1.0)},
                      std::pair{glm::dvec3(-2.55, 1.2, -1.2), glm::dvec3(-0.3, 1.2, -1.2)}}) {
    const int steps = int(glm::length(b - a) / 0.001);
    double worst = 0.0;
    glm::dvec3 previous = f.volume.evaluate(a, n);
    for (int i = 1; i <= steps; ++i) {
      const glm::dvec3 e = f.volume.evaluate(a + (b - a) * (double(i) / steps), n);
      worst = std::max(worst, std::abs(luminance(e) - luminance(previous)) / luminance(previous));
      previous = e;
    }
    std::printf("largest change over 1 mm: %.3f %%\n", 100 * worst);
    EXPECT_LE(worst, 0.01);
  }
}

TEST(IrradianceRoom, CachedVolumeIsLoadedTheSecondTime) {
  const Scratch scratch("irradiance-cache");
  const DividedRoom room = make_divided_room();
  VolumeSettings s = volume_settings_for("volume");
  s.spacing = 1.0;
  RoomRadiance radiance(room.map, room.proxy, s.radiance);
  bool loaded = true;
  const auto first = cached_irradiance_volume(radiance, room.box_min, room.box_max, s, scratch.dir, &loaded);
  EXPECT_FALSE(loaded);
  const auto second = cached_irradiance_volume(radiance, room.box_min, room.box_max, s, scratch.dir, &loaded);
  EXPECT_TRUE(loaded);
  for (const glm::dvec3& n : random_normals(10, 4)) {
    const glm::dvec3 p(-1.2, 0.7, 0.1);
    EXPECT_EQ(first.evaluate(p, n), second.evaluate(p, n));
  }
  // Other settings are another key; a damaged file is rebuilt, not trusted.
  s.rays_per_probe = 256;
  cached_irradiance_volume(radiance, room.box_min, room.box_max, s, scratch.dir, &loaded);
  EXPECT_FALSE(loaded);
  for (const auto& entry : std::filesystem::directory_iterator(scratch.dir))
    std::filesystem::resize_file(entry.path(), 100);
  cached_irradiance_volume(radiance, room.box_min, room.box_max, s, scratch.dir, &loaded);
  EXPECT_FALSE(loaded);
  EXPECT_THROW(IrradianceVolume::load(scratch.dir / "missing.bin"), InputError);
}

}  // namespace
}  // namespace lumar::test
