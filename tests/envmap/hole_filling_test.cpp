// Push-pull hole filling, coverage picture and contact sheet.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/error.h"

#include "lumar/base/latlong.h"
#include "lumar/envmap/hole_filling.h"

namespace lumar {
namespace {

EnvironmentMap ramp_map(int width) {
  EnvironmentMap map;
  map.width = width;
  map.height = width / 2;
  map.rgb.resize(std::size_t(width) * map.height * 3);
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < width; ++c)
      for (int ch = 0; ch < 3; ++ch) map.rgb[(std::size_t(r) * width + c) * 3 + ch] = float(1.0 + r * 0.01 * (ch + 1));
  return map;
}

TEST(HoleFilling, FillsTheFloorFromItsBorderAndKeepsKnownPixels) {
  EnvironmentMap map = ramp_map(128);
  const EnvironmentMap original = map;
  cv::Mat known(map.height, map.width, CV_8UC1, cv::Scalar(1));
  known.rowRange(52, 64).setTo(0);  // a cap around the nadir
  for (int r = 52; r < 64; ++r)
    for (int c = 0; c < map.width; ++c)
      for (int ch = 0; ch < 3; ++ch) map.rgb[(std::size_t(r) * map.width + c) * 3 + ch] = -1000.f;  // garbage
  EXPECT_EQ(calib::fill_holes_push_pull(map, known), 12 * 128);
  for (int r = 0; r < 52; ++r)
    for (int c = 0; c < map.width; ++c) ASSERT_EQ(map.texel(c, r), original.texel(c, r));
  // The hole is filled with values near its border (row 51), not garbage, and smoothly.
  const float border = original.texel(0, 51).g;
  for (int r = 52; r < 64; ++r)
    for (int c = 0; c < map.width; ++c) {
      ASSERT_NEAR(map.texel(c, r).g, border, 0.06f) << r << "," << c;
      ASSERT_NEAR(map.texel(c, r).g, map.texel((c + 1) % map.width, r).g, 0.01f);
    }
}

TEST(HoleFilling, NothingToFillAndNothingKnown) {
  EnvironmentMap map = ramp_map(64);
  EXPECT_EQ(calib::fill_holes_push_pull(map, cv::Mat(32, 64, CV_8UC1, cv::Scalar(1))), 0);
  EXPECT_THROW(calib::fill_holes_push_pull(map, cv::Mat(32, 64, CV_8UC1, cv::Scalar(0))), InputError);
  EXPECT_THROW(calib::fill_holes_push_pull(map, cv::Mat(16, 64, CV_8UC1, cv::Scalar(1))), InputError);
}

TEST(HoleFilling, CoverageImageFlagsHolesAndShowsCounts) {
  cv::Mat count(2, 3, CV_16UC1);
  count.at<std::uint16_t>(0, 0) = 0, count.at<std::uint16_t>(0, 1) = 1, count.at<std::uint16_t>(0, 2) = 8;
  count.at<std::uint16_t>(1, 0) = 30, count.at<std::uint16_t>(1, 1) = 4, count.at<std::uint16_t>(1, 2) = 0;
  const cv::Mat image = calib::coverage_image(count);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 255));
  EXPECT_EQ(image.at<cv::Vec3b>(1, 2), cv::Vec3b(255, 0, 255));
  EXPECT_LT(image.at<cv::Vec3b>(0, 1)[0], image.at<cv::Vec3b>(1, 1)[0]);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 2), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(image.at<cv::Vec3b>(1, 0), cv::Vec3b(255, 255, 255));
}

TEST(HoleFilling, ContactSheetPutsTheMedianAtMiddleGreyInTheMiddleRow) {
  EnvironmentMap map = ramp_map(64);
  for (float& v : map.rgb) v = 5.f;  // uniform: every pixel is the median
  const cv::Mat sheet = calib::contact_sheet(map);
  ASSERT_EQ(sheet.rows, 96);
  // 18 % linear is sRGB 118; -4 and +4 stops are darker and brighter.
  EXPECT_NEAR(sheet.at<cv::Vec3b>(40, 10)[1], 118, 1);
  EXPECT_LT(sheet.at<cv::Vec3b>(5, 10)[1], 50);
  EXPECT_EQ(sheet.at<cv::Vec3b>(80, 10)[1], 255);
}

}  // namespace
}  // namespace lumar
