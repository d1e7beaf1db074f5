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
