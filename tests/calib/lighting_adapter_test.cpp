// The lighting adapter against a room whose brightness is changed by known factors.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/error.h"
#include "lumar/calib/lighting_adapter.h"

namespace lumar {
namespace {

// A textured "predicted" room radiance, and what a noisy camera sees of it when the room
// is `global` times brighter, with the right third `right` times brighter again.
struct Views {
  cv::Mat predicted, observed;
};
Views views(double global, double right, cv::RNG& rng) {
  Views v;
  v.predicted.create(120, 160, CV_32FC3);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const float base = 0.2f + 0.15f * std::sin(x * 0.3f) * std::cos(y * 0.2f) + 0.1f * (x % 7 == 0);
      v.predicted.at<cv::Vec3f>(y, x) = {base, base * 0.9f, base * 1.1f};
    }
  v.observed = v.predicted * global;
  v.observed.colRange(120, 160) *= right;
  cv::Mat noise(v.observed.size(), CV_32FC3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.01);
  v.observed += noise;
  v.observed.setTo(0.0f, v.observed < 0.0f);
  return v;
}

TEST(LightingAdapter, MeasuresGlobalAndRegionalRatios) {
  calib::LightingAdapterSettings s;
  s.grid_cols = 4, s.grid_rows = 1, s.min_pixels = 100;
  calib::LightingAdapter adapter(s);
  EXPECT_FALSE(adapter.has_estimate());
  EXPECT_EQ(adapter.global_ratio(), 1.0);
  cv::RNG rng(1);
  const Views v = views(1.6, 1.5, rng);
  adapter.update(v.observed, v.predicted, 0);
  ASSERT_TRUE(adapter.has_estimate());
  // Three quarters of the pixels are 1.6 times brighter: the median says 1.6.
  EXPECT_NEAR(adapter.global_ratio(), 1.6, 0.03);
  const cv::Mat regions = adapter.region_ratios();
  EXPECT_NEAR(regions.at<double>(0, 0), 1.6, 0.03);
  EXPECT_NEAR(regions.at<double>(0, 3), 2.4, 0.05);
}

TEST(LightingAdapter, IgnoresFlickerBelowTheHysteresisAndFollowsARealChange) {
  calib::LightingAdapterSettings s;
  s.time_constant_s = 0.2;
  s.hysteresis = 0.05;
  calib::LightingAdapter adapter(s);
  cv::RNG rng(2);
  Nanos t = 0;
  const Nanos frame = seconds_to_nanos(1.0 / 30);
  // A lamp that flickers by +-2 %: the published ratio must not move at all.
  for (int k = 0; k < 60; ++k, t += frame) {
    const Views v = views(1.0 + 0.02 * ((k % 2) ? 1 : -1), 1.0, rng);
    adapter.update(v.observed, v.predicted, t);
  }
  const double settled = adapter.global_ratio();
  for (int k = 0; k < 60; ++k, t += frame) {
    const Views v = views(1.0 + 0.02 * ((k % 2) ? 1 : -1), 1.0, rng);
    adapter.update(v.observed, v.predicted, t);
    ASSERT_EQ(adapter.global_ratio(), settled) << "flicker reached the lighting at frame " << k;
  }
  EXPECT_NEAR(settled, 1.0, 0.03);
  // The lights are dimmed to 60 %: within a second the lighting follows, smoothly.
  double previous = adapter.global_ratio(), biggest_step = 0;
  for (int k = 0; k < 45; ++k, t += frame) {
    const Views v = views(0.6, 1.0, rng);
    adapter.update(v.observed, v.predicted, t);
    biggest_step = std::max(biggest_step, std::abs(adapter.global_ratio() - previous));
    previous = adapter.global_ratio();
  }
  EXPECT_NEAR(adapter.global_ratio(), 0.6, 0.03);
  EXPECT_LT(biggest_step, 0.1) << "the change should be spread over several frames";
  EXPECT_NEAR(adapter.last_measurement(), 0.6, 0.03);
}

TEST(LightingAdapter, SkipsFramesWithoutRoomAndRejectsMismatchedImages) {
  calib::LightingAdapter adapter;
  const cv::Mat black = cv::Mat::zeros(50, 50, CV_32FC3);
  adapter.update(black, black, 0);
  EXPECT_FALSE(adapter.has_estimate());
  EXPECT_EQ(adapter.last_measurement(), 0.0);
  EXPECT_THROW(adapter.update(black, cv::Mat::zeros(40, 50, CV_32FC3), 0), InputError);
  EXPECT_THROW(adapter.update(black, cv::Mat::zeros(50, 50, CV_8UC3), 0), InputError);
}

}  // namespace
}  // namespace lumar
