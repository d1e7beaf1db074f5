// Environment maps: real HDR maps, a grey map written by hand, exact round trips,
// bilinear lookups against texels, the azimuth rotation and the error cases.
#include "lumar/scene/envmap.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>

#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "test_paths.h"

namespace lumar {
namespace {

using test::Scratch;

std::filesystem::path real_map(const std::string& name) {
  return test::shared_dir() / "data/envmaps" / (name + ".exr");
}

void expect_input_error_naming(const std::filesystem::path& path, const std::string& needle = "") {
  try {
    load_environment_map(path);
    FAIL() << "no InputError for " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "message must be one line";
  }
}

EnvironmentMap gradient_map(int width, int height) {
  EnvironmentMap map;
  map.width = width;
  map.height = height;
  map.rgb.resize(std::size_t(width) * height * 3);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      for (int k = 0; k < 3; ++k) map.rgb[(std::size_t(r) * width + c) * 3 + k] = float(1 + c + 1000 * r + 0.25 * k);
  return map;
}

TEST(EnvironmentMap, RealMapsLoadFiniteAndNearlyNonNegative) {
  for (const char* name : {"city", "courtyard", "interior", "studio"}) {
    const EnvironmentMap map = load_environment_map(real_map(name));
    EXPECT_EQ(map.width, 1024) << name;
    EXPECT_EQ(map.height, 512) << name;
    ASSERT_EQ(map.rgb.size(), 1024u * 512u * 3u);
    float lo = 1e30f, hi = 0.f;
    double sum = 0.0;
    std::size_t negative = 0;
    for (float v : map.rgb) {
      ASSERT_TRUE(std::isfinite(v)) << name;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      sum += v;
      negative += v < 0.f;
    }
    // The source files hold a few slightly negative values (resampling ringing in the
    // originals); the loader keeps the file's values as they are.
    std::printf("[ measured ] %-9s min %.3g, max %.4g, mean %.4g, negative values %zu of %zu\n", name, lo, hi,
                sum / double(map.rgb.size()), negative, map.rgb.size());
    EXPECT_GE(lo, -0.01f) << name;
    EXPECT_LT(negative, map.rgb.size() / 100) << name;
    EXPECT_GT(sum / double(map.rgb.size()), 0.01) << name;  // not black
    EXPECT_GT(hi, 10.f) << name << ": HDR maps hold sources far above 1";
  }
}

TEST(EnvironmentMap, GreyFileIsReplicatedAndTopRowFirst) {
  // PFM stores rows bottom to top; the map must come out top row first.
  const Scratch scratch("envmap-grey");
  const auto& dir = scratch.dir;
  const auto path = dir / "grey.pfm";
  {
    std::ofstream f(path, std::ios::binary);
    f << "Pf\n4 2\n-1.0\n";
    const float bottom_then_top[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    f.write(reinterpret_cast<const char*>(bottom_then_top), sizeof bottom_then_top);
  }
  const EnvironmentMap map = load_environment_map(path);
  ASSERT_EQ(map.width, 4);
  ASSERT_EQ(map.height, 2);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(map.texel(c, 0), glm::vec3(float(5 + c))) << c;
    EXPECT_EQ(map.texel(c, 1), glm::vec3(float(1 + c))) << c;
  }
}

TEST(EnvironmentMap, SaveLoadRoundTripIsBitExact) {
  const Scratch scratch("envmap-roundtrip");
  const auto& dir = scratch.dir;
  const EnvironmentMap original = load_environment_map(real_map("courtyard"));
  save_environment_map(dir / "copy.exr", original);
  // Nothing but the map is left in the folder (no temporary).
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
  const EnvironmentMap copy = load_environment_map(dir / "copy.exr");
  ASSERT_EQ(copy.width, original.width);
  ASSERT_EQ(copy.height, original.height);
  ASSERT_EQ(copy.rgb.size(), original.rgb.size());
  EXPECT_EQ(std::memcmp(copy.rgb.data(), original.rgb.data(), original.rgb.size() * sizeof(float)), 0);

  // Values a half-float file could not hold survive too.
  EnvironmentMap fine = gradient_map(8, 4);
  fine.rgb[5] = 1.0f + 1e-7f * 3;
  fine.rgb[7] = 123456.789f;
  save_environment_map(dir / "fine.exr", fine);
  EXPECT_EQ(load_environment_map(dir / "fine.exr").rgb, fine.rgb);
}

TEST(EnvironmentMap, AzimuthRotationFollowsTheConvention) {
  EnvironmentMap map;
  map.azimuth_offset_deg = 90.0;
  // Ry(90) maps +Z to +X and +X to -Z; +Y stays.
  EXPECT_NEAR(glm::distance(map.world_direction({0, 0, 1}), glm::dvec3(1, 0, 0)), 0.0, 1e-15);
  EXPECT_NEAR(glm::distance(map.world_direction({1, 0, 0}), glm::dvec3(0, 0, -1)), 0.0, 1e-15);
  EXPECT_NEAR(glm::distance(map.world_direction({0, 1, 0}), glm::dvec3(0, 1, 0)), 0.0, 1e-15);
  map.azimuth_offset_deg = 30.0;
  const glm::dvec3 z = map.world_direction({0, 0, 1});
  EXPECT_NEAR(glm::distance(z, glm::dvec3(0.5, 0, std::sqrt(3.0) / 2)), 0.0, 1e-15);

  map.azimuth_offset_deg = -137.25;
  for (const glm::dvec3 d : {glm::dvec3(0.3, -0.4, 0.866), glm::dvec3(-1, 2, 3), glm::dvec3(0, -1, 0)}) {
    EXPECT_NEAR(glm::distance(map.map_direction(map.world_direction(d)), d), 0.0, 1e-14);
    EXPECT_NEAR(glm::distance(map.world_direction(map.map_direction(d)), d), 0.0, 1e-14);
    EXPECT_NEAR(glm::length(map.world_direction(d)), glm::length(d), 1e-14);
  }
}

TEST(EnvironmentMap, RadianceAtTexelCentresIsTheTexel) {
  EnvironmentMap map = load_environment_map(real_map("studio"));
  map.azimuth_offset_deg = 23.0;
  int checked = 0;
  for (int r = 0; r < map.height; r += 7)
    for (int c = 0; c < map.width; c += 13) {
      const glm::dvec3 world = map.world_direction(latlong_pixel_direction(c, r, map.width, map.height));
      ASSERT_EQ(map.radiance(world), map.texel(c, r)) << c << "," << r;
      ++checked;
    }
  for (const auto& [c, r] :
       {std::pair{0, 0}, {map.width - 1, 0}, {0, map.height - 1}, {map.width - 1, map.height - 1}}) {
    const glm::dvec3 world = map.world_direction(latlong_pixel_direction(c, r, map.width, map.height));
    EXPECT_EQ(map.radiance(world), map.texel(c, r)) << c << "," << r;
  }
  EXPECT_GT(checked, 5000);
}

TEST(EnvironmentMap, RadianceInterpolatesWrapsAndClamps) {
  EnvironmentMap map = gradient_map(16, 8);
  const auto at = [&](double u, double v) { return map.radiance(latlong_direction(u, v, 16, 8)); };
  const auto near = [](glm::vec3 a, glm::vec3 b) { return glm::distance(a, b) < 1e-3f * glm::length(b); };
  // Halfway between the centres of columns 3 and 4 of row 2, a quarter down towards row 3.
  const glm::vec3 expected =
      0.75f * (0.5f * (map.texel(3, 2) + map.texel(4, 2))) + 0.25f * (0.5f * (map.texel(3, 3) + map.texel(4, 3)));
  EXPECT_TRUE(near(at(4.0, 2.75), expected));
  // u = 0 is halfway between the last column and the first.
  EXPECT_TRUE(near(at(0.0, 4.5), 0.5f * (map.texel(15, 4) + map.texel(0, 4))));
  EXPECT_TRUE(near(at(15.75, 4.5), 0.75f * map.texel(15, 4) + 0.25f * map.texel(0, 4)));
  // Above the first row's centres and below the last row's, rows are clamped.
  EXPECT_TRUE(near(at(5.5, 0.2), map.texel(5, 0)));
  EXPECT_TRUE(near(at(5.5, 7.9), map.texel(5, 7)));
  // No direction, no radiance (and no out-of-range read).
  EXPECT_EQ(map.radiance(glm::dvec3(0.0)), glm::vec3(0.f));
}

TEST(EnvironmentMap, BadFilesThrowInputErrorNamingTheFile) {
  const Scratch scratch("envmap-bad");
  const auto& dir = scratch.dir;
  expect_input_error_naming(dir / "missing.exr", "not found");

  std::ofstream(dir / "garbage.exr", std::ios::binary) << "this is not an OpenEXR file\x01\x02\x03\x04";
  expect_input_error_naming(dir / "garbage.exr");

  // A real OpenEXR file cut short.
  save_environment_map(dir / "whole.exr", gradient_map(256, 128));
  const auto size = std::filesystem::file_size(dir / "whole.exr");
  std::filesystem::copy_file(dir / "whole.exr", dir / "truncated.exr");
  std::filesystem::resize_file(dir / "truncated.exr", size / 2);
  expect_input_error_naming(dir / "truncated.exr");

  save_environment_map(dir / "square.exr", gradient_map(64, 64));
  expect_input_error_naming(dir / "square.exr", "64x64");

  // Negative radiance (once accepted, giving negative irradiance); a trace of ringing is kept.
  EnvironmentMap map = gradient_map(64, 32);
  map.rgb[5] = -1.f;
  save_environment_map(dir / "ringing.exr", map);
  EXPECT_EQ(load_environment_map(dir / "ringing.exr").rgb[5], -1.f);
  for (std::size_t i = 0; i < map.rgb.size(); i += 2) map.rgb[i] = -map.rgb[i];
  save_environment_map(dir / "negative.exr", map);
  expect_input_error_naming(dir / "negative.exr", "negative radiance");

  // An 8-bit PNG renamed .exr opens (the reader goes by content), but holds no radiance.
  const cv::Mat png(32, 64, CV_8UC3, cv::Scalar(200, 100, 50));
  ASSERT_TRUE(cv::imwrite((dir / "photo.png").string(), png));
  std::filesystem::rename(dir / "photo.png", dir / "photo.exr");
  expect_input_error_naming(dir / "photo.exr", "not high dynamic range");

  std::filesystem::create_directories(dir / "folder.exr");
  expect_input_error_naming(dir / "folder.exr", "is a directory");
  expect_input_error_naming("/dev/zero", "is a device or a pipe");
}

TEST(EnvironmentMap, ScaledByCellsOfItsOwnDirections) {
  // A grey 16 x 8 map, a 4 x 2 grid: each texel takes the factor of the cell its centre is in.
  EnvironmentMap map;
  map.width = 16, map.height = 8;
  map.rgb.assign(16 * 8 * 3, 1.0f);
  map.azimuth_offset_deg = 90.0;  // cells are in the map's own directions, not the world's
  MapCellScale scale{4, 2, std::vector<glm::vec3>(8, glm::vec3(1.0f))};
  scale.rgb[1 * 4 + 2] = {2.0f, 1.0f, 0.5f};  // lower row, third column
  const EnvironmentMap out = scale_environment_map(map, scale);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) {
      const glm::vec3 want = (r >= 4 && c >= 8 && c < 12) ? glm::vec3(2.0f, 1.0f, 0.5f) : glm::vec3(1.0f);
      ASSERT_EQ(out.texel(c, r), want) << c << "," << r;
      // at() finds the same cell from the texel's direction.
      ASSERT_EQ(scale.at(latlong_pixel_direction(c, r, 16, 8)), want) << c << "," << r;
    }
  const MapCellScale half =
      MapCellScale::blend(MapCellScale{4, 2, std::vector<glm::vec3>(8, glm::vec3(1.0f))}, scale, 0.5);
  EXPECT_EQ(half.rgb[6], glm::vec3(1.5f, 1.0f, 0.75f));
  EXPECT_THROW(scale_environment_map(map, MapCellScale{4, 2, std::vector<glm::vec3>(7, glm::vec3(1.0f))}), InputError);
}

}  // namespace
}  // namespace lumar
