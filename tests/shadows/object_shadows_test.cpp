// ObjectShadows (object B shading object A) against independent references: the brute
// force reference_attenuation over every emitter texel, and analytic sun shadows.
#include "lumar/lighting/shadows/object_shadows.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

#include "lumar/base/error.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/scene.h"
#include "test_geometry.h"
#include "test_paths.h"

namespace lumar {
namespace {

glm::dmat4 translation(double x, double y, double z) { return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z)); }

// A flat n x n grid of vertices on y = 0 over [-half, half]^2, facing +Y.
Mesh make_grid(float half, int n) {
  Mesh m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.positions.push_back({-half + 2 * half * (i + 0.5f) / n, 0.0f, -half + 2 * half * (j + 0.5f) / n});
      m.normals.push_back({0, 1, 0});
    }
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const std::uint32_t a = std::uint32_t(i * n + j), b = a + 1, c = a + std::uint32_t(n), d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  return m;
}

// Emitters of distant suns (unit directions), each one sample and one "texel", so that
// reference_attenuation sees exactly the same light.
Emitters suns(const std::vector<glm::vec3>& directions) {
  Emitters e;
  e.distant = true;
  for (const glm::vec3& d : directions) {
    EmitterPoint p;
    p.position = glm::normalize(d);
    p.flux = glm::vec3(1.0f, 0.8f, 0.6f);
    e.texels.push_back(p);
    EmitterPatch patch;
    patch.first_sample = std::uint32_t(e.samples.size());
    patch.sample_count = 1;
    patch.flux = p.flux;
    e.samples.push_back(p);
    e.patches.push_back(patch);
  }
  return e;
}

// The brute-force attenuation of `receiver` (posed) by `occluder` (posed): every texel,
// no proxy, the occluder as a RayScene instance.
std::vector<glm::vec3> reference(const Mesh& receiver, const glm::dmat4& T_r, const Mesh& occluder,
                                 const glm::dmat4& T_o, const Emitters& emitters) {
  const Mesh posed = transformed(receiver, T_r);
  RayScene empty, occluders;
  occluders.add_instance(occluder, T_o);
  occluders.commit();
  empty.commit();
  return reference_attenuation(posed.positions, posed.normals, emitters, empty, occluders);
}

struct Errors {
  double mean_shadowed = 0, mean_lit = 0, max_lit = 0;
  std::size_t shadowed = 0, lit = 0;  // vertices where the reference is < 0.98 (any channel) / not
};
Errors compare(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& ref) {
  Errors e;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = std::max({std::abs(a[i].r - ref[i].r), std::abs(a[i].g - ref[i].g), std::abs(a[i].b - ref[i].b)});
    if (std::min({ref[i].r, ref[i].g, ref[i].b}) < 0.98f)
      e.mean_shadowed += d, ++e.shadowed;
    else
      e.mean_lit += d, ++e.lit, e.max_lit = std::max(e.max_lit, d);
  }
  if (e.shadowed) e.mean_shadowed /= double(e.shadowed);
  if (e.lit) e.mean_lit /= double(e.lit);
  return e;
}

// 1. The sample room's real map and proxy emitters: a ball on the floor under a hovering slab.
TEST(ObjectShadows, MatchesReferenceInSampleRoom) {
  const ShadowScene scene(load_scene_files(test::source_dir() / "data/scenes/room/scene.json"));
  const Mesh ball = test::make_sphere(glm::vec3(0.0f), 0.12f, 32, 16);
  const Mesh slab = test::make_box({-0.2f, -0.02f, -0.2f}, {0.2f, 0.02f, 0.2f});
  const glm::dmat4 T_ball = translation(-0.4, 0.12, 0.4), T_slab = translation(-0.3, 0.45, 0.35);
  const Mesh posed = transformed(ball, T_ball);
  const Emitters emitters = scene.emitters(posed.positions, posed.normals);

  ObjectShadows shadows(emitters);
  const int a = shadows.add_object(ball, T_ball);
  shadows.add_object(slab, T_slab);
  ASSERT_TRUE(shadows.update());
  const std::vector<glm::vec3> ref = reference(ball, T_ball, slab, T_slab, emitters);
  const Errors e = compare(shadows.vertex_attenuation(a), ref);
  std::printf(
      "sample room: %zu emitter samples, %zu texels; %zu shadowed vertices (ref < 0.98), mean |err| %.4f; "
      "%zu lit, mean |err| %.5f, max %.5f; %zu rays, %.2f ms\n",
      emitters.samples.size(), emitters.texels.size(), e.shadowed, e.mean_shadowed, e.lit, e.mean_lit, e.max_lit,
      shadows.stats().rays_traced, shadows.stats().ms);
  EXPECT_GT(e.shadowed, ball.positions.size() / 5);  // the slab really shades the ball
  // Emitter sampling: the default 8 points per patch stand for each patch's area.
  EXPECT_LT(e.mean_shadowed, 0.1);
  EXPECT_LE(e.mean_lit, 0.005);
  EXPECT_GT(shadows.stats().vertices_shadowed, ball.positions.size() / 5);
  {
    Emitters all = emitters;
    all.samples = all.texels;
    ObjectShadows exact(all);
    exact.add_object(ball, T_ball);
    exact.add_object(slab, T_slab);
    exact.update();
    const Errors x = compare(exact.vertex_attenuation(a), ref);
    std::printf("every texel a sample: shadowed mean |err| %.2g, lit %.2g\n", x.mean_shadowed, x.mean_lit);
    EXPECT_LT(x.mean_shadowed, 1e-4);  // the same lines as the reference
    EXPECT_LT(x.mean_lit, 1e-4);
  }
  // The error is the emitter sampling's: it shrinks with more points per patch.
  double previous = e.mean_shadowed;
  for (int spp : {32, 128}) {
    EmitterOptions opt;
    opt.samples_per_patch = spp;
    const Emitters more = scene.emitters(posed.positions, posed.normals, opt);
    ObjectShadows dense(more);
    dense.add_object(ball, T_ball);
    dense.add_object(slab, T_slab);
    dense.update();
    const Errors x = compare(dense.vertex_attenuation(a), reference(ball, T_ball, slab, T_slab, more));
    std::printf("%d per patch (%zu samples): shadowed mean |err| %.4f, lit %.2g\n", spp, more.samples.size(),
                x.mean_shadowed, x.mean_lit);
    EXPECT_LT(x.mean_shadowed, 0.6 * previous);
    EXPECT_LE(x.mean_lit, 0.005);
    previous = x.mean_shadowed;
  }
}

