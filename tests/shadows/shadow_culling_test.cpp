// The per-frame culling against brute force: a box's shadow cone against an exact
// segment/box test, the receiver grids' bookkeeping, and, over many poses of the
// figurine (touching the floor, next to an emitter point, under a distant sun), every
// line that tracing all lines finds blocked must be among the culled update's candidates.
#include <gtest/gtest.h>

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>
#include <vector>

#include "lumar/lighting/shadows/shadow_cone.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/lighting/shadows/shadow_receiver_grid.h"
#include "lumar/scene/scene.h"
#include "sample_room_lines.h"
#include "shadow_test_util.h"
#include "test_paths.h"

namespace lumar {
namespace {

struct Box {
  glm::dvec3 centre;
  glm::dmat3 axes;  // columns: unit axes
  glm::dvec3 half;
  std::array<glm::vec3, 8> corners() const {
    std::array<glm::vec3, 8> c;
    for (int k = 0; k < 8; ++k) {
      glm::dvec3 p = centre;
      for (int a = 0; a < 3; ++a) p += axes[a] * (((k >> a) & 1) ? half[a] : -half[a]);
      c[std::size_t(k)] = glm::vec3(p);
    }
    return c;
  }
  // Whether the segment p0 -> p1 meets the box (slabs, double precision).
  bool crossed_by(const glm::dvec3& p0, const glm::dvec3& p1) const {
    double t0 = 0, t1 = 1;
    for (int a = 0; a < 3; ++a) {
      const double o = glm::dot(p0 - centre, axes[a]), d = glm::dot(p1 - p0, axes[a]);
      if (std::abs(d) < 1e-15) {
        if (std::abs(o) > half[a]) return false;
        continue;
      }
      double ta = (-half[a] - o) / d, tb = (half[a] - o) / d;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
};

TEST(ShadowCone, ContainsEveryPointWhoseLineCrossesTheBox) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
  std::size_t crossing = 0, rejected = 0, total = 0, everything = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Box box;
    box.centre = {u(rng), u(rng), u(rng)};
    box.axes = glm::mat3_cast(glm::normalize(glm::dquat(u(rng), u(rng), u(rng), u(rng))));
    box.half = {0.02 + 0.3 * unit(rng), 0.02 + 0.3 * unit(rng), 0.02 + 0.3 * unit(rng)};
    const bool distant = trial % 4 == 3;
    glm::dvec3 e;
    if (distant) {
      e = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    } else {
      // From inside the box and grazing its faces out to several metres away.
      const double reach = glm::length(box.half) * std::pow(10.0, 2.0 * unit(rng) - 0.7);
      e = box.centre + reach * glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
      if (trial % 50 == 0) e = box.centre + box.axes[0] * box.half.x;  // exactly on a face
    }
    const ShadowCone cone(box.corners(), glm::vec3(e), distant);
    everything += cone.everything();
    for (int k = 0; k < 40; ++k) {
      glm::dvec3 x;
      if (k % 2 == 0) {
        x = 3.0 * glm::dvec3(u(rng), u(rng), u(rng));
      } else {  // through a point of the box, beyond it (or just in front of it)
        glm::dvec3 y = box.centre;
        for (int a = 0; a < 3; ++a) y += box.axes[a] * (box.half[a] * u(rng) * 1.02);
        x = distant ? y - (0.5 + 2.0 * unit(rng)) * e : e + (0.8 + 3.0 * unit(rng)) * (y - e);
      }
      // The shadow ray stops just short of the emitter (shadow_ray_t_far).
      const glm::dvec3 end =
          x + double(shadow_ray_t_far(distant)) * ((distant ? x + double(kDistantLineLength) * e : e) - x);
      const bool crosses = box.crossed_by(x, end);
      const bool said = cone.contains(glm::vec3(x));
      ++total;
      crossing += crosses;
      rejected += !said;
      if (crosses) {
        ASSERT_TRUE(said) << "trial " << trial << " point " << k;
      }
    }
  }
  std::printf("cone: %zu points, %zu lines cross the box, %zu rejected, %zu cones contain everything\n", total,
              crossing, rejected, everything);
  EXPECT_GT(crossing, total / 5);
  EXPECT_GT(rejected, total / 3);  // and it does reject
  EXPECT_LT(everything, 700u);     // only emitters inside the box
}

TEST(ShadowReceiverGrid, EveryReceiverInItsBucket) {
  // A floor and a table top: two flat groups, one per level.
  std::vector<glm::vec3> points, normals;
  test::floor_grid(0.0f, 0.0f, 1.0f, 40, 0.0f, points, normals);
  test::floor_grid(0.3f, -0.2f, 0.3f, 20, 0.72f, points, normals);
  const ReceiverGrids g = build_receiver_grids(points, normals);
  ASSERT_EQ(g.grids.size(), 2u);
  ASSERT_EQ(g.order.size(), points.size());
  std::vector<int> seen(points.size(), 0);
  for (const std::uint32_t r : g.order) ++seen[r];
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(points.size()));
  for (const ReceiverGrid& grid : g.grids) {
    EXPECT_NEAR(std::abs(grid.normal.y), 1.0f, 1e-5f);  // flat: on one level
    EXPECT_LT(grid.h_max - grid.h_min, 1e-4f);
    for (int j = 0; j < grid.nv; ++j)
      for (int i = 0; i < grid.nu; ++i) {
        const std::uint32_t b = grid.first_bucket + std::uint32_t(j * grid.nu + i);
        for (std::uint32_t k = g.bucket_first[b]; k < g.bucket_first[b + 1]; ++k) {
          const glm::vec3 d = points[g.order[k]] - grid.origin;
          const float u = glm::dot(d, grid.u_axis), v = glm::dot(d, grid.v_axis), h = glm::dot(d, grid.normal);
          ASSERT_GE(u, grid.u0 + float(i) * grid.cell - 1e-5f);
          ASSERT_LE(u, grid.u0 + float(i + 1) * grid.cell + 1e-5f);
          ASSERT_GE(v, grid.v0 + float(j) * grid.cell - 1e-5f);
          ASSERT_LE(v, grid.v0 + float(j + 1) * grid.cell + 1e-5f);
          ASSERT_GE(h, grid.h_min);
          ASSERT_LE(h, grid.h_max);
        }
      }
  }
}

// Updates with culling on and off; returns the lines tracing all of them found blocked
// (ascending). Every one of them must be a candidate of the culled update, and the culled
// update must find exactly them.
std::vector<std::uint32_t> culled_matches_all(LineShadows& shadows, const std::string& what) {
  shadows.set_culling(true);
  shadows.update();
  std::vector<std::uint32_t> traced = shadows.traced_lines(), culled_blocked = shadows.blocked_lines();
  const auto culled = shadows.attenuation();
  shadows.set_culling(false);
  shadows.update();
  const std::vector<std::uint32_t>& blocked = shadows.blocked_lines();
  std::sort(traced.begin(), traced.end());
  std::sort(culled_blocked.begin(), culled_blocked.end());
  std::size_t missed = 0;
  for (const std::uint32_t li : blocked) missed += !std::binary_search(traced.begin(), traced.end(), li);
  EXPECT_EQ(missed, 0u) << what << ": blocked lines outside the candidates";
  EXPECT_EQ(culled_blocked, blocked) << what;
  float diff = 0;
  for (std::size_t i = 0; i < culled.size(); ++i)
    diff = std::max(diff, glm::length(culled[i] - shadows.attenuation()[i]));
  EXPECT_LT(diff, 1e-5f) << what;
  EXPECT_LT(traced.size(), shadows.lines().lines.size()) << what;
  return blocked;
}

// Poses the (first) object and checks the culled update; returns how many lines are blocked.
std::size_t check_pose(LineShadows& shadows, const glm::dmat4& T, const char* what) {
  shadows.set_object_pose(0, T);
  return culled_matches_all(shadows, what).size();
}

// The emitter sample point with the most flux: lines to it shadow the most.
const EmitterPoint& brightest_sample(const ShadowLines& lines) {
  return *std::max_element(lines.samples.begin(), lines.samples.end(),
                           [](const EmitterPoint& a, const EmitterPoint& b) { return a.flux.g < b.flux.g; });
}

TEST(ShadowCulling, CandidatesContainEveryBlockedLine) {
  const test::SampleRoomLines room = test::sample_room_lines(900);
  LineShadows shadows(room.lines);
  const auto& fig = room.figurine();
  shadows.add_object(fig.model, fig.T_world_model);
  const auto [lo, hi] = fig.model.bounds();
  const glm::dvec3 model_centre = 0.5 * glm::dvec3(lo + hi);
  // The figurine rotated about the vertical, its box centre at `at`.
  const auto pose = [&](double yaw, const glm::dvec3& at) {
    const glm::dmat4 R = glm::rotate(glm::dmat4(1.0), yaw, glm::dvec3(0, 1, 0)) * fig.T_world_model;
    const glm::dvec3 c = glm::dvec3(R * glm::dvec4(model_centre, 1.0));
    return glm::translate(glm::dmat4(1.0), at - c) * R;
  };
  // World height of the posed mesh's lowest vertex.
  const auto lowest = [&](const glm::dmat4& T) {
    double y = 1e30;
    for (const glm::vec3& p : fig.model.positions) y = std::min(y, (T * glm::dvec4(glm::dvec3(p), 1.0)).y);
    return y;
  };
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t blocked = 0;
  for (int k = 0; k < 12; ++k) {
    const Scene& s = room.scene->scene().manifest;
    const glm::dvec3 at(s.movement_min.x + u(rng) * (s.movement_max.x - s.movement_min.x), 0.1 + 0.4 * u(rng),
                        s.movement_min.z + u(rng) * (s.movement_max.z - s.movement_min.z));
    glm::dmat4 T = pose(6.3 * u(rng), at);
    if (k % 3 == 0)
      T = glm::translate(glm::dmat4(1.0), glm::dvec3(0, -lowest(T) - 0.002, 0)) * T;  // on the floor, 2 mm in
    blocked += check_pose(shadows, T, k % 3 == 0 ? "touching the floor" : "random");
  }
  // Next to the brightest emitter point: the figurine's box centre 8-20 cm from it along
  // its normal (the point inside the box or just outside), and at it.
  const EmitterPoint& brightest = brightest_sample(room.lines);
  const glm::dvec3 x(brightest.position), n(brightest.normal);
  for (const double d : {0.08, 0.12, 0.2, 0.0}) {
    // d = 0: the emitter point inside the figurine's box.
    blocked += check_pose(shadows, pose(0.7, x + d * n), d == 0.0 ? "emitter inside the box" : "near an emitter");
  }
  EXPECT_GT(blocked, 1000u);
}

// The figurine gliding a few millimetres per frame: most lines it blocked in the last
// frame are proven blocked again by walking over its mesh from last frame's blocker,
// without Embree, and the result stays exactly that of tracing every line.
TEST(ShadowCulling, SlowMotionReusesLastFramesBlockers) {
  const test::SampleRoomLines room = test::sample_room_lines(900);
  const auto& fig = room.figurine();
  LineShadows shadows(room.lines), oracle(room.lines);
  oracle.set_culling(false);
  const auto pose = [&](int k) {
    return glm::translate(glm::dmat4(1.0), glm::dvec3(0.004 * k, 0.12, 0.003 * k)) *
           glm::rotate(glm::dmat4(1.0), 0.01 * k, glm::dvec3(0, 1, 0)) * fig.T_world_model;
  };
  shadows.add_object(fig.model, pose(0));
  oracle.add_object(fig.model, pose(0));
  for (int k = 0; k < 8; ++k) {
    shadows.set_object_pose(0, pose(k));
    oracle.set_object_pose(0, pose(k));
    shadows.update();
    oracle.update();
    std::vector<std::uint32_t> blocked = shadows.blocked_lines();
    std::sort(blocked.begin(), blocked.end());
    EXPECT_EQ(blocked, oracle.blocked_lines()) << "frame " << k;
    const ShadowFrameStats& st = shadows.stats();
    std::printf("frame %d: %zu lines blocked, %zu of them proven by walking\n", k, st.lines_blocked, st.lines_walked);
    if (k == 0)
      EXPECT_EQ(st.lines_walked, 0u);  // no last frame
    else
      EXPECT_GT(double(st.lines_walked), 0.6 * double(st.lines_blocked)) << "frame " << k;
  }
  // A jump of 0.3 m: no walks (they would all fail), the same lines as tracing all.
  const glm::dmat4 far = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.3, 0.0, 0.0)) * pose(7);
  shadows.set_object_pose(0, far);
  oracle.set_object_pose(0, far);
  shadows.update();
  oracle.update();
  std::vector<std::uint32_t> blocked = shadows.blocked_lines();
  std::sort(blocked.begin(), blocked.end());
  EXPECT_EQ(blocked, oracle.blocked_lines()) << "after the jump";
  EXPECT_GT(blocked.size(), 1000u);
  EXPECT_EQ(shadows.stats().lines_walked, 0u);
}

