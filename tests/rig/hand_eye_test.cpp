// The pieces of the rig calibration against exact references: cv::calibrateHandEye on
// noise-free poses made from a known offset, the time offset of two speed signals with a
// known shift, and the board poses found in rendered frames against the renderer's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "board_recordings.h"
#include "lumar/base/error.h"
#include "lumar/calib/hand_eye_calibration.h"
#include "lumar/calib/latency_estimation.h"
#include "lumar/capture/recording_reader.h"

namespace lumar {
namespace {

Pose random_pose(std::mt19937_64& rng, double max_angle_deg, double max_t) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const glm::dvec3 axis = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)) + glm::dvec3(1e-9));
  return Pose{axis_angle_deg(axis, max_angle_deg * u(rng)), {max_t * u(rng), max_t * u(rng), max_t * u(rng)}};
}

TEST(HandEye, RecoversAnExactOffsetFromNoiseFreePoses) {
  std::mt19937_64 rng(7);
  const Pose X = random_pose(rng, 120, 0.05);  // T_sensor_camera
  const Pose Z = random_pose(rng, 180, 0.8);   // T_transmitter_board
  std::vector<Pose> sensor, board;
  for (int i = 0; i < 40; ++i) {
    const Pose S = random_pose(rng, 60, 0.5);
    sensor.push_back(S);
    board.push_back((S * X).inverse() * Z);  // T_camera_board = (T_transmitter_camera)^-1 * Z
  }
  for (auto method : {calib::HandEyeMethod::Tsai, calib::HandEyeMethod::Park, calib::HandEyeMethod::Daniilidis}) {
    calib::HandEyeOptions options;
    options.method = method;
    options.max_views = 20;
    const auto s = calib::solve_hand_eye(sensor, board, options);
    EXPECT_LT(glm::length(s.T_sensor_camera.translation - X.translation), 1e-6);
    EXPECT_LT(rotation_angle_deg(s.T_sensor_camera.rotation, X.rotation), 1e-5);
    EXPECT_LT(glm::length(s.T_transmitter_board.translation - Z.translation), 1e-6);
    EXPECT_LT(rotation_angle_deg(s.T_transmitter_board.rotation, Z.rotation), 1e-5);
    EXPECT_EQ(s.views_used.size(), 20u);
    EXPECT_GT(s.min_pair_rotation_deg, 5.0);
  }
  EXPECT_THROW(calib::solve_hand_eye({sensor[0], sensor[1]}, {board[0], board[1]}), InputError);
}

TEST(HandEye, SpreadRotationsPicksTheFarthestFirst) {
  // Rotations about one axis by 0, 1, ..., 90 degrees: after 0 comes 90, then 45.
  std::vector<glm::dquat> q;
  for (int a = 0; a <= 90; ++a) q.push_back(axis_angle_deg({0, 1, 0}, a));
  const auto picked = calib::spread_rotations(q, 3);
  ASSERT_EQ(picked.size(), 3u);
  EXPECT_EQ(picked[0], 0);
  EXPECT_EQ(picked[1], 90);
  EXPECT_EQ(picked[2], 45);
}

// A rigid body turning with angular speed 50 + 25 sin(2 pi 0.3 t) + 10 sin(2 pi 0.77 t)
// + 15 sin(2 pi 1.1 t) deg/s about a fixed axis: video poses at 30 Hz, tracker poses at 60 Hz whose clock runs
// `shift` late, with 0.75 deg RMS noise.
TEST(TimeOffset, FindsAKnownShiftBetweenTwoSpeedSignals) {
  const Nanos shift = 37'300'000;
  auto angle = [](double t) {  // integral of the speed, degrees
    const double pi = 3.14159265358979323846;
    return 50 * t - 25 / (2 * pi * 0.3) * std::cos(2 * pi * 0.3 * t) -
           10 / (2 * pi * 0.77) * std::cos(2 * pi * 0.77 * t) - 15 / (2 * pi * 1.1) * std::cos(2 * pi * 1.1 * t);
  };
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 1, -0.2));
  std::vector<Nanos> vt, tt;
  std::vector<glm::dquat> vr, tr;
  for (int k = 0; k < 300; ++k) {
    const Nanos t = 500'000'000 + Nanos(k) * 33'333'333;
    vt.push_back(t), vr.push_back(axis_angle_deg(axis, angle(nanos_to_seconds(t))));
  }
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.75 / std::sqrt(3.0));
  for (int k = 0; k < 660; ++k) {
    const Nanos t = Nanos(k) * 16'666'667;
    const glm::dvec3 e(noise(rng), noise(rng), noise(rng));
    const glm::dquat n =
        glm::length(e) > 0 ? axis_angle_deg(glm::normalize(e), glm::length(e)) : glm::dquat(1, 0, 0, 0);
    tt.push_back(t + shift), tr.push_back(n * axis_angle_deg(axis, angle(nanos_to_seconds(t))));
  }
  const calib::TimeOffsetOptions options;
  const auto est = calib::estimate_time_offset(calib::angular_speed(vt, vr, options.video_span),
                                               calib::angular_speed(tt, tr, options.tracker_span), options);
  std::printf("known shift 37.3 ms, cross-correlation %.3f ms, peak r %.3f\n", nanos_to_seconds(est.offset) * 1e3,
              est.peak_correlation);
  EXPECT_NEAR(nanos_to_seconds(est.offset) * 1e3, 37.3, 1.5);
  EXPECT_GT(est.peak_correlation, 0.8);
  EXPECT_LT(est.correlation_at_zero, est.peak_correlation);

  // Constant speed: nothing to correlate.
  std::vector<calib::AngularSpeedSample> flat;
  for (int k = 0; k < 100; ++k) flat.push_back({Nanos(k) * 16'666'667, 30.0});
  EXPECT_THROW(calib::estimate_time_offset(flat, flat), InputError);
}

// The renderer and the detector agree with the truth: board poses from solvePnP on the
// rendered frames against T_camera_board from truth.csv.
TEST(BoardPose, RenderedFramesGiveTheTruePose) {
  const sim::BoardSynthSettings args = test::noisy_board();
  const auto& rec = test::loaded_board_recording(args);
  const capture::RecordingReader reader(test::board_recording(args));
  const auto truth = reader.truth();
  ASSERT_EQ(rec.views.size(), truth.size()) << "the board must be found in every frame";
  const Pose T_world_board{axis_angle_deg({1, 0, 0}, 90.0), {0, 0, 0}};
  double worst_mm = 0, worst_deg = 0, worst_px = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Pose expected = truth[i].T_world_camera.inverse() * T_world_board;
    worst_mm = std::max(worst_mm, 1e3 * glm::length(rec.views[i].T_camera_board.translation - expected.translation));
    worst_deg = std::max(worst_deg, rotation_angle_deg(rec.views[i].T_camera_board.rotation, expected.rotation));
    worst_px = std::max(worst_px, rec.views[i].reprojection_rms_px);
  }
  std::printf("board poses over %zu frames: worst %.3f mm, %.4f deg; worst PnP RMS %.3f px\n", truth.size(), worst_mm,
              worst_deg, worst_px);
  EXPECT_LT(worst_mm, 1.0);
  EXPECT_LT(worst_deg, 0.1);
  EXPECT_LT(worst_px, 0.3);
}

}  // namespace
}  // namespace lumar
