// The GPU path: the volume uploaded as textures and evaluated per pixel gives what the
// CPU evaluation gives at the same world points; the Compositor shades with the volume,
// so an object's shading changes with where it stands, as the CPU volume predicts.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "../common/test_paths.h"
#include "irradiance_test_util.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/render/compositor.h"
#include "lumar/render/platform/context.h"
#include "lumar/render/renderer.h"
#include "lumar/scene/scene.h"

namespace lumar::test {
namespace {

gl::Context& context() {
  static std::unique_ptr<gl::Context> c = gl::create_headless_context();
  c->make_current();
  return *c;
}

Mesh sphere(float radius, int slices, int stacks) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i)
    for (int j = 0; j <= slices; ++j) {
      const double t = std::numbers::pi * i / stacks, p = 2 * std::numbers::pi * j / slices;
      const glm::vec3 n(std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p));
      m.positions.push_back(n * radius);
      m.normals.push_back(n);
    }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = std::uint32_t(i * (slices + 1) + j), b = a + std::uint32_t(slices + 1);
      m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
    }
  return m;
}

// OpenCV camera at eye looking at target (+Y up).
Pose look_at(const glm::dvec3& eye, const glm::dvec3& target) {
  const glm::dvec3 z = glm::normalize(target - eye), x = glm::normalize(glm::cross(z, glm::dvec3(0, -1, 0)));
  const glm::dvec3 y = glm::cross(z, x);
  return Pose::from_matrix(glm::dmat4(glm::dvec4(x, 0), glm::dvec4(y, 0), glm::dvec4(z, 0), glm::dvec4(eye, 1)));
}

CameraIntrinsics camera(int w, int h, double f) {
  CameraIntrinsics c;
  c.width = w, c.height = h, c.fx = c.fy = f, c.cx = (w - 1) / 2.0, c.cy = (h - 1) / 2.0;
  return c;
}

double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

struct Comparison {
  double mean_gpu = 0, mean_cpu = 0, mean_abs_levels = 0, max_levels = 0;
  int pixels = 0;
};

// Renders a sphere at `centre` and compares every covered pixel with the CPU volume.
Comparison compare(gl::Renderer& r, int id, const IrradianceVolume& v, const glm::dvec3& centre, const Pose& eye,
                   const glm::vec3& albedo, double exposure, const CameraIntrinsics& cam) {
  r.set_object_pose(id, glm::translate(glm::dmat4(1.0), centre));
  const cv::Mat video(cam.height, cam.width, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat out = r.render_overlay(video, eye, exposure);
  const cv::Mat positions = r.render_object_world_positions(eye);
  Comparison c;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const cv::Vec4f p = positions.at<cv::Vec4f>(y, x);
      if (p[3] < 0.5f) continue;
      const glm::dvec3 w(p[0], p[1], p[2]);
      const glm::dvec3 e = v.evaluate(w, glm::normalize(w - centre));
      const cv::Vec3b px = out.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) {
        const double linear = std::clamp(albedo[k] * e[k] / std::numbers::pi * exposure, 0.0, 1.0);
        const double encoded = linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
        const double diff = std::abs(encoded * 255.0 - px[2 - k]);
        c.mean_abs_levels += diff;
        c.max_levels = std::max(c.max_levels, diff);
        c.mean_gpu += srgb_decode(px[2 - k] / 255.0);
        c.mean_cpu += linear;
      }
      ++c.pixels;
    }
  c.mean_abs_levels /= 3.0 * std::max(c.pixels, 1);
  c.mean_gpu /= 3.0 * std::max(c.pixels, 1);
  c.mean_cpu /= 3.0 * std::max(c.pixels, 1);
  return c;
}