TEST(ShadowCulling, TwoObjectsCountEachBlockedLineOnce) {
  const test::SampleRoomLines room = test::sample_room_lines(900);
  const ShadowLines& lines = room.lines;
  const auto& fig = room.figurine();
  const glm::dmat4 T_fig = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0.1, 0)) * fig.T_world_model;
  const auto [lo, hi] = fig.model.bounds();
  const glm::dvec3 centre(T_fig * glm::dvec4(0.5 * glm::dvec3(lo + hi), 1.0));
  const Mesh ball = test::make_sphere({0, 0, 0}, 0.12f, 32, 16);
  LineShadows both(lines), fig_only(lines), ball_only(lines);
  both.add_object(fig.model, T_fig);
  fig_only.add_object(fig.model, T_fig);
  both.add_object(ball, glm::dmat4(1.0));
  ball_only.add_object(ball, glm::dmat4(1.0));
  fig_only.update();
  const EmitterPoint& brightest = brightest_sample(room.lines);
  const glm::dvec3 towards = glm::normalize(glm::dvec3(brightest.position) - centre);
  for (int k = 0; k < 3; ++k) {
    // The ball between the figurine and the brightest emitter point: many lines pass both.
    const glm::dmat4 T_ball = glm::translate(glm::dmat4(1.0), centre + (0.25 + 0.05 * k) * towards);
    both.set_object_pose(1, T_ball);
    ball_only.set_object_pose(0, T_ball);
    ball_only.update();
    // The culled update finds each line once, however many objects block it.
    const std::vector<std::uint32_t> all = culled_matches_all(both, "two objects, pose " + std::to_string(k));
    EXPECT_LT(all.size() + 200, fig_only.blocked_lines().size() + ball_only.blocked_lines().size())
        << "pose " << k << ": the objects must share blocked lines for this test";
    std::printf("two objects, pose %d: %zu lines blocked (figurine alone %zu, ball alone %zu)\n", k, all.size(),
                fig_only.blocked_lines().size(), ball_only.blocked_lines().size());
  }
}

