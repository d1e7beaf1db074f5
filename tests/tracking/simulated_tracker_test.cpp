// The simulated ISOTRAK II: noise statistics, and the full path bytes -> parser ->
// timestamping -> conversion recovers what the device measured, when it measured it.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/error.h"
#include "lumar/tracking/isotrak_ascii.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/pose_stream.h"
#include "lumar/tracking/simulated_tracker.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {
namespace {

// A smooth, tumbling trajectory within a metre of the transmitter.
Pose trajectory(Nanos t) {
  const double s = nanos_to_seconds(t);
  Pose p;
  p.rotation = axis_angle_deg({std::sin(0.3 * s), std::cos(0.2 * s), 0.5}, 40.0 * s) *
               polhemus_attitude_to_quat(30.0, -20.0, 10.0);
  p.translation = {0.5 * std::cos(0.4 * s), 0.3 * std::sin(0.5 * s), -0.4 + 0.1 * std::sin(s)};
  return p;
}

constexpr int kSamples = 3000;
const Nanos kDuration = seconds_to_nanos((kSamples - 1) / 60.0);

struct Recovered {
  std::vector<PoseSample> samples;
  std::size_t rejected = 0, skipped = 0;
};

Recovered parse(const SimulatedTrackerOutput& out, const SimulatedTrackerSettings& s) {
  AsciiRecordParser parser(s.format, 2, s.baud);
  Recovered r;
  for (const auto& c : out.chunks) parser.push(c);
  for (const auto& rec : parser.take_all()) {
    const auto sample =
        to_pose_sample(rec.record, s.format, measurement_time(rec.first_byte_arrival, s.baud, s.device_latency));
    if (sample) r.samples.push_back(*sample);
  }
  r.rejected = parser.rejected_records();
  r.skipped = parser.skipped_bytes();
  return r;
}

TEST(SimulatedTracker, NoiseHasTheRequestedSize) {
  const SimulatedTrackerSettings s;
  const auto out = simulate_tracker(trajectory, kDuration, s);
  ASSERT_EQ(out.noisy_samples.size(), std::size_t(kSamples));
  ASSERT_EQ(out.chunks.size(), std::size_t(kSamples));
  double sum_angle2 = 0;
  glm::dvec3 sum_pos2(0.0), sum_pos(0.0);
  for (const auto& m : out.noisy_samples) {
    const Pose truth = trajectory(m.time);
    const double a = rotation_angle_deg(m.T_transmitter_sensor.rotation, truth.rotation);
    sum_angle2 += a * a;
    const glm::dvec3 d = m.T_transmitter_sensor.translation - truth.translation;
    sum_pos2 += d * d;
    sum_pos += d;
  }
  const double rms_angle = std::sqrt(sum_angle2 / kSamples);
  const glm::dvec3 rms_pos = glm::sqrt(sum_pos2 / double(kSamples));
  EXPECT_NEAR(rms_angle, 0.75, 0.05);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(rms_pos[k], 0.0025, 0.00025) << "axis " << k;
    EXPECT_NEAR(sum_pos[k] / kSamples, 0.0, 0.0002) << "axis " << k;  // unbiased (4 sigma of the mean)
  }
  std::printf("simulator: RMS orientation error %.4f deg, RMS position error %.5f %.5f %.5f m\n", rms_angle, rms_pos.x,
              rms_pos.y, rms_pos.z);
}

