// Frame-pose pairing against known truth: a noise-free simulated tracker (the real
// byte stream, parser and timestamping) with a known device latency, where the paired
// pose must match truth within the interpolation error of the sample rate; and the
// synthetic sample recording (recordings/orbit), whose tracker has noise.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "lumar/base/constants.h"
#include "lumar/capture/frame_pose_pairing.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_parser.h"
#include "lumar/tracking/simulated_tracker.h"
#include "lumar/tracking/timestamping.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {

// A smooth head-like motion of the sensor in the transmitter frame, away from the
// Euler angles' gimbal lock.
Pose true_sensor(Nanos t) {
  const double s = nanos_to_seconds(t), w = 2 * kPi * 0.5;
  Pose p;
  p.translation = {0.3 * std::cos(w * s), 0.2 * std::sin(w * s), 0.4 + 0.05 * std::sin(2 * w * s)};
  p.rotation =
      axis_angle_deg(glm::normalize(glm::dvec3(1, 0.5, 0.2)), 40 * std::sin(w * s)) * axis_angle_deg({0, 0, 1}, 30 * s);
  return p;
}

tracking::Rig test_rig(Nanos latency) {
  tracking::Rig rig;
  rig.T_world_transmitter.translation = {0.85, 0.72, -0.75};
  rig.T_world_transmitter.rotation = axis_angle_deg({1, 0, 0}, 90);
  rig.T_sensor_camera.translation = {0.03, 0.05, -0.02};
  rig.T_sensor_camera.rotation = axis_angle_deg({0, 0, 1}, 90);
  rig.latency = latency;
  return rig;
}

struct Errors {
  double position_m = 0, rotation_deg = 0;
};
Errors error(const Pose& a, const Pose& b) {
  return {glm::length(a.translation - b.translation), rotation_angle_deg(a.rotation, b.rotation)};
}

