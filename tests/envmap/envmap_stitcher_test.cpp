// Stitching a lat-long map from frames of a rotating camera: geometry against analytic
// maps, HDR merging of clipped brackets, and the reconstruction of shared real maps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lumar/base/color.h"
#include "lumar/base/error.h"

#include "lumar/base/latlong.h"
#include "lumar/envmap/envmap_quality.h"
#include "lumar/envmap/envmap_stitcher.h"
#include "lumar/envmap/hole_filling.h"
#include "lumar/envmap/orientation_refinement.h"
#include "lumar/envmap/sweep_path.h"
#include "lumar/lighting/sh.h"
#include "sweep_fixture.h"
#include "test_paths.h"

namespace lumar {
namespace {

// A smooth, everywhere positive map whose value at each texel is known in closed form.
EnvironmentMap analytic_map(int width, double azimuth_offset_deg) {
  EnvironmentMap map;
  map.width = width;
  map.height = width / 2;
  map.azimuth_offset_deg = azimuth_offset_deg;
  map.rgb.resize(std::size_t(width) * map.height * 3);
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < width; ++c) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, width, map.height);
      float* p = &map.rgb[(std::size_t(r) * width + c) * 3];
      p[0] = float(1.0 + 0.6 * d.x + 0.2 * d.y);
      p[1] = float(0.8 + 0.3 * d.y - 0.4 * d.z);
      p[2] = float(0.5 + 0.3 * std::sin(3 * d.x) * d.z + 0.2 * d.y);
    }
  return map;
}

calib::StitchSettings settings_for(const CameraIntrinsics& camera, const sim::SensorModel& sensor, int width) {
  calib::StitchSettings s;
  s.width = width;
  s.camera = camera;
  s.vignetting_a = sensor.vignetting_a;
  s.vignetting_b = sensor.vignetting_b;
  return s;
}

TEST(EnvmapStitcher, NoiseFreeSweepOfAnAnalyticMapLandsOnTheRightTexels) {
  // Every convention at once: distortion, OpenCV camera axes, the lat-long layout and
  // the azimuth offset. A wrong one shifts the smooth pattern by degrees, i.e. by
  // several percent.
  const EnvironmentMap source = analytic_map(256, 30.0);
  const CameraIntrinsics camera = test::webcam();
  sim::SensorModel sensor;
  sensor.read_noise = 0, sensor.shot_noise_gain = 0;
  const sim::EnvmapViewRenderer view(camera);
  auto settings = settings_for(camera, sensor, 256);
  settings.azimuth_offset_deg = 30.0;
  calib::EnvmapStitcher stitcher(settings);
  cv::RNG rng(1);
  const double exposure = 0.35;
  for (int k = 0; k < 40; ++k) {
    const glm::dquat R = calib::sweep_rotation((k + 0.5) / 40);
    stitcher.add_frame(sim::expose_8bit(view.render(source, R), camera, sensor, exposure, rng), R, exposure);
  }
  const EnvironmentMap result = stitcher.current_map();
  const cv::Mat coverage = stitcher.coverage();
  double worst = 0, sum = 0;
  int n = 0;
  for (int r = 0; r < result.height; ++r)
    for (int c = 0; c < result.width; ++c) {
      if (coverage.at<std::uint16_t>(r, c) == 0) continue;
      for (int ch = 0; ch < 3; ++ch) {
        const double want = source.rgb[(std::size_t(r) * 256 + c) * 3 + ch];
        const double e = std::abs(result.rgb[(std::size_t(r) * 256 + c) * 3 + ch] - want) / want;
        worst = std::max(worst, e), sum += e, ++n;
      }
    }
  EXPECT_GT(n, 3 * 0.85 * 256 * 128) << "the sweep should cover most of the sphere";
  EXPECT_LT(sum / n, 0.006) << "mean relative error";
  EXPECT_LT(worst, 0.04);
  EXPECT_EQ(stitcher.frames_added(), 40);
}