TEST(SimulatedTracker, ParserRecoversTimesAndPosesWithinQuantisation) {
  const SimulatedTrackerSettings s;
  const auto out = simulate_tracker(trajectory, kDuration, s);
  const Recovered r = parse(out, s);
  ASSERT_EQ(r.samples.size(), out.noisy_samples.size());
  EXPECT_EQ(r.rejected, 0u);
  EXPECT_EQ(r.skipped, 0u);
  Nanos worst_dt = 0;
  double worst_pos_in = 0, worst_deg = 0, sum_angle2 = 0;
  for (std::size_t k = 0; k < r.samples.size(); ++k) {
    const PoseSample& got = r.samples[k];
    const PoseSample& measured = out.noisy_samples[k];
    const Nanos t_k = seconds_to_nanos(double(k) / 60.0);  // independent of the simulator's own times
    EXPECT_EQ(measured.time, t_k);
    worst_dt = std::max(worst_dt, std::abs(got.time - t_k));
    const glm::dvec3 d = (got.T_transmitter_sensor.translation - measured.T_transmitter_sensor.translation) / 0.0254;
    worst_pos_in = std::max({worst_pos_in, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    worst_deg = std::max(worst_deg,
                         rotation_angle_deg(got.T_transmitter_sensor.rotation, measured.T_transmitter_sensor.rotation));
    const double a = rotation_angle_deg(got.T_transmitter_sensor.rotation, trajectory(t_k).rotation);
    sum_angle2 += a * a;
  }
  EXPECT_LE(worst_dt, 1000);
  EXPECT_LE(worst_pos_in, 0.005 + 1e-9);  // half of 0.01 in
  // Each Euler angle is off by at most 0.005 deg; composed, at most 0.015 deg.
  EXPECT_LE(worst_deg, 0.015);
  EXPECT_NEAR(std::sqrt(sum_angle2 / kSamples), 0.75, 0.05);  // end to end, after quantisation
  std::printf("simulator -> parser: worst time error %lld ns, position %.5f in, rotation %.5f deg\n",
              static_cast<long long>(worst_dt), worst_pos_in, worst_deg);
}

TEST(SimulatedTracker, NoiselessQuaternionRecordsFeedAPoseStream) {
  SimulatedTrackerSettings s;
  s.orientation_noise_deg = 0.0;
  s.position_noise_m = 0.0;
  s.format.output_list = {2, 11, 1};
  s.format.centimetres = true;
  s.rate_hz = 120.0;
  s.baud = 115200;
  s.device_latency = 7'000'000;
  const Nanos duration = 5 * kNanosPerSecond;
  const auto out = simulate_tracker(trajectory, duration, s);
  ASSERT_EQ(out.chunks.size(), 601u);
  // Last byte of record k: t_k + latency + 54 bytes * 10 / 115200 s (4687500 ns, exact).
  EXPECT_EQ(out.chunks[3].arrival, 25'000'000 + 7'000'000 + 4'687'500);
  const Recovered r = parse(out, s);
  ASSERT_EQ(r.samples.size(), 601u);
  PoseStream stream;
  double worst_deg = 0, worst_m = 0;
  for (std::size_t k = 0; k < r.samples.size(); ++k) {
    const Pose truth = trajectory(seconds_to_nanos(double(k) / 120.0));
    worst_deg = std::max(worst_deg, rotation_angle_deg(r.samples[k].T_transmitter_sensor.rotation, truth.rotation));
    const glm::dvec3 d = r.samples[k].T_transmitter_sensor.translation - truth.translation;
    worst_m = std::max({worst_m, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    stream.add(r.samples[k]);
  }
  EXPECT_LE(worst_m, 0.00005 + 1e-12);  // half of 0.01 cm
  // Four components each off by <= 5e-5: the rotation angle is off by < 2 * 1e-4 rad.
  EXPECT_LE(worst_deg, glm::degrees(2e-4));
  // Between samples the stream follows the trajectory (8.3 ms steps, smooth motion).
  double worst_mid = 0;
  for (int k = 0; k < 600; ++k) {
    const Nanos t = seconds_to_nanos((k + 0.5) / 120.0);
    const auto p = stream.at(t);
    ASSERT_TRUE(p.has_value());
    worst_mid = std::max(worst_mid, rotation_angle_deg(p->rotation, trajectory(t).rotation));
  }
  EXPECT_LE(worst_mid, 0.02);
  std::printf("noiseless 2,11,1 in cm: worst rotation %.5f deg, position %.2e m; midpoints %.5f deg\n", worst_deg,
              worst_m, worst_mid);
}

TEST(SimulatedTracker, IsDeterministicPerSeed) {
  SimulatedTrackerSettings s;
  const Nanos d = kNanosPerSecond;
  const auto a = simulate_tracker(trajectory, d, s);
  const auto b = simulate_tracker(trajectory, d, s);
  s.seed = 2;
  const auto c = simulate_tracker(trajectory, d, s);
  ASSERT_EQ(a.chunks.size(), 61u);
  bool all_same = true, any_differs = false;
  for (std::size_t k = 0; k < a.chunks.size(); ++k) {
    all_same = all_same && a.chunks[k].bytes == b.chunks[k].bytes && a.chunks[k].arrival == b.chunks[k].arrival;
    any_differs = any_differs || a.chunks[k].bytes != c.chunks[k].bytes;
  }
  EXPECT_TRUE(all_same);
  EXPECT_TRUE(any_differs);
}

TEST(SimulatedTracker, RefusesUnusableSettings) {
  SimulatedTrackerSettings s;
  s.baud = 1200;  // 47 bytes take 392 ms: cannot keep up with 60 Hz
  EXPECT_THROW(simulate_tracker(trajectory, kNanosPerSecond, s), InputError);
  s = {};
  s.rate_hz = 0.0;
  EXPECT_THROW(simulate_tracker(trajectory, kNanosPerSecond, s), InputError);
  s = {};
  s.position_noise_m = -1.0;
  EXPECT_THROW(simulate_tracker(trajectory, kNanosPerSecond, s), InputError);
  s = {};
  // 30 m is beyond the 999.99 in an ASCII field can hold.
  EXPECT_THROW(simulate_tracker(
                   [](Nanos) {
                     Pose p;
                     p.translation = {30.0, 0, 0};
                     return p;
                   },
                   kNanosPerSecond, s),
               std::invalid_argument);
}

}  // namespace
}  // namespace lumar::tracking