TEST(FramePosePairing, MatchesTruthWithinTheInterpolationErrorAtAKnownLatency) {
  const Nanos latency = 20'000'000;
  const double rate = 60;
  tracking::SimulatedTrackerSettings ts;
  ts.rate_hz = rate;
  ts.device_latency = latency;
  ts.orientation_noise_deg = 0;
  ts.position_noise_m = 0;
  const auto out = tracking::simulate_tracker(true_sensor, 3 * kNanosPerSecond, ts);

  // The live path: bytes -> parser -> measurement time (device latency removed) -> pairing.
  const tracking::Rig rig = test_rig(latency);
  std::vector<tracking::PoseSample> samples;
  tracking::RecordParser parser(tracking::TrackerFormat::of(tracking::Device::Isotrak2, false, ts.format), ts.baud);
  for (const auto& chunk : out.chunks) {
    parser.push(chunk);
    for (const auto& r : parser.take_all())
      if (auto s = tracking::to_pose_sample(r.record, ts.format,
                                            tracking::measurement_time(r.first_byte_arrival, ts.baud, latency)))
        samples.push_back(*s);
  }
  ASSERT_EQ(samples.size(), out.chunks.size());
  FramePosePairing pairing(rig);
  pairing.add(samples);
  // The same samples with the latency forgotten: the pose 20 ms too early.
  tracking::PoseLookupSettings forgotten;
  forgotten.time_offset = -latency;
  FramePosePairing stale(rig, 1, forgotten);
  stale.add(samples);

  // Brute-force reference: the true poses at the two sample times around t,
  // interpolated the same way. That is all a 60 Hz tracker can know.
  const auto interpolation_error = [&](Nanos t) {
    const Nanos k = Nanos(std::floor(nanos_to_seconds(t) * rate));
    const Nanos t0 = std::llround(double(k) * 1e9 / rate), t1 = std::llround(double(k + 1) * 1e9 / rate);
    const Pose interpolated = interpolate(true_sensor(t0), true_sensor(t1), double(t - t0) / double(t1 - t0));
    return error(rig.camera_pose(interpolated), rig.camera_pose(true_sensor(t)));
  };

  // Frames at 30 fps, out of phase with the tracker.
  Errors worst, worst_interpolation, worst_stale;
  int frames = 0;
  for (Nanos t = 107'300'000; t < 2'800'000'000; t += 33'333'333, ++frames) {
    Frame f;
    f.time = t;
    const PairedFrame p = pairing.pair(f);
    ASSERT_EQ(p.sensor.status, tracking::PoseStatus::Interpolated) << "t " << t;
    ASSERT_TRUE(p.T_world_camera);
    const Pose truth = rig.camera_pose(true_sensor(t));
    const Errors e = error(*p.T_world_camera, truth);
    const Errors ei = interpolation_error(t);

    // Plus the record's quantisation: 0.01 in per axis, 0.01 deg per Euler angle.
    EXPECT_LE(e.position_m, ei.position_m + 0.30e-3) << "t " << t;
    EXPECT_LE(e.rotation_deg, ei.rotation_deg + 0.015) << "t " << t;
    worst.position_m = std::max(worst.position_m, e.position_m);
    worst.rotation_deg = std::max(worst.rotation_deg, e.rotation_deg);
    worst_interpolation.position_m = std::max(worst_interpolation.position_m, ei.position_m);
    worst_interpolation.rotation_deg = std::max(worst_interpolation.rotation_deg, ei.rotation_deg);

    // Another instant of the frame's shutter (motion blur): the same poses, the same
    // bounds; at the frame's own time, the paired pose itself.
    EXPECT_EQ(pairing.camera_at(t)->translation, p.T_world_camera->translation);
    for (const Nanos dt : {-10'000'000, 10'000'000}) {
      const std::optional<Pose> then = pairing.camera_at(t + dt);
      ASSERT_TRUE(then);
      const Errors et = error(*then, rig.camera_pose(true_sensor(t + dt))), eit = interpolation_error(t + dt);
      EXPECT_LE(et.position_m, eit.position_m + 0.30e-3) << "t " << t + dt;
      EXPECT_LE(et.rotation_deg, eit.rotation_deg + 0.015) << "t " << t + dt;
      EXPECT_GT(error(*then, *p.T_world_camera).position_m, 1e-3);  // the motion is there (>1 mm in 10 ms)
    }

    const PairedFrame ps = stale.pair(f);
    ASSERT_TRUE(ps.T_world_camera);
    const Errors es = error(*ps.T_world_camera, truth);
    worst_stale.position_m = std::max(worst_stale.position_m, es.position_m);
    worst_stale.rotation_deg = std::max(worst_stale.rotation_deg, es.rotation_deg);
  }
  EXPECT_EQ(frames, 81);
  // The check can fail: forgetting the latency breaks both bounds by far.
  EXPECT_GT(worst_stale.position_m, 10 * (worst_interpolation.position_m + 0.30e-3));
  EXPECT_GT(worst_stale.rotation_deg, 10 * (worst_interpolation.rotation_deg + 0.015));
  std::printf(
      "pairing vs truth over %d frames: worst %.3f mm, %.4f deg; interpolation alone %.3f mm, %.4f deg; "
      "latency forgotten %.1f mm, %.2f deg\n",
      frames, worst.position_m * 1e3, worst.rotation_deg, worst_interpolation.position_m * 1e3,
      worst_interpolation.rotation_deg, worst_stale.position_m * 1e3, worst_stale.rotation_deg);
}