// 2. One sun: a floor patch under a slab is black exactly where the slab hides the sun.
TEST(ObjectShadows, SunShadowIsAnalytic) {
  const Mesh floor = make_grid(1.0f, 41);
  const Mesh slab = test::make_box({-0.3f, 0.5f, -0.25f}, {0.3f, 0.6f, 0.25f});
  for (const glm::vec3 dir : {glm::vec3(0, 1, 0), glm::vec3(0.5f, 1.0f, -0.3f)}) {
    const glm::vec3 d = glm::normalize(dir);
    ObjectShadows shadows(suns({d}));
    const int a = shadows.add_object(floor, glm::dmat4(1.0));
    shadows.add_object(slab, glm::dmat4(1.0));
    shadows.update();
    const auto& att = shadows.vertex_attenuation(a);
    std::size_t dark = 0;
    for (std::size_t i = 0; i < floor.positions.size(); ++i) {
      // Slab test of the line from the ray origin towards the sun.
      const glm::vec3 o = shadow_ray_origin(floor.positions[i], floor.normals[i]);
      const float t_in = (0.5f - o.y) / d.y, t_out = (0.6f - o.y) / d.y;
      const glm::vec3 p = o + 0.5f * (t_in + t_out) * d;  // at mid height (only x, z matter)
      const float dx = std::abs(d.x / d.y) * 0.05f, dz = std::abs(d.z / d.y) * 0.05f;  // drift over half the slab
      const bool inside = std::abs(p.x) + dx < 0.3f && std::abs(p.z) + dz < 0.25f;
      const bool outside = std::abs(p.x) - dx > 0.3f || std::abs(p.z) - dz > 0.25f;
      if (inside) {
        EXPECT_EQ(att[i], glm::vec3(0.0f)) << "vertex " << i;
        ++dark;
      } else if (outside) {
        EXPECT_EQ(att[i], glm::vec3(1.0f)) << "vertex " << i;
      }
    }
    EXPECT_GT(dark, 100u);
  }
}

// 3. Moving the occluder away clears the shadow; nothing moved: no work. Bad ids throw.
TEST(ObjectShadows, UpdatesOnlyWhenMoved) {
  const Mesh floor = make_grid(0.5f, 21);
  const Mesh slab = test::make_box({-0.2f, -0.05f, -0.2f}, {0.2f, 0.05f, 0.2f});
  ObjectShadows shadows(suns({{0, 1, 0}}));
  const int a = shadows.add_object(floor, glm::dmat4(1.0));
  EXPECT_TRUE(shadows.update());
  for (const glm::vec3& v : shadows.vertex_attenuation(a)) EXPECT_EQ(v, glm::vec3(1.0f));  // alone: no shadow
  EXPECT_EQ(shadows.stats().rays_traced, 0u);
  const int b = shadows.add_object(slab, translation(0, 0.5, 0));
  EXPECT_TRUE(shadows.update());
  EXPECT_GT(shadows.stats().vertices_shadowed, 40u);
  EXPECT_FALSE(shadows.update());
  EXPECT_FALSE(shadows.stats().recomputed);
  shadows.set_object_pose(b, translation(0, 0.5, 0));  // same pose: still nothing to do
  EXPECT_FALSE(shadows.update());
  shadows.set_object_pose(b, translation(3, 0.5, 0));
  EXPECT_TRUE(shadows.update());
  for (const glm::vec3& v : shadows.vertex_attenuation(a)) EXPECT_EQ(v, glm::vec3(1.0f));
  EXPECT_EQ(shadows.stats().vertices_shadowed, 0u);
  EXPECT_FALSE(shadows.update());
  EXPECT_THROW(shadows.set_object_pose(2, glm::dmat4(1.0)), RuntimeError);
  EXPECT_THROW(shadows.set_object_pose(-1, glm::dmat4(1.0)), RuntimeError);
  EXPECT_THROW(shadows.vertex_attenuation(5), RuntimeError);
}