TEST(IrradianceGpu, ShaderMatchesTheCpuEvaluationAtTheSameWorldPoints) {
  context();
  const DividedRoom room = make_divided_room();
  for (const char* method : {"volume", "sh9"}) {
    VolumeSettings s = volume_settings_for(method);
    s.spacing = 0.5;
    RoomRadiance radiance(room.map, room.proxy, s.radiance);
    const IrradianceVolume v = IrradianceVolume::build(radiance, room.box_min, room.box_max, s);
    const CameraIntrinsics cam = camera(120, 90, 110);
    gl::Renderer r(cam);
    r.set_features({.antialiasing = false});  // each pixel its one point's shading
    const int id = r.add_object(sphere(0.3f, 64, 32));
    const glm::vec3 albedo(0.8f, 0.7f, 0.6f);
    r.set_object_material(id, albedo, SH9{});
    r.set_irradiance_volume(&v);
    for (const glm::dvec3 centre : {glm::dvec3(-1.0, 0.7, -0.6), glm::dvec3(0.4, 1.1, 1.3)}) {
      const Pose eye = look_at(centre + glm::dvec3(0.3, 0.2, -1.2), centre);
      const Comparison c = compare(r, id, v, centre, eye, albedo, 0.5, cam);
      std::printf("%-10s sphere at (%.1f %.1f %.1f): %d pixels, mean |GPU - CPU| %.3f levels, max %.1f\n", method,
                  centre.x, centre.y, centre.z, c.pixels, c.mean_abs_levels, c.max_levels);
      EXPECT_GT(c.pixels, 500);
      EXPECT_LT(c.mean_abs_levels, 0.6) << method;
      EXPECT_LE(c.max_levels, 4.0) << method;
    }
  }
}

TEST(IrradianceGpu, CompositorShadingFollowsTheObjectThroughTheSampleRoom) {
  context();
  const auto scene =
      std::make_shared<const LoadedScene>(load_scene_files(source_dir() / "data/scenes/room/scene.json"));
  const CameraIntrinsics cam = camera(120, 90, 110);
  Compositor compositor(scene, cam, cv::Mat(), cv::Mat());
  const IrradianceVolume* v = compositor.irradiance_volume().get();
  ASSERT_NE(v, nullptr);
  std::printf("sample room volume: %d probes, %d refined cells, %.0f ms to build\n", v->stats().probes,
              v->stats().refined_cells, v->stats().build_ms);
  gl::Renderer& r = compositor.renderer();
  r.set_features({.antialiasing = false});  // each pixel its one point's shading
  const int id = r.add_object(sphere(0.15f, 48, 24));
  const glm::vec3 albedo(0.6f);
  r.set_object_material(id, albedo, SH9{});
  // Hide the scene's own objects far away, so they do not cover the sphere.
  for (std::size_t k = 0; k < scene->objects.size(); ++k)
    compositor.set_object_pose(k, glm::translate(glm::dmat4(1.0), glm::dvec3(100, 100, 100)));
  std::vector<Comparison> at;
  for (const glm::dvec3 centre : {glm::dvec3(-1.0, 0.2, 1.0), glm::dvec3(0.3, 0.9, -0.3)}) {
    const Pose eye = look_at(centre + glm::dvec3(0.0, 0.3, -0.8), centre);
    at.push_back(compare(r, id, *v, centre, eye, albedo, 0.3, cam));
    std::printf("sphere at (%.1f %.1f %.1f): mean linear GPU %.4f CPU %.4f, |diff| %.3f levels\n", centre.x, centre.y,
                centre.z, at.back().mean_gpu, at.back().mean_cpu, at.back().mean_abs_levels);
  }
  const double gpu_ratio = at[1].mean_gpu / at[0].mean_gpu, cpu_ratio = at[1].mean_cpu / at[0].mean_cpu;
  std::printf("brightness ratio between the positions: GPU %.3f, CPU %.3f\n", gpu_ratio, cpu_ratio);
  EXPECT_GT(std::abs(cpu_ratio - 1.0), 0.05);  // the positions are lit differently
  EXPECT_NEAR(gpu_ratio, cpu_ratio, 0.02 * cpu_ratio);
}