// recordings/orbit: 48 frames at 24 fps, a 60 Hz ISOTRAK II with 0.75 deg and 2.5 mm
// RMS noise and 20 ms latency, and the true camera pose of every frame.
TEST(FramePosePairing, PairsTheOrbitRecordingWithinTheTrackerNoise) {
  const auto dir = test::source_dir() / "recordings" / "orbit";
  const RecordingReplay replay(dir);
  const Session& session = replay.session();
  FramePosePairing pairing(session.rig, session.tracker.station);
  pairing.add(replay.reader().poses());  // decoded, latency removed
  const auto truth = replay.reader().truth();
  ASSERT_EQ(truth.size(), replay.reader().frames().size());

  auto rms_errors = [&](const FramePosePairing& p, Nanos shift) {
    double sp = 0, sr = 0;
    for (const auto& e : truth) {
      Frame f;
      f.time = e.time + shift;
      const PairedFrame pf = p.pair(f);
      EXPECT_TRUE(pf.T_world_camera) << "frame " << e.index;
      if (!pf.T_world_camera) continue;
      const Errors err = error(*pf.T_world_camera, e.T_world_camera);
      sp += err.position_m * err.position_m;
      sr += err.rotation_deg * err.rotation_deg;
      if (shift == 0) {
        // The same pose as the replay computes from the raw tracker bytes.
        const auto replayed = replay.tracked_camera_pose(e.time);
        EXPECT_TRUE(replayed);
        if (replayed) {
          EXPECT_LT(error(*replayed, *pf.T_world_camera).position_m, 1e-6);
        }
      }
    }
    const double n = double(truth.size());
    return Errors{std::sqrt(sp / n), std::sqrt(sr / n)};
  };
  const Errors e = rms_errors(pairing, 0);
  const Errors late = rms_errors(pairing, 100'000'000);
  std::printf("orbit: RMS %.2f mm, %.3f deg (tracker noise 2.5 mm/axis, 0.75 deg); 100 ms late: %.2f mm, %.3f deg\n",
              e.position_m * 1e3, e.rotation_deg, late.position_m * 1e3, late.rotation_deg);
  // Noise of one sample: 2.5 mm per axis is 4.33 mm in 3-D, plus 0.75 deg on the 6 cm
  // lever to the camera (0.8 mm): 4.4 mm; 0.75 deg RMS angle. Interpolating between
  // two noisy samples can only average it down; a pairing off in time adds to it.
  EXPECT_LT(e.position_m, 4.4e-3);
  EXPECT_LT(e.rotation_deg, 0.80);
  EXPECT_GT(late.rotation_deg, 2 * e.rotation_deg);
}

TEST(FramePosePairing, CoversOnlyOnceASampleAtTheFrameTimeArrived) {
  FramePosePairing pairing(test_rig(0), 1);
  EXPECT_FALSE(pairing.covers(0));
  Frame f;
  f.time = 50;
  EXPECT_EQ(pairing.pair(f).sensor.status, tracking::PoseStatus::NoSamples);
  pairing.add({0, 1, true_sensor(0)});
  EXPECT_FALSE(pairing.covers(50));
  pairing.add({100, 1, true_sensor(100)});
  EXPECT_TRUE(pairing.covers(50));
  for (Nanos t = 200; t < 2000; t += 100) pairing.add({t, 1, true_sensor(t)});
  pairing.forget_before(1050);
  EXPECT_EQ(pairing.samples(), 10u);  // 1000 ... 1900: 1000 kept to interpolate 1050
  f.time = 1050;
  const PairedFrame p = pairing.pair(f);
  ASSERT_TRUE(p.sensor.pose);
  EXPECT_LT(error(*p.sensor.pose, interpolate(true_sensor(1000), true_sensor(1100), 0.5)).position_m, 1e-12);
}

// A tracker thread adding samples while a render thread pairs frames (for TSan).
TEST(FramePosePairing, AddAndPairFromTwoThreads) {
  FramePosePairing pairing(test_rig(0), 1);
  std::thread tracker([&] {
    for (Nanos t = 0; t < 2000 * 1'000'000; t += 1'000'000) pairing.add({t, 1, true_sensor(t)});
  });
  int paired = 0;
  for (Nanos t = 0; t < 2000 * 1'000'000; t += 1'000'000) {
    while (!pairing.covers(t)) std::this_thread::yield();
    Frame f;
    f.time = t;
    if (pairing.pair(f).T_world_camera) ++paired;
  }
  tracker.join();
  EXPECT_EQ(paired, 2000);
}

}  // namespace
}  // namespace lumar::capture
