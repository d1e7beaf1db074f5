// The complementary filter against its closed forms: a perfect video and a tracker with
// white noise sigma settle at sigma * sqrt(g / (2 - g)); before that the running mean
// gives sigma / sqrt(n); a video drifting by d per frame settles d (1 - g) / g behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "lumar/base/error.h"
#include "lumar/tracking/pose_fusion.h"

namespace lumar::tracking {
namespace {

// The camera turning at 1 degree per frame about a tilted axis, moving 1 cm per frame.
Pose truth(int k) {
  return Pose{axis_angle_deg(glm::normalize(glm::dvec3(0.2, 1, 0.1)), 1.0 * k), glm::dvec3(0.01 * k, 1.5, 0)};
}

Pose noisy(const Pose& p, double sigma_deg, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, glm::radians(sigma_deg) / std::sqrt(3.0));
  return Pose{rotation_exp(glm::dvec3(n(rng), n(rng), n(rng))) * p.rotation, p.translation};
}

// The video's pose: the last fused pose moved by the true motion, turned by `drift_deg`.
Pose video(const Pose& last_fused, int k, double drift_deg = 0.0) {
  return last_fused * (truth(k - 1).inverse() * truth(k)) * Pose{axis_angle_deg({0, 1, 0}, drift_deg), {}};
}

TEST(PoseFusion, APerfectVideoAveragesTheTrackersNoise) {
  const double sigma = 0.75;
  for (double gain : {0.02, 0.05, 0.2}) {
    PoseFusion fusion({.tracker_gain = gain});
    std::mt19937 rng(7);
    fusion.update(std::nullopt, noisy(truth(0), sigma, rng));
    double sum2 = 0;
    int n = 0;
    for (int k = 1; k < 40000; ++k) {
      const Pose fused = *fusion.update(video(*fusion.pose(), k), noisy(truth(k), sigma, rng));
      if (k > 2000) sum2 += std::pow(rotation_angle_deg(fused.rotation, truth(k).rotation), 2), ++n;
    }
    const double rms = std::sqrt(sum2 / n), expected = sigma * std::sqrt(gain / (2 - gain));
    std::printf("gain %.2f: settled RMS %.4f deg, closed form %.4f deg\n", gain, rms, expected);
    EXPECT_NEAR(rms / expected, 1.0, 0.08) << gain;
  }
}

TEST(PoseFusion, StartsAsTheRunningMeanOfTheTracker) {
  const double sigma = 0.75;
  const int trials = 3000, frames = 10;
  std::vector<double> sum2(frames, 0.0);
  std::mt19937 rng(3);
  for (int t = 0; t < trials; ++t) {
    PoseFusion fusion({.tracker_gain = 0.05});
    fusion.update(std::nullopt, noisy(truth(0), sigma, rng));
    sum2[0] += std::pow(rotation_angle_deg(fusion.pose()->rotation, truth(0).rotation), 2);
    for (int k = 1; k < frames; ++k) {
      const Pose fused = *fusion.update(video(*fusion.pose(), k), noisy(truth(k), sigma, rng));
      sum2[k] += std::pow(rotation_angle_deg(fused.rotation, truth(k).rotation), 2);
    }
  }
  for (int k : {0, 3, 9}) EXPECT_NEAR(std::sqrt(sum2[k] / trials) / (sigma / std::sqrt(k + 1.0)), 1.0, 0.05) << k;
}

TEST(PoseFusion, ADriftingVideoSettlesBehindByDriftOverGain) {
  const double drift = 0.01, gain = 0.05;
  PoseFusion fusion({.tracker_gain = gain});
  fusion.update(std::nullopt, truth(0));
  Pose fused;
  for (int k = 1; k < 2000; ++k) fused = *fusion.update(video(*fusion.pose(), k, drift), truth(k));
  EXPECT_NEAR(rotation_angle_deg(fused.rotation, truth(1999).rotation), drift * (1 - gain) / gain, 1e-3);
}

TEST(PoseFusion, WithoutTheVideoItsLastMotionGoesOnAndTheTrackerTakesOverSmoothly) {
  PoseFusion fusion;
  // The tracker off by a constant 2 degrees about world x (so it moves as the truth does,
  // seen from the camera); the video follows the true motion.
  const Pose offset{axis_angle_deg({1, 0, 0}, 2.0), {}};
  fusion.update(std::nullopt, offset * truth(0));
  for (int k = 1; k < 400; ++k) fusion.update(video(*fusion.pose(), k), offset * truth(k));
  // Lost for 4 s: the fused pose moves on at the video's last motion (the true one here)
  // and slides over to the tracker, a little more of the way each frame, never jumping.
  double apart = rotation_angle_deg(fusion.pose()->rotation, (offset * truth(399)).rotation);
  for (int k = 400; k < 500; ++k) {
    const Pose last = *fusion.pose();
    const Pose fused = *fusion.update(std::nullopt, offset * truth(k));
    const double now = rotation_angle_deg(fused.rotation, (offset * truth(k)).rotation);
    const double gain = std::min(PoseFusion::kMaxCoastGain, 0.035 + (k - 399) * PoseFusion::kCoastGainPerFrame);
    EXPECT_NEAR(now, (1 - gain) * apart, 1e-6) << k;
    EXPECT_NEAR(rotation_angle_deg(fused.rotation, last.rotation), 1.0, gain * apart + 1e-6) << k;
    apart = now;
  }
  EXPECT_LT(apart, 0.01);
  EXPECT_THROW(PoseFusion({.tracker_gain = 0.0}), InputError);
  EXPECT_THROW(PoseFusion({.tracker_gain = 1.5}), InputError);
}

TEST(PoseFusion, AfterAGapTheTrackersMotionBridgesIt) {
  PoseFusion fusion;
  fusion.update(std::nullopt, truth(0));
  for (int k = 1; k < 100; ++k) fusion.update(video(*fusion.pose(), k), truth(k));
  // Frames 100-109 never came: the tracker's motion over the gap, weighed as at the start.
  fusion.restart_mean();
  const Pose fused = *fusion.update(std::nullopt, truth(110));
  EXPECT_LT(rotation_angle_deg(fused.rotation, truth(110).rotation), 1e-6);
  EXPECT_LT(glm::distance(fused.translation, truth(110).translation), 1e-9);
}

TEST(PoseFusion, NothingBeforeTheTrackerAndAfterAReset) {
  PoseFusion fusion;
  EXPECT_FALSE(fusion.update(truth(0), std::nullopt));
  EXPECT_TRUE(fusion.update(std::nullopt, truth(0)));
  fusion.reset();
  EXPECT_FALSE(fusion.pose());
}

}  // namespace
}  // namespace lumar::tracking