// Per-vertex shading (ObjectShading::PerVertex) against per pixel on the figurine, where
// it stands and after it moved to where the room lights it differently: the vertices are
// lit again when it moves, so the two agree at both places.
TEST(IrradianceGpu, PerVertexShadingFollowsPerPixelAsTheFigurineMoves) {
  context();
  const auto scene =
      std::make_shared<const LoadedScene>(load_scene_files(source_dir() / "data/scenes/room/scene.json"));
  const CameraIntrinsics cam = camera(320, 240, 300);
  Compositor compositor(scene, cam, cv::Mat(), cv::Mat());
  compositor.set_features({.antialiasing = false, .self_occlusion = true, .noise = false, .blur = false});
  compositor.set_shadows_enabled(false);  // the figurine's pixels alone
  const cv::Mat video(cam.height, cam.width, CV_8UC3, cv::Scalar(0, 0, 0));
  const glm::dmat4 start = scene->objects[0].T_world_model;
  double mean[2][2] = {};  // [place][pixel, vertex]
  for (int place = 0; place < 2; ++place) {
    const glm::dvec3 shift = place == 0 ? glm::dvec3(0.0) : glm::dvec3(-1.1, 0.7, 1.0);
    compositor.set_object_pose(0, glm::translate(glm::dmat4(1.0), shift) * start);
    const glm::dvec3 centre = glm::dvec3(0.0, 0.15, 0.0) + shift;
    const Pose eye = look_at(centre + glm::dvec3(0.2, 0.3, -0.7), centre);
    const cv::Mat mask = compositor.renderer().render_object_mask(eye);
    ASSERT_GT(cv::countNonZero(mask), 3000);
    cv::Mat linear[2];
    for (int k = 0; k < 2; ++k) {
      compositor.set_object_shading(k == 0 ? ObjectShading::PerPixel : ObjectShading::PerVertex);
      const cv::Mat out = compositor.composite(video, eye, 1.0);
      out.convertTo(linear[k], CV_64FC3, 1.0 / 255.0);
      linear[k].forEach<cv::Vec3d>([](cv::Vec3d& v, const int*) {
        for (int c = 0; c < 3; ++c) v[c] = srgb_decode(v[c]);
      });
      mean[place][k] = cv::sum(cv::mean(linear[k], mask))[0] / 3.0;
    }
    cv::Mat diff;
    cv::absdiff(linear[0], linear[1], diff);
    const double mean_abs = cv::sum(cv::mean(diff, mask))[0] / 3.0;
    std::printf("place %d: %d pixels, mean linear per pixel %.4f, per vertex %.4f, mean |diff| %.2f %%\n", place,
                cv::countNonZero(mask), mean[place][0], mean[place][1], 100.0 * mean_abs / mean[place][0]);
    EXPECT_NEAR(mean[place][1], mean[place][0], 0.02 * mean[place][0]);
    EXPECT_LT(mean_abs, 0.06 * mean[place][0]);  // the shadow maps' edges soften between vertices
  }
  const double pixel_ratio = mean[1][0] / mean[0][0], vertex_ratio = mean[1][1] / mean[0][1];
  std::printf("brightness ratio between the places: per pixel %.3f, per vertex %.3f\n", pixel_ratio, vertex_ratio);
  EXPECT_GT(std::abs(pixel_ratio - 1.0), 0.05);  // the places are lit differently
  EXPECT_NEAR(vertex_ratio, pixel_ratio, 0.02 * pixel_ratio);
}

// Not a timing assertion: reports the per-pixel cost of volume shading on this GPU.
TEST(IrradianceGpu, ReportsShadingCostPerPixel) {
  context();
  const DividedRoom room = make_divided_room();
  const VolumeSettings s = volume_settings_for("volume");
  RoomRadiance radiance(room.map, room.proxy, s.radiance);
  VolumeSettings coarse = s;
  coarse.spacing = 0.5;
  const IrradianceVolume v = IrradianceVolume::build(radiance, room.box_min, room.box_max, coarse);
  const CameraIntrinsics cam = camera(160, 120, 100);
  gl::Renderer r(cam);
  const int id = r.add_object(sphere(0.6f, 64, 32));
  r.set_object_material(id, glm::vec3(0.7f), SH9{});
  r.set_object_pose(id, glm::translate(glm::dmat4(1.0), glm::dvec3(-1.0, 0.8, -0.6)));
  const Pose eye = look_at({-1.0, 0.9, -1.9}, {-1.0, 0.8, -0.6});
  const cv::Mat video(cam.height, cam.width, CV_8UC3, cv::Scalar(0, 0, 0));
  const int pixels = cv::countNonZero(r.render_object_mask(eye));
  double ms[2] = {0, 0};
  for (int pass = 0; pass < 2; ++pass) {
    r.set_irradiance_volume(pass ? &v : nullptr);
    gl::OverlayTimings t;
    r.render_overlay(video, eye, 1.0, &t);
    double best = 1e9;
    for (int i = 0; i < 3; ++i) {
      r.render_overlay(video, eye, 1.0, &t);
      best = std::min(best, t.objects_ms);
    }
    ms[pass] = best;
  }
  std::printf("object pass, %d object pixels: SH9 %.2f ms, volume %.2f ms -> volume shading %.1f ns per pixel (%s)\n",
              pixels, ms[0], ms[1], 1e6 * (ms[1] - ms[0]) / std::max(pixels, 1), context().renderer_name().c_str());
  EXPECT_GT(pixels, 3000);
}

}  // namespace
}  // namespace lumar::test
