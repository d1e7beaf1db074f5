// Pose lookup between samples against analytic motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "lumar/tracking/pose_stream.h"

namespace lumar::tracking {
namespace {

// Constant angular velocity about a fixed axis, constant linear velocity.
const glm::dvec3 kAxis = glm::normalize(glm::dvec3(1.0, -2.0, 0.5));
const glm::dquat kStart = axis_angle_deg({0.3, 0.4, -1.0}, 70.0);
constexpr double kDegPerSecond = 90.0;

Pose analytic(Nanos t) {
  Pose p;
  p.rotation = axis_angle_deg(kAxis, kDegPerSecond * nanos_to_seconds(t)) * kStart;
  p.translation = glm::dvec3(0.1, -0.2, 0.3) + glm::dvec3(0.5, 0.25, -1.0) * nanos_to_seconds(t);
  return p;
}

PoseSample sample(Nanos t, int station = 1) {
  PoseSample s;
  s.time = t;
  s.station = station;
  s.T_transmitter_sensor = analytic(t);
  return s;
}

constexpr Nanos kStep = 100'000'000;  // 100 ms: 9 degrees between samples

TEST(PoseStream, SlerpMatchesConstantAngularVelocity) {
  PoseStream stream;
  std::mt19937_64 rng(1);
  for (int k = 0; k <= 20; ++k) {
    PoseSample s = sample(k * kStep);
    // q and -q are the same rotation; the stream must take the short way regardless.
    if (rng() % 2) s.T_transmitter_sensor.rotation = -s.T_transmitter_sensor.rotation;
    stream.add(s);
  }
  double worst_deg = 0, worst_m = 0;
  for (int k = 0; k < 20; ++k) {
    for (double frac : {0.5, 0.25, 0.9}) {
      const Nanos t = k * kStep + Nanos(frac * kStep);
      const auto p = stream.at(t);
      ASSERT_TRUE(p.has_value());
      const Pose truth = analytic(t);
      worst_deg = std::max(worst_deg, rotation_angle_deg(p->rotation, truth.rotation));
      worst_m = std::max(worst_m, glm::length(p->translation - truth.translation));
    }
  }
  EXPECT_LE(glm::radians(worst_deg), 1e-9);
  EXPECT_LE(worst_m, 1e-12);
  std::printf("slerp vs analytic rotation: worst %.3e rad, translation %.3e m\n", glm::radians(worst_deg), worst_m);
}

TEST(PoseStream, ExactAtSamplesAndNothingOutsideRange) {
  PoseStream stream;
  for (int k = 0; k <= 10; ++k) stream.add(sample(k * kStep));
  const auto at3 = stream.at(3 * kStep);
  ASSERT_TRUE(at3.has_value());
  EXPECT_EQ(at3->translation, analytic(3 * kStep).translation);
  EXPECT_TRUE(stream.at(0).has_value());
  EXPECT_TRUE(stream.at(10 * kStep).has_value());
  EXPECT_FALSE(stream.at(-1).has_value());
  EXPECT_FALSE(stream.at(10 * kStep + 1).has_value());
  EXPECT_FALSE(stream.at(5 * kStep, 2).has_value());  // no station 2
}

TEST(PoseStream, RefusesToBridgeBigGaps) {
  PoseStream stream;
  for (int k : {0, 1, 2, 5, 6}) stream.add(sample(k * kStep));  // 300 ms hole between 2 and 5
  EXPECT_TRUE(stream.at(Nanos(1.5 * kStep)).has_value());
  EXPECT_FALSE(stream.at(Nanos(3.5 * kStep)).has_value());
  EXPECT_TRUE(stream.at(Nanos(3.5 * kStep), 1, 300'000'000).has_value());
  EXPECT_FALSE(stream.at(Nanos(0.5 * kStep), 1, 50'000'000).has_value());
}

TEST(PoseStream, KeepsTimeOrderPerStation) {
  std::vector<PoseSample> all;
  for (int k = 0; k <= 30; ++k) all.push_back(sample(k * kStep / 3, 1 + k % 2));
  std::mt19937_64 rng(9);
  std::shuffle(all.begin(), all.end(), rng);
  PoseStream stream;
  for (const auto& s : all) stream.add(s);
  EXPECT_EQ(stream.size(), 31u);
  EXPECT_EQ(stream.stations(), (std::vector<int>{1, 2}));
  for (int station : {1, 2}) {
    const auto& v = stream.samples(station);
    EXPECT_TRUE(std::is_sorted(v.begin(), v.end(), [](auto& a, auto& b) { return a.time < b.time; }));
    for (const auto& s : v) EXPECT_EQ(s.station, station);
  }
  EXPECT_EQ(stream.samples(1).size(), 16u);
  // Station 2 samples do not leak into station 1's interpolation.
  const Nanos t = kStep / 3;  // a station 2 sample time, between station 1 samples
  const auto p = stream.at(t, 1);
  ASSERT_TRUE(p.has_value());
  EXPECT_LE(glm::radians(rotation_angle_deg(p->rotation, analytic(t).rotation)), 1e-9);
  EXPECT_TRUE(stream.samples(3).empty());
}

TEST(PoseStream, ExtrapolatesAtConstantVelocityForABoundedTime) {
  PoseStream stream;
  for (int k = 0; k <= 20; ++k) stream.add(sample(k * kStep));
  const Nanos last = 20 * kStep;
  PoseLookupSettings settings;  // 50 ms limit
  // 30 ms past the newest sample: constant angular and linear velocity is exact here.
  const PoseLookup ahead = stream.lookup(last + 30'000'000, 1, settings);
  ASSERT_EQ(ahead.status, PoseStatus::Extrapolated);
  ASSERT_TRUE(ahead.pose.has_value());
  EXPECT_EQ(ahead.age, 30'000'000);
  const Pose truth = analytic(last + 30'000'000);
  EXPECT_LE(glm::radians(rotation_angle_deg(ahead.pose->rotation, truth.rotation)), 1e-9);
  EXPECT_LE(glm::length(ahead.pose->translation - truth.translation), 1e-12);
  // Right at the limit, and just past it.
  EXPECT_EQ(stream.lookup(last + 50'000'000, 1, settings).status, PoseStatus::Extrapolated);
  const PoseLookup stale = stream.lookup(last + 50'000'001, 1, settings);
  EXPECT_EQ(stale.status, PoseStatus::TooOld);
  EXPECT_FALSE(stale.pose.has_value());
  settings.max_extrapolation = 80'000'000;
  EXPECT_EQ(stream.lookup(last + 60'000'000, 1, settings).status, PoseStatus::Extrapolated);
  EXPECT_EQ(std::string(to_string(PoseStatus::TooOld)), "tracker data too old");
}

TEST(PoseStream, LookupStatesWhyThereIsNoPose) {
  PoseStream stream;
  for (int k : {0, 1, 2, 5, 6}) stream.add(sample(k * kStep));  // 300 ms hole between 2 and 5
  const PoseLookup inside = stream.lookup(Nanos(1.5 * kStep));
  EXPECT_EQ(inside.status, PoseStatus::Interpolated);
  ASSERT_TRUE(inside.pose.has_value());
  EXPECT_EQ(inside.pose->translation, stream.at(Nanos(1.5 * kStep))->translation);
  EXPECT_EQ(stream.lookup(Nanos(3.5 * kStep)).status, PoseStatus::Gap);
  EXPECT_FALSE(stream.lookup(Nanos(3.5 * kStep)).pose.has_value());
  EXPECT_EQ(stream.lookup(-1).status, PoseStatus::BeforeFirst);
  EXPECT_EQ(stream.lookup(kStep, 2).status, PoseStatus::NoSamples);
  // The time offset moves the query: frame time 10 ms before a sample + 10 ms offset.
  PoseLookupSettings offset;
  offset.time_offset = 10'000'000;
  const PoseLookup shifted = stream.lookup(kStep - 10'000'000, 1, offset);
  ASSERT_TRUE(shifted.pose.has_value());
  EXPECT_EQ(shifted.pose->translation, analytic(kStep).translation);
  // Velocity is not taken across a dropout: after the hole only 5 -> 6 counts, and a
  // lone sample is held, not extrapolated.
  PoseStream lone;
  lone.add(sample(0));
  const PoseLookup held = lone.lookup(20'000'000);
  EXPECT_EQ(held.status, PoseStatus::Extrapolated);
  EXPECT_EQ(held.pose->translation, analytic(0).translation);
  PoseStream dropout;
  dropout.add(sample(0));
  dropout.add(sample(5 * kStep));  // 500 ms apart: more than max_gap
  EXPECT_EQ(dropout.lookup(5 * kStep + 20'000'000).pose->translation, analytic(5 * kStep).translation);
}

}  // namespace
}  // namespace lumar::tracking