namespace lumar::tracking {
namespace {

// An absolute fix worth W tracker samples, on a fused pose worth w of them, moves it by
// W / (w + W) of the way. A frame later the fix's variance 1/W has grown by the process
// noise q = g^2 / (1 - g), and the tracker pulls by 1 / (w + 1 / (1/W + q)) of the way.
TEST(PoseFusion, AFixIsWeighedByItsWorthAndThenHoldsTheTrackerBack) {
  const double gain = 0.05, worth = 100;
  PoseFusion fusion({.tracker_gain = gain, .fix_worth = worth});
  const Pose tracked = Pose{axis_angle_deg({1, 0, 0}, 2.0), {}} * truth(0);
  fusion.update(std::nullopt, tracked);  // worth 2 after one sample (its gain: 1/2)
  const Pose fused = *fusion.fix(truth(0));
  EXPECT_NEAR(rotation_angle_deg(fused.rotation, truth(0).rotation), 2.0 * 2 / (2 + worth), 1e-9);
  EXPECT_NEAR(rotation_angle_deg(fused.rotation, tracked.rotation), 2.0 * worth / (2 + worth), 1e-9);
  // The next frame: the video moves it exactly, the tracker is 1 degree off the result.
  const Pose moved = video(fused, 1);
  const Pose after = *fusion.update(moved, Pose{axis_angle_deg({0, 0, 1}, 1.0), {}} * moved);
  const double q = gain * gain / (1 - gain);
  EXPECT_NEAR(rotation_angle_deg(after.rotation, moved.rotation), 1.0 / (2 + 1 / (1 / worth + q)), 1e-6);
  // After a gap the fixes are forgotten: the tracker is weighed as at the start.
  fusion.restart_mean();
  const Pose before = *fusion.pose();
  const Pose gap = *fusion.update(before, Pose{axis_angle_deg({0, 0, 1}, 1.0), {}} * before);
  EXPECT_NEAR(rotation_angle_deg(gap.rotation, before.rotation), 0.5, 1e-6);
}

// A perfect video, the tracker with 0.75 degrees of white noise, and every 24 frames a fix
// with the noise its worth says (sigma / sqrt(400)): the fixes hold the fused pose far
// below the tracker's settled sigma * sqrt(g / (2 - g)), and not below their own noise.
TEST(PoseFusion, FixesHoldTheFusedPoseNearTheirOwnAccuracy) {
  const double sigma = 0.75, gain = 0.035, worth = 400;
  double rms[2];
  for (int with_fixes : {0, 1}) {
    PoseFusion fusion({.tracker_gain = gain, .fix_worth = worth});
    std::mt19937 rng(11);
    fusion.update(std::nullopt, noisy(truth(0), sigma, rng));
    double sum2 = 0;
    int n = 0;
    for (int k = 1; k < 20000; ++k) {
      fusion.update(video(*fusion.pose(), k), noisy(truth(k), sigma, rng));
      if (with_fixes && k % 24 == 0) fusion.fix(noisy(truth(k), sigma / std::sqrt(worth), rng));
      if (k > 1000) sum2 += std::pow(rotation_angle_deg(fusion.pose()->rotation, truth(k).rotation), 2), ++n;
    }
    rms[with_fixes] = std::sqrt(sum2 / n);
  }
  std::printf("settled RMS: %.4f deg without fixes (closed form %.4f), %.4f deg with a fix every 24 frames\n", rms[0],
              sigma * std::sqrt(gain / (2 - gain)), rms[1]);
  EXPECT_NEAR(rms[0] / (sigma * std::sqrt(gain / (2 - gain))), 1.0, 0.08);
  EXPECT_LT(rms[1], 0.5 * rms[0]);
  EXPECT_GT(rms[1], 0.5 * sigma / std::sqrt(worth));
}

TEST(PoseFusion, FixesWorthNothingAreIgnoredAndANegativeWorthIsRefused) {
  PoseFusion fusion({.tracker_gain = 0.05, .fix_worth = 0});
  fusion.update(std::nullopt, truth(0));
  EXPECT_NEAR(rotation_angle_deg(fusion.fix(truth(10))->rotation, truth(0).rotation), 0.0, 1e-12);
  EXPECT_THROW(PoseFusion({.tracker_gain = 0.05, .fix_worth = -1}), InputError);
  EXPECT_THROW(PoseFusion({.tracker_gain = 0.05, .fix_worth = std::nan("")}), InputError);
}

}  // namespace
}  // namespace lumar::tracking