TEST(ShadowCulling, CandidatesContainEveryBlockedLineUnderASun) {
  const EnvironmentMap sky = test::make_sun_sky(256, 35.0, 60.0, 1.5, 20000.0f);
  Scene s = load_scene(test::source_dir() / "data/scenes/room/scene.json");
  const Mesh fig = load_mesh(s.objects[0].mesh);
  std::vector<ShadowScene::Object> objects{{"figurine", fig, s.objects[0].T_world_model, glm::vec3(0.8f), {}}};
  const ShadowScene scene(sky, true, test::make_ground(5.0f), std::move(objects));
  std::vector<glm::vec3> positions, normals;
  test::floor_grid(-0.2f, 0.3f, 1.0f, 30, 0.0f, positions, normals);
  const Emitters e = scene.emitters(positions, normals);
  LineShadows shadows(build_shadow_lines(positions, normals, e, scene.proxy()));
  shadows.add_object(fig, s.objects[0].T_world_model);
  std::size_t blocked = 0;
  for (int k = 0; k < 6; ++k) {
    const glm::dmat4 T = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.1 * k, 0.05 * (k % 3), 0.08 * k)) *
                         glm::rotate(glm::dmat4(1.0), 0.9 * k, glm::dvec3(0, 1, 0)) * s.objects[0].T_world_model;
    blocked += check_pose(shadows, T, "sun");
  }
  EXPECT_GT(blocked, 500u);
}

}  // namespace
}  // namespace lumar
