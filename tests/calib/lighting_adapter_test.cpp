// The lighting adapter against a room whose brightness is changed by known factors.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/error.h"
#include "lumar/calib/lighting_adapter.h"

namespace lumar {
namespace {

// A textured "predicted" room radiance whose pixels come from a 4 x 2 grid of map
// cells (the image's left and right halves, in four bands), and what a noisy camera
// sees of it when the room is `global` times brighter, with the right-hand cells
// `right` (per channel, BGR) times brighter again.
struct Views {
  cv::Mat predicted, observed, map_uv;
};
Views views(double global, const cv::Vec3d& right, cv::RNG& rng) {
  Views v;
  v.predicted.create(120, 160, CV_32FC3);
  v.map_uv.create(120, 160, CV_32FC2);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const float base = 0.2f + 0.15f * std::sin(x * 0.3f) * std::cos(y * 0.2f) + 0.1f * (x % 7 == 0);
      v.predicted.at<cv::Vec3f>(y, x) = {base, base * 0.9f, base * 1.1f};
      // u: cells 0-1 on the left half, 2-3 on the right; v: rows 0-1 by the image's halves.
      v.map_uv.at<cv::Vec2f>(y, x) = {float((x + 0.5) / 160.0), float((y + 0.5) / 120.0)};
    }
  v.observed = v.predicted * global;
  cv::Mat right_half = v.observed.colRange(80, 160);
  cv::multiply(right_half, cv::Scalar(right[0], right[1], right[2]), right_half);
  cv::Mat noise(v.observed.size(), CV_32FC3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.01);
  v.observed += noise;
  v.observed.setTo(0.0f, v.observed < 0.0f);
  return v;
}

calib::LightingAdapterSettings four_by_two() {
  calib::LightingAdapterSettings s;
  s.cell_cols = 4, s.cell_rows = 2, s.min_cell_pixels = 100;
  return s;
}

TEST(LightingAdapter, MeasuresEachMapCellPerColour) {
  calib::LightingAdapter adapter(four_by_two());
  EXPECT_FALSE(adapter.has_estimate());
  EXPECT_EQ(adapter.global_ratio(), 1.0);
  cv::RNG rng(1);
  // A lamp on the right turns warmer: red up, blue down.
  const Views v = views(1.6, {0.7, 1.0, 1.3}, rng);
  adapter.update(v.observed, v.predicted, v.map_uv, 0);
  ASSERT_TRUE(adapter.has_estimate());
  EXPECT_EQ(adapter.measured_cells(), 8);
  EXPECT_NEAR(adapter.global_ratio(), 1.6, 0.05);
  const cv::Mat cells = adapter.cell_ratios();
  ASSERT_EQ(cells.type(), CV_64FC3);
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(cells.at<cv::Vec3d>(r, c)[k], 1.6, 0.02) << r << "," << c;
    for (int c = 2; c < 4; ++c) {
      EXPECT_NEAR(cells.at<cv::Vec3d>(r, c)[0], 1.6 * 0.7, 0.02);
      EXPECT_NEAR(cells.at<cv::Vec3d>(r, c)[1], 1.6, 0.02);
      EXPECT_NEAR(cells.at<cv::Vec3d>(r, c)[2], 1.6 * 1.3, 0.03);
    }
  }
}

TEST(LightingAdapter, ALampGoingOutIsMeasuredByItsPowerNotItsPixelCount) {
  // A cell whose few bright pixels go dark: the median pixel is unchanged, the light is not.
  calib::LightingAdapterSettings s;
  s.cell_cols = 1, s.cell_rows = 1, s.time_constant_s = 0;
  calib::LightingAdapter adapter(s);
  cv::Mat predicted(60, 80, CV_32FC3, cv::Scalar::all(0.2)), uv(60, 80, CV_32FC2, cv::Scalar(0.5, 0.5));
  predicted(cv::Rect(10, 10, 6, 6)).setTo(cv::Scalar::all(40.0));  // 36 px of 4800: 94 % of the power
  cv::Mat observed = predicted.clone();
  observed(cv::Rect(10, 10, 6, 6)).setTo(cv::Scalar::all(0.2));
  adapter.update(observed, predicted, uv, 0);
  const double power_ratio = (4800 * 0.2) / (4764 * 0.2 + 36 * 40.0);
  EXPECT_NEAR(adapter.cell_ratios().at<cv::Vec3d>(0, 0)[1], power_ratio, 1e-3);
  EXPECT_NEAR(adapter.global_ratio(), 1.0, 1e-3);  // the median pixel did not change
}

