// The One Euro pose filter against closed forms: with beta = 0 it is exponential
// smoothing, so a step decays as (1 - a)^n and white noise shrinks by sqrt(a / (2 - a)).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "lumar/base/error.h"
#include "lumar/tracking/one_euro_filter.h"

namespace lumar::tracking {
namespace {

constexpr double kRate = 60.0;
constexpr Nanos kPeriod = 16'666'667;  // 60 Hz, a whole number of ns so every dt is equal
Nanos tick(int k) { return k * kPeriod; }
double alpha(double cutoff_hz) {
  const double r = 2 * std::numbers::pi * cutoff_hz * nanos_to_seconds(kPeriod);
  return r / (1 + r);
}

PoseFilterSettings plain(double cutoff_hz, double beta = 0.0) {
  PoseFilterSettings s;
  s.position = {cutoff_hz, beta, 1.0};
  s.rotation = {cutoff_hz, beta, 1.0};
  return s;
}

TEST(OneEuroFilter, ConstantInputPassesUnchanged) {
  Pose p;
  p.rotation = axis_angle_deg({0.3, -1.0, 0.2}, 123.0);
  p.translation = {0.4, -1.2, 2.5};
  OneEuroPoseFilter filter(plain(1.0, 0.7));
  for (int k = 0; k < 600; ++k) {
    const Pose out = filter.filter(p, tick(k));
    ASSERT_LE(glm::length(out.translation - p.translation), 1e-15);
    ASSERT_LE(rotation_angle_deg(out.rotation, p.rotation), 1e-6);  // acos resolution at 1e-14
    ASSERT_NEAR(std::abs(glm::dot(out.rotation, p.rotation)), 1.0, 1e-15);
  }
}

TEST(OneEuroFilter, StepDecaysExactlyLikeExponentialSmoothingWithoutBeta) {
  // beta = 0: each sample closes the fraction a of the remaining distance, on a line
  // for the position and on the geodesic for the rotation.
  const double a = alpha(1.0);
  OneEuroPoseFilter filter(plain(1.0));
  Pose start, step;
  step.translation = {1.0, 0.0, 0.0};
  step.rotation = axis_angle_deg({0, 0, 1}, 90.0);
  filter.filter(start, tick(0));
  for (int n = 1; n <= 120; ++n) {
    const Pose out = filter.filter(step, tick(n));
    const double expected = std::pow(1 - a, n);
    ASSERT_NEAR(1.0 - out.translation.x, expected, 1e-12) << n;
    ASSERT_NEAR(rotation_angle_deg(out.rotation, step.rotation), 90.0 * expected, 1e-6) << n;
  }
  std::printf("step, beta 0, 1 Hz at 60 Hz: a = %.6f, 63 %% reached after %.0f ms\n", a,
              1000.0 / kRate * std::ceil(std::log(1 / std::exp(1.0)) / std::log(1 - a)));
}

TEST(OneEuroFilter, BetaMakesAStepConvergeFaster) {
  OneEuroPoseFilter slow(plain(1.0)), fast(plain(1.0, 2.0));
  Pose step;
  step.translation = {1.0, 0.0, 0.0};
  step.rotation = axis_angle_deg({0, 0, 1}, 90.0);
  slow.filter(Pose{}, tick(0));
  fast.filter(Pose{}, tick(0));
  double slow_m = 0, fast_m = 0, slow_deg = 0, fast_deg = 0;
  for (int n = 1; n <= 30; ++n) {  // half a second
    const Pose s = slow.filter(step, tick(n)), f = fast.filter(step, tick(n));
    slow_m = 1.0 - s.translation.x, fast_m = 1.0 - f.translation.x;
    slow_deg = rotation_angle_deg(s.rotation, step.rotation), fast_deg = rotation_angle_deg(f.rotation, step.rotation);
    ASSERT_LT(fast_m, slow_m);
    ASSERT_LT(fast_deg, slow_deg);
  }
  std::printf("step after 0.5 s: beta 0 leaves %.4f m and %.2f deg, beta 2 leaves %.2e m and %.2e deg\n", slow_m,
              slow_deg, fast_m, fast_deg);
  EXPECT_NEAR(slow_m, std::pow(1 - alpha(1.0), 30), 1e-12);
  EXPECT_LT(fast_m, 0.01 * slow_m);
  EXPECT_LT(fast_deg, 0.01 * slow_deg);
}

TEST(OneEuroFilter, ReducesJitterAtRestAsTheClosedFormSays) {
  // 0.75 deg RMS rotation noise and 2.5 mm RMS per axis at rest, 60 Hz. Exponential
  // smoothing of white noise keeps a / (2 - a) of its variance.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double sigma_rot = glm::radians(0.75) / std::sqrt(3.0), sigma_pos = 0.0025;
  Pose truth;
  truth.rotation = axis_angle_deg({1, 2, 3}, 40.0);
  truth.translation = {0.1, 0.2, 0.3};
  for (double beta : {0.0, 0.3}) {
    OneEuroPoseFilter filter(plain(1.0, beta));
    double raw_rot = 0, out_rot = 0, raw_pos = 0, out_pos = 0;
    const int warmup = 300, n = 30000;
    for (int k = 0; k < warmup + n; ++k) {
      const glm::dvec3 v(sigma_rot * normal(rng), sigma_rot * normal(rng), sigma_rot * normal(rng));
      Pose noisy = truth;
      noisy.rotation = glm::angleAxis(glm::length(v), glm::normalize(v)) * truth.rotation;
      noisy.translation += glm::dvec3(normal(rng), normal(rng), normal(rng)) * sigma_pos;
      const Pose out = filter.filter(noisy, tick(k));
      if (k < warmup) continue;
      raw_rot += std::pow(rotation_angle_deg(noisy.rotation, truth.rotation), 2);
      out_rot += std::pow(rotation_angle_deg(out.rotation, truth.rotation), 2);
      raw_pos += glm::dot(noisy.translation - truth.translation, noisy.translation - truth.translation);
      out_pos += glm::dot(out.translation - truth.translation, out.translation - truth.translation);
    }
    const double rot_ratio = std::sqrt(out_rot / raw_rot), pos_ratio = std::sqrt(out_pos / raw_pos);
    const double a = alpha(1.0), closed_form = std::sqrt(a / (2 - a));
    std::printf("beta %.1f: rotation jitter %.3f -> %.3f deg RMS (x%.3f), position x%.3f; beta 0 closed form x%.3f\n",
                beta, std::sqrt(raw_rot / n), std::sqrt(out_rot / n), rot_ratio, pos_ratio, closed_form);
    EXPECT_NEAR(std::sqrt(raw_rot / n), 0.75, 0.02);
    if (beta == 0) {
      EXPECT_NEAR(rot_ratio, closed_form, 0.03 * closed_form);
      EXPECT_NEAR(pos_ratio, closed_form, 0.03 * closed_form);
    } else {
      // Noise makes the velocity estimate non-zero, so the cutoff rises a little.
      EXPECT_GT(rot_ratio, closed_form);
      EXPECT_LT(rot_ratio, 1.5 * closed_form);
    }
  }
}

TEST(OneEuroFilter, TakesTheShortWayAndIgnoresRepeatedTimes) {
  OneEuroPoseFilter filter(plain(5.0));
  Pose p;
  p.rotation = axis_angle_deg({0, 1, 0}, 10.0);
  filter.filter(p, tick(0));
  Pose flipped = p;
  flipped.rotation = -axis_angle_deg({0, 1, 0}, 12.0);  // same as +12 deg
  const Pose out = filter.filter(flipped, tick(1));
  const double moved = rotation_angle_deg(out.rotation, p.rotation);
  EXPECT_NEAR(moved, 2.0 * alpha(5.0), 1e-6);
  const Pose again = filter.filter(flipped, tick(1));  // same time: no update
  EXPECT_EQ(again.rotation, out.rotation);
}

TEST(OneEuroFilter, SampleFilterKeepsStationsApartAndRefusesBadSettings) {
  PoseSampleFilter filter(plain(1.0));
  PoseSample a, b;
  a.station = 1;
  b.station = 2;
  b.T_transmitter_sensor.translation = {5, 5, 5};
  for (int k = 0; k < 10; ++k) {
    a.time = b.time = tick(k);
    EXPECT_EQ(filter.filter(a).T_transmitter_sensor.translation, glm::dvec3(0.0));
    EXPECT_EQ(filter.filter(b).T_transmitter_sensor.translation, glm::dvec3(5.0));
  }
  EXPECT_THROW(OneEuroPoseFilter(plain(0.0)), InputError);
  EXPECT_THROW(OneEuroPoseFilter(plain(1.0, -1.0)), InputError);
  EXPECT_THROW(PoseSampleFilter(plain(NAN)), InputError);
}

}  // namespace
}  // namespace lumar::tracking