TEST(EnvmapStitcher, ShortExposuresRecoverWhatLongOnesClip) {
  // A small source 3000 times brighter than the rest: clipped at the long exposure,
  // measured at the short one.
  EnvironmentMap source = analytic_map(256, 0.0);
  const glm::dvec3 lamp = glm::normalize(glm::dvec3(0.3, 0.5, 0.8));
  for (int r = 0; r < source.height; ++r)
    for (int c = 0; c < source.width; ++c)
      if (glm::dot(latlong_pixel_direction(c, r, 256, 128), lamp) > std::cos(glm::radians(8.0)))
        for (int ch = 0; ch < 3; ++ch) source.rgb[(std::size_t(r) * 256 + c) * 3 + ch] = 3000.f;
  const CameraIntrinsics camera = test::webcam();
  sim::SensorModel sensor;
  const sim::EnvmapViewRenderer view(camera);
  auto stitch = [&](const std::vector<double>& exposures) {
    calib::EnvmapStitcher stitcher(settings_for(camera, sensor, 256));
    cv::RNG rng(3);
    for (int k = 0; k < 36; ++k) {
      const glm::dquat R = calib::sweep_rotation((k + 0.5) / 36);
      const double e = exposures[k % exposures.size()];
      stitcher.add_frame(sim::expose_8bit(view.render(source, R), camera, sensor, e, rng), R, e);
    }
    return stitcher.current_map();
  };
  const EnvironmentMap bracketed = stitch({0.4, 0.4 / 64, 0.4 / 4096});
  const EnvironmentMap single = stitch({0.4});
  const int lamp_col = int(latlong_coordinates(lamp, 256, 128).x),
            lamp_row = int(latlong_coordinates(lamp, 256, 128).y);
  EXPECT_NEAR(bracketed.texel(lamp_col, lamp_row).g, 3000.f, 3000.f * 0.05f);
  EXPECT_LT(single.texel(lamp_col, lamp_row).g, 10.f) << "one long exposure can only give a lower bound";
  // Away from the lamp both agree with the map (the dark exposures take little weight).
  const glm::dvec3 away(-0.7, 0.1, -0.7);
  const glm::dvec2 uv = latlong_coordinates(away, 256, 128);
  EXPECT_NEAR(bracketed.texel(int(uv.x), int(uv.y)).r, source.texel(int(uv.x), int(uv.y)).r, 0.03);
}

TEST(EnvmapStitcher, RejectsAFrameOfAnotherSize) {
  calib::StitchSettings s;
  s.width = 128;
  s.camera = test::webcam();
  calib::EnvmapStitcher stitcher(s);
  EXPECT_THROW(stitcher.add_frame(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(100)), glm::dquat(1, 0, 0, 0), 1.0),
               InputError);
  s.width = 101;
  EXPECT_THROW(calib::EnvmapStitcher{s}, InputError);
}

struct Quality {
  double median_error, worst_irradiance_direct, worst_irradiance_sh, coverage;
};

// Stitch a sweep with the given rotations, fill holes, and compare with the source.
Quality reconstruct(const test::Sweep& sweep, const std::vector<glm::dquat>& rotations, int width) {
  calib::EnvmapStitcher stitcher(settings_for(sweep.camera, sweep.sensor, width));
  for (std::size_t k = 0; k < sweep.frames.size(); ++k)
    stitcher.add_frame(sweep.frames[k], rotations[k], sweep.exposures[k]);
  EnvironmentMap result = stitcher.current_map();
  const cv::Mat coverage = stitcher.coverage();
  calib::fill_holes_push_pull(result, coverage);
  const EnvironmentMap reference = calib::downsample_map(sweep.source, width);
  Quality q{};
  q.median_error = calib::median_relative_luminance_error(result, reference, coverage);
  q.coverage = double(cv::countNonZero(coverage)) / coverage.total();
  const SH9 sh_result = project_radiance_sh9(result), sh_reference = project_radiance_sh9(reference);
  for (const glm::dvec3& n : calib::fibonacci_directions(48)) {
    const double want = luminance(calib::irradiance_direct(reference, n));
    q.worst_irradiance_direct =
        std::max(q.worst_irradiance_direct, std::abs(luminance(calib::irradiance_direct(result, n)) - want) / want);
    const double want_sh = luminance(sh9_irradiance(sh_reference, n));
    q.worst_irradiance_sh =
        std::max(q.worst_irradiance_sh, std::abs(luminance(sh9_irradiance(sh_result, n)) - want_sh) / want_sh);
  }
  return q;
}

class SharedMapSweep : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedMapSweep, RefinedSweepReconstructsTheMapAndItsIrradiance) {
  test::SweepSpec spec;
  spec.map = GetParam();
  const test::Sweep& sweep = test::synthetic_sweep(spec);
  const Quality q = reconstruct(sweep, test::refined_sweep(spec).rotations, 256);
  std::printf("%s: coverage %.3f, median luminance error %.4f, worst irradiance error %.4f (direct) %.4f (SH9)\n",
              GetParam().c_str(), q.coverage, q.median_error, q.worst_irradiance_direct, q.worst_irradiance_sh);
  EXPECT_GT(q.coverage, 0.9);
  EXPECT_LE(q.median_error, 0.05);
  EXPECT_LE(q.worst_irradiance_direct, 0.03);
  EXPECT_LE(q.worst_irradiance_sh, 0.03);
}

// One map here to keep the suite short; tests/cli/envmap.sh sweeps courtyard (a sun) end to end.
INSTANTIATE_TEST_SUITE_P(Maps, SharedMapSweep, ::testing::Values("studio"));

}  // namespace
}  // namespace lumar