TEST(LightingAdapter, CellsNotSeenFollowTheMedianChange) {
  calib::LightingAdapter adapter(four_by_two());
  cv::RNG rng(3);
  Views v = views(0.5, {1.0, 1.0, 1.0}, rng);
  v.map_uv.colRange(80, 160).setTo(cv::Scalar(0.3, 0.2));  // the right half: the left cells too
  adapter.update(v.observed, v.predicted, v.map_uv, 0);
  EXPECT_EQ(adapter.measured_cells(), 4);
  const cv::Mat cells = adapter.cell_ratios();
  EXPECT_NEAR(cells.at<cv::Vec3d>(1, 3)[1], 0.5, 0.02);  // never seen: the room's dimmer
}

TEST(LightingAdapter, IgnoresFlickerBelowTheHysteresisAndFollowsARealChange) {
  calib::LightingAdapterSettings s = four_by_two();
  s.time_constant_s = 0.2;
  s.hysteresis = 0.05;
  calib::LightingAdapter adapter(s);
  cv::RNG rng(2);
  Nanos t = 0;
  const Nanos frame = seconds_to_nanos(1.0 / 30);
  const auto flicker = [](int k) { return 1.0 + 0.02 * ((k % 2) ? 1 : -1); };
  // A lamp that flickers by +-2 %: the published ratios must not move at all.
  for (int k = 0; k < 60; ++k, t += frame) {
    const Views v = views(flicker(k), {1, 1, 1}, rng);
    adapter.update(v.observed, v.predicted, v.map_uv, t);
  }
  const double settled = adapter.global_ratio();
  const std::uint64_t version = adapter.version();
  const cv::Mat cells = adapter.cell_ratios();
  for (int k = 0; k < 60; ++k, t += frame) {
    const Views v = views(flicker(k), {1, 1, 1}, rng);
    adapter.update(v.observed, v.predicted, v.map_uv, t);
    ASSERT_EQ(adapter.global_ratio(), settled) << "flicker reached the lighting at frame " << k;
    ASSERT_EQ(adapter.version(), version) << "flicker moved a cell at frame " << k;
  }
  EXPECT_NEAR(settled, 1.0, 0.03);
  EXPECT_EQ(cv::norm(adapter.cell_ratios(), cells, cv::NORM_INF), 0.0);
  // The right-hand lights are dimmed to 60 %: within a second the cells follow, smoothly.
  double previous = adapter.cell_ratios().at<cv::Vec3d>(0, 3)[1], biggest_step = 0;
  for (int k = 0; k < 45; ++k, t += frame) {
    const Views v = views(1.0, {0.6, 0.6, 0.6}, rng);
    adapter.update(v.observed, v.predicted, v.map_uv, t);
    const double now = adapter.cell_ratios().at<cv::Vec3d>(0, 3)[1];
    biggest_step = std::max(biggest_step, std::abs(now - previous));
    previous = now;
  }
  EXPECT_NEAR(previous, 0.6, 0.03);
  EXPECT_NEAR(adapter.cell_ratios().at<cv::Vec3d>(0, 0)[1], 1.0, 0.03);
  EXPECT_LT(biggest_step, 0.1) << "the change should be spread over several frames";
}

TEST(LightingAdapter, SkipsFramesWithoutRoomAndRejectsMismatchedImages) {
  calib::LightingAdapter adapter;
  const cv::Mat black = cv::Mat::zeros(50, 50, CV_32FC3), uv(50, 50, CV_32FC2, cv::Scalar(0.5, 0.5));
  adapter.update(black, black, uv, 0);
  EXPECT_FALSE(adapter.has_estimate());
  EXPECT_EQ(adapter.last_measurement(), 0.0);
  EXPECT_THROW(adapter.update(black, cv::Mat::zeros(40, 50, CV_32FC3), uv, 0), InputError);
  EXPECT_THROW(adapter.update(black, cv::Mat::zeros(50, 50, CV_8UC3), uv, 0), InputError);
  EXPECT_THROW(adapter.update(black, black, cv::Mat::zeros(50, 50, CV_32FC1), 0), InputError);
}

}  // namespace
}  // namespace lumar