// 4. Each object receives from the other: two rotated, scaled balls side by side, suns
// from both sides; both match the brute-force reference.
TEST(ObjectShadows, ObjectsShadowEachOther) {
  const Mesh ball = test::make_sphere(glm::vec3(0.0f), 1.0f, 24, 12);
  const glm::dmat4 T_a =
      glm::rotate(translation(0, 0.1, 0), 0.7, glm::dvec3(0.3, 1, 0.2)) * glm::scale(glm::dmat4(1.0), glm::dvec3(0.1));
  const glm::dmat4 T_b = glm::rotate(translation(0.35, 0.12, 0.02), -1.1, glm::dvec3(1, 0.2, 0)) *
                         glm::scale(glm::dmat4(1.0), glm::dvec3(0.12));
  const Emitters emitters = suns({{1, 0.15f, 0}, {-1, 0.25f, 0.05f}, {0.2f, 1, 0.1f}});
  ObjectShadows shadows(emitters);
  const int a = shadows.add_object(ball, T_a), b = shadows.add_object(ball, T_b);
  shadows.update();
  const Errors ea = compare(shadows.vertex_attenuation(a), reference(ball, T_a, ball, T_b, emitters));
  const Errors eb = compare(shadows.vertex_attenuation(b), reference(ball, T_b, ball, T_a, emitters));
  std::printf("two balls: A %zu shadowed (mean |err| %.2g), B %zu shadowed (mean |err| %.2g)\n", ea.shadowed,
              ea.mean_shadowed, eb.shadowed, eb.mean_shadowed);
  for (const Errors& e : {ea, eb}) {
    EXPECT_GT(e.shadowed, 20u);
    EXPECT_LT(e.mean_shadowed, 1e-3);  // same lines: only grazing float differences
    EXPECT_LT(e.mean_lit, 1e-3);
  }
}

// 5. The occluder gliding a few millimetres per update: most blocked lines are proven by
// walks from the last update's blockers, and every result equals a fresh computation at
// the same poses (which has no blockers to walk from); a jump turns the walks off.
TEST(ObjectShadows, SlowMotionWalksFromLastBlockers) {
  const Mesh ball = test::make_sphere(glm::vec3(0.0f), 1.0f, 24, 12);
  const glm::dmat4 T_a = glm::scale(translation(0, 0.1, 0), glm::dvec3(0.1));
  const Emitters emitters = suns({{1, 0.15f, 0}, {-1, 0.25f, 0.05f}, {0.2f, 1, 0.1f}, {0.6f, 0.5f, -0.4f}});
  const auto pose_b = [](double x) {
    return glm::rotate(translation(x, 0.14, 0.02), 3.0 * x, glm::dvec3(0.2, 1, 0)) *
           glm::scale(glm::dmat4(1.0), glm::dvec3(0.12));
  };
  ObjectShadows moving(emitters);
  const int a = moving.add_object(ball, T_a), b = moving.add_object(ball, pose_b(0.3));
  for (int k = 0; k <= 6; ++k) {
    const double x = k < 6 ? 0.3 + 0.004 * k : 0.45;  // the last: a 13 cm jump
    moving.set_object_pose(b, pose_b(x));
    moving.update();
    ObjectShadows fresh(emitters);
    fresh.add_object(ball, T_a), fresh.add_object(ball, pose_b(x));
    fresh.update();
    for (const int id : {a, b})
      EXPECT_EQ(moving.vertex_attenuation(id), fresh.vertex_attenuation(id)) << "update " << k;
    const ObjectShadowStats& st = moving.stats();
    EXPECT_EQ(st.lines_blocked, fresh.stats().lines_blocked);
    std::printf("update %d: %zu lines blocked, %zu proven by walks\n", k, st.lines_blocked, st.lines_walked);
    EXPECT_GT(st.lines_blocked, 50u);
    if (k == 0 || k == 6)
      EXPECT_EQ(st.lines_walked, 0u);
    else
      EXPECT_GT(double(st.lines_walked), 0.5 * double(st.lines_blocked)) << "update " << k;
  }
}

}  // namespace
}  // namespace lumar
