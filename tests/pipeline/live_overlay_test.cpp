// The live overlay does what the replay does: the same recording, played as a live
// source (recording:DIR, in real time) with the tracker emulator on a pty in place of
// the recorded stream, gives the frames the replay gives with the recording's true
// poses: the session's response, vignetting and exposure are applied, the rig and its
// latency are used, and the lighting adaptation follows the room the same way.
//
// The recording holds the camera still, so the comparison does not depend on when the
// emulator's clock and the source's started; the emulator measures the true sensor
// pose without noise, so what differs is only the record format's quantisation.
#include <gtest/gtest.h>

#include <map>
#include <opencv2/core.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/capture/session.h"
#include "lumar/pipeline/live_inputs.h"
#include "lumar/pipeline/live_loop.h"
#include "lumar/pipeline/live_overlay.h"
#include "lumar/pipeline/registration_error.h"
#include "lumar/pipeline/replay_overlay.h"
#include "lumar/sim/synthetic_recording.h"
#include "lumar/tracking/tracker_emulator.h"
#include "test_paths.h"

namespace lumar {
namespace {

// A still camera's recording of the sample room, `frames` long, into `dir`.
std::filesystem::path record_still(const std::filesystem::path& dir, int frames) {
  sim::SynthSettings s;
  s.scene = test::source_dir() / "data/scenes/room/scene.json";
  s.out = dir;
  s.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.frames = frames;
  s.fps = 24;
  s.supersample = 1;
  s.path = "still";
  s.tracker_noise_deg = 0;
  s.position_noise_m = 0;
  s.codec = "ffv1";  // lossless: the replay and the live path decode the same pixels
  sim::synthesize_recording(s);
  return s.out;
}

// Two seconds of it, made once per test process.
const std::filesystem::path& still_recording() {
  static const test::Scratch scratch("live-overlay-still");
  static const std::filesystem::path dir = record_still(scratch.dir / "still", 48);
  return dir;
}

// Six seconds: live, the lighting is re-baked on a thread and faded in, which a slow
// build (ThreadSanitizer) needs a few seconds for.
const std::filesystem::path& long_still_recording() {
  static const test::Scratch scratch("live-overlay-long-still");
  static const std::filesystem::path dir = record_still(scratch.dir / "still", 144);
  return dir;
}

// The true sensor pose of the still camera, for the emulator to measure.
tracking::EmulatorSettings emulator_for(const capture::RecordingReplay& replay) {
  const capture::Session& session = replay.session();
  const Pose T_world_camera = *replay.true_camera_pose(0);
  const Pose sensor = session.rig.sensor_pose(T_world_camera);
  tracking::EmulatorSettings e;
  e.trajectory = [sensor](int, Nanos) { return sensor; };
  e.orientation_noise_deg = 0;
  e.position_noise_m = 0;
  e.device_latency = session.rig.latency;
  e.continuous_at_power_up = false;
  return e;
}

double psnr(const cv::Mat& a, const cv::Mat& b) { return std::min(99.0, cv::PSNR(a, b)); }

// These tests compare the two paths' radiometry and lighting; the composite's features
// (noise, blur, antialiasing, self-occlusion) have their own tests, and off they keep the
// frame rate, and so what a live source shows under ThreadSanitizer, as it was.
constexpr gl::CompositeFeatures kNoFeatures{false, false, false, false};

// The live overlay of the recording `dir` played as a camera, posed by the emulator.
pipeline::LiveOverlayOptions live_options(const std::filesystem::path& dir, const tracking::TrackerEmulator& emulator) {
  pipeline::LiveOverlayOptions lo;
  lo.in.source = "recording:" + dir.string();
  lo.in.tracker = "serial:" + emulator.port_path();
  lo.scene = test::source_dir() / "data/scenes/room/scene.json";
  lo.rig = dir / "session.json";  // rig, camera, radiometry and latency
  lo.max_wait_ms = 200;           // let the tracker connect before the first frames
  lo.overlay.window = false;
  lo.overlay.features = kNoFeatures;
  // The emulator is noise-free here: its poses are the truth's up to the record format's
  // quantisation, which the video's help (tested below with noise) would only blur.
  lo.steady_with_video = false;
  return lo;
}

struct Compared {
  int frames = 0;
  int settled = 0;  // frames where neither path was re-baking or fading the lighting
  double worst_psnr = 99.0;
  double live_scale = 1.0, replay_scale = 1.0;
};

Compared compare_live_with_replay(const std::filesystem::path& dir, int adapt_lighting_every) {
  pipeline::ReplayOverlaySettings rs;
  rs.poses = pipeline::PoseSource::Truth;
  rs.overlay.features = kNoFeatures;
  rs.overlay.adapt_lighting_every = adapt_lighting_every;
  pipeline::ReplayOverlay replay(dir, rs);
  std::map<std::int64_t, cv::Mat> expected;
  double replay_scale = 1.0;
  replay.run(0, [&](const pipeline::OverlayFrame& f) {
    if (f.lighting_settled) expected[f.index] = f.composite.clone();
    replay_scale = f.lighting_scale;
    return true;
  });

  tracking::TrackerEmulator emulator(emulator_for(replay.replay()));
  pipeline::LiveOverlayOptions lo = live_options(dir, emulator);
  lo.overlay.adapt_lighting_every = adapt_lighting_every;
  pipeline::LiveOverlay live(lo);
  Compared c;
  c.replay_scale = replay_scale;
  live.run([&](const pipeline::OverlayFrame& f) {
    if (!f.T_world_camera) return true;  // before the tracker connected
    ++c.frames;
    // Live, the lighting's re-bake runs on a thread and fades in when it is done; the
    // replay's at once: compare the frames where both had settled.
    if (f.lighting_settled && expected.count(f.index)) {
      ++c.settled;
      c.worst_psnr = std::min(c.worst_psnr, psnr(f.composite, expected.at(f.index)));
    }
    c.live_scale = f.lighting_scale;
    return true;
  });
  return c;
}

// A live source drops the frames the overlay is too slow for (36 of 48 at release speed;
// under ThreadSanitizer 42), so only a few compared frames are certain on any machine.
constexpr int kFewestLiveFrames = 4;

TEST(LiveOverlay, FramesMatchTheReplayOfTheSameInputs) {
  const Compared c = compare_live_with_replay(still_recording(), 0);
  std::printf("%d live frames with a pose, worst PSNR against the replay %.1f dB\n", c.frames, c.worst_psnr);
  EXPECT_GE(c.frames, kFewestLiveFrames);
  EXPECT_GE(c.worst_psnr, 40.0);
}

TEST(LiveOverlay, AdaptsTheLightingAsTheReplayDoes) {
  // The same video, but the session claims twice the exposure: the room looks half as
  // bright as the map predicts, and both paths follow it down to about 0.5.
  const test::Scratch scratch("live-overlay-adapt");
  const auto dir = scratch.dir / "brighter";
  std::filesystem::copy(long_still_recording(), dir, std::filesystem::copy_options::recursive);
  capture::update_session_file(dir, [](capture::Session& s) { s.radiometry.exposure *= 2; });
  const Compared c = compare_live_with_replay(dir, 2);
  std::printf(
      "%d frames, %d with the lighting settled in both; lighting scale live %.4f, replay %.4f; worst PSNR %.1f dB\n",
      c.frames, c.settled, c.live_scale, c.replay_scale, c.worst_psnr);
  EXPECT_GE(c.frames, kFewestLiveFrames);  // two lighting updates at least (every 2 frames)
  EXPECT_GE(c.settled, 1) << "the live path's re-baked lighting never finished fading in";
  EXPECT_NEAR(c.replay_scale, 0.5, 0.05);
  EXPECT_NEAR(c.live_scale, c.replay_scale, 0.01);
  EXPECT_GE(c.worst_psnr, 35.0);
}

TEST(LiveOverlay, WithoutTheSessionsRadiometryTheFramesDiffer) {
  // The check above would pass trivially if the two paths ignored the radiometry alike:
  // the live path with exposure 1 (the old fixed value) must differ from the replay.
  const std::filesystem::path& dir = still_recording();
  pipeline::ReplayOverlaySettings rs;
  rs.poses = pipeline::PoseSource::Truth;
  rs.overlay.features = kNoFeatures;
  pipeline::ReplayOverlay replay(dir, rs);
  std::map<std::int64_t, cv::Mat> expected;
  replay.run(0, [&](const pipeline::OverlayFrame& f) {
    expected[f.index] = f.composite.clone();
    return true;
  });
  tracking::TrackerEmulator emulator(emulator_for(replay.replay()));
  pipeline::LiveOverlayOptions lo = live_options(dir, emulator);
  lo.exposure = 1.0;
  pipeline::LiveOverlay live(lo);
  // The same frame of the recording (the same noise), so that only the radiometry differs:
  // the pixels it moves by more than 8 levels, where the matched radiometry moves none
  // (its frames are within 40 dB).
  double psnr_first = 0;
  int moved = 0;
  live.run([&](const pipeline::OverlayFrame& f) {
    if (!f.T_world_camera) return true;
    const cv::Mat& want = expected.at(f.index);
    psnr_first = psnr(f.composite, want);
    cv::Mat difference;
    cv::absdiff(f.composite, want, difference);
    moved = cv::countNonZero(difference.reshape(1) > 8);
    return false;
  });
  std::printf("exposure 1 instead of the session's: PSNR %.1f dB against the replay, %d pixel channels moved\n",
              psnr_first, moved);
  EXPECT_GT(moved, 1000);
  EXPECT_LT(psnr_first, 40.0);
}

// An orbit (60 degrees in 6 s, 4 frames/s) with the shutter open 200 ms, played as a
// camera with its own poses: the live path blurs the figurine over the shutter as the
// replay does with the same (the tracker's) poses, and differs from the frames without.
// Six seconds, so that a slow build (ThreadSanitizer) still shows a few frames.
TEST(LiveOverlay, BlursTheObjectsOverTheShutterAsTheReplayDoes) {
  const test::Scratch scratch("live-overlay-motion-blur");
  sim::SynthSettings s;
  s.scene = test::source_dir() / "data/scenes/room/scene.json";
  s.out = scratch.dir / "orbit";
  s.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.frames = 24;
  s.fps = 4;
  s.supersample = 1;
  s.faults.motion_blur_s = 0.2;
  s.codec = "ffv1";
  sim::synthesize_recording(s);

  gl::CompositeFeatures features = kNoFeatures;  // motion blur on, noise off: the frames repeat
  std::map<std::int64_t, cv::Mat> replayed[2];
  for (const bool blur : {false, true}) {
    pipeline::ReplayOverlaySettings rs;
    rs.poses = pipeline::PoseSource::Tracker;
    rs.overlay.features = features;
    rs.overlay.features.motion_blur = blur;
    pipeline::ReplayOverlay replay(s.out, rs);
    replay.run(0, [&](const pipeline::OverlayFrame& f) {
      replayed[blur][f.index] = f.composite.clone();
      return true;
    });
  }

  pipeline::LiveOverlayOptions lo;
  lo.in.source = "recording:" + s.out.string();
  lo.scene = s.scene;
  lo.overlay.window = false;
  lo.overlay.features = features;
  lo.steady_with_video = false;
  pipeline::LiveOverlay live(lo);
  EXPECT_DOUBLE_EQ(live.overlay().shutter_s(), 0.2);  // the source's (the recording's session's)
  int frames = 0, moved[2] = {0, 0};
  double worst_psnr_blurred = 99.0;
  live.run([&](const pipeline::OverlayFrame& f) {
    if (!f.T_world_camera) return true;
    ++frames;
    worst_psnr_blurred = std::min(worst_psnr_blurred, psnr(f.composite, replayed[1].at(f.index)));
    for (const int blur : {0, 1}) {
      cv::Mat difference;
      cv::absdiff(f.composite, replayed[blur].at(f.index), difference);
      moved[blur] += cv::countNonZero(difference.reshape(1) > 8);
    }
    return true;
  });
  std::printf(
      "%d live frames: worst PSNR %.1f dB against the replay's blurred ones; pixel channels more than 8 levels "
      "off: %d against them, %d against the sharp ones\n",
      frames, worst_psnr_blurred, moved[1], moved[0]);
  EXPECT_GE(frames, kFewestLiveFrames);
  EXPECT_GE(worst_psnr_blurred, 45.0);
  EXPECT_GT(moved[0], 100 * frames);
  EXPECT_LT(moved[1], moved[0] / 20);
}

// With motion blur a live frame waits until the tracker's samples pass its shutter's end,
// so that the camera at the shutter's last instant is interpolated, not extrapolated;
// without, only its middle. The recording played as a camera, the emulator on a pty.
TEST(LiveLoop, WithAShutterAFrameWaitsForTheTrackerToPassItsEnd) {
  const std::filesystem::path& dir = still_recording();
  const capture::RecordingReplay replay(dir);
  constexpr Nanos kShutter = 200'000'000;
  // covered: the tracker had passed the shutter's end; posed_at_end: the camera there was
  // known (the pose stream refuses to extrapolate that far, and the frame gets no blur).
  int frames[2] = {0, 0}, covered[2] = {0, 0}, posed_at_end[2] = {0, 0};
  for (const int blur : {0, 1}) {
    tracking::EmulatorSettings e = emulator_for(replay);
    e.device_latency = 0;
    tracking::TrackerEmulator emulator(e);
    pipeline::LiveInputOptions in;
    in.source = "recording:" + dir.string();
    in.tracker = "serial:" + emulator.port_path();
    pipeline::LiveLoopSettings settings;
    settings.max_wait = 2 * kShutter;
    settings.max_frames = 12;
    settings.shutter = blur ? kShutter : 0;
    pipeline::LiveLoop loop(pipeline::open_live_source(in).source, pipeline::make_tracker_driver(in, {}),
                            tracking::Rig{}, settings);
    Nanos newest = 0;  // the newest sample's measurement time the loop has taken
    loop.on_samples([&](const std::vector<tracking::PoseSample>& samples) {
      for (const auto& s : samples) newest = std::max(newest, s.time);
    });
    loop.wait_for_tracker(5 * kNanosPerSecond, "emulator");
    loop.run([&](capture::PairedFrame& paired) {
      ++frames[blur];
      if (newest >= paired.frame.time + kShutter / 2) ++covered[blur];
      if (loop.camera_at(paired.frame, paired.frame.time + kShutter / 2)) ++posed_at_end[blur];
      return true;
    });
  }
  std::printf(
      "frames whose shutter's end the tracker had passed: %d of %d waiting for it, %d of %d not; the camera "
      "there known for %d and %d\n",
      covered[1], frames[1], covered[0], frames[0], posed_at_end[1], posed_at_end[0]);
  EXPECT_GE(frames[1], kFewestLiveFrames);
  EXPECT_GE(frames[0], kFewestLiveFrames);
  EXPECT_EQ(covered[1], frames[1]);
  EXPECT_EQ(posed_at_end[1], frames[1]);
  EXPECT_LE(covered[0], frames[0] / 2);
}

// Live, with the tracker's usual noise (0.75 deg, 2.5 mm RMS): the video steadies it as on
// replay. The camera is still, so every live frame's pose is held to the one true pose;
// the emulator's noise is the same realisation in both runs (its seed). Six seconds, so
// that a slow build (ThreadSanitizer), which skips most frames and aligns the frame after
// each long gap, still shows a few.
TEST(LiveOverlay, SteadiesANoisyTrackerWithTheVideo) {
  const std::filesystem::path& dir = long_still_recording();
  const capture::RecordingReplay replay(dir);
  const Pose truth = *replay.true_camera_pose(0);
  double mean[2] = {0, 0};
  int frames[2] = {0, 0};
  for (int steady : {0, 1}) {
    tracking::EmulatorSettings noisy = emulator_for(replay);
    noisy.orientation_noise_deg = 0.75;
    noisy.position_noise_m = 0.0025;
    tracking::TrackerEmulator emulator(noisy);
    pipeline::LiveOverlayOptions lo = live_options(dir, emulator);
    lo.steady_with_video = steady == 1;
    pipeline::LiveOverlay live(lo);
    // Where the objects' points project, as registration_error measures it.
    const Compositor& compositor = live.overlay().compositor();
    live.run([&](const pipeline::OverlayFrame& f) {
      if (!f.T_world_camera) return true;
      mean[steady] += pipeline::projection_error_px(compositor.output_camera(), compositor.object_points(),
                                                    *f.T_world_camera, truth);
      ++frames[steady];
      return true;
    });
    if (frames[steady] > 0) mean[steady] /= frames[steady];
  }
  std::printf("live, noisy tracker: %d frames, tracker alone %.2f px mean; %d frames, steadied %.2f px mean\n",
              frames[0], mean[0], frames[1], mean[1]);
  EXPECT_GE(frames[0], kFewestLiveFrames);
  EXPECT_GE(frames[1], kFewestLiveFrames);
  EXPECT_GT(mean[0], 2.0);  // the noise is there
  EXPECT_LT(mean[1], 1.0);
  EXPECT_LT(mean[1], 0.3 * mean[0]);
}

TEST(PoseFilter, ParsesTheCommandLineForms) {
  EXPECT_FALSE(tracking::parse_pose_filter("none").has_value());
  const auto chosen = tracking::parse_pose_filter("one-euro");
  ASSERT_TRUE(chosen.has_value());
  EXPECT_DOUBLE_EQ(chosen->rotation.min_cutoff_hz, tracking::PoseFilterSettings{}.rotation.min_cutoff_hz);
  const auto given = tracking::parse_pose_filter("one-euro:0.2,1.5");
  ASSERT_TRUE(given.has_value());
  EXPECT_DOUBLE_EQ(given->rotation.min_cutoff_hz, 0.2);
  EXPECT_DOUBLE_EQ(given->position.beta, 1.5);
  EXPECT_THROW(tracking::parse_pose_filter("kalman"), InputError);
  EXPECT_THROW(tracking::parse_pose_filter("one-euro:0,1"), InputError);
  EXPECT_THROW(tracking::parse_pose_filter("one-euro:1"), InputError);
}

TEST(PoseFilter, ReplayFiltersTheTrackersSamples) {
  // The sample recording's tracker jitters 0.75 deg RMS: filtered, consecutive frames'
  // poses move less from one to the next than raw ones (the camera moves smoothly).
  const auto path = test::source_dir() / "recordings/orbit";
  const capture::RecordingReplay raw(path), filtered(path, tracking::parse_pose_filter("one-euro"));
  double raw_jerk = 0, filtered_jerk = 0;
  const auto& frames = raw.reader().frames();
  for (std::size_t k = 2; k < frames.size(); ++k) {
    const auto second_difference = [&](const capture::RecordingReplay& r) {
      const auto a = r.tracked_camera_pose(frames[k - 2].time), b = r.tracked_camera_pose(frames[k - 1].time),
                 c = r.tracked_camera_pose(frames[k].time);
      if (!a || !b || !c) return 0.0;
      return std::abs(rotation_angle_deg(a->rotation, b->rotation) - rotation_angle_deg(b->rotation, c->rotation));
    };
    raw_jerk += second_difference(raw);
    filtered_jerk += second_difference(filtered);
  }
  std::printf("frame-to-frame change of the rotation step: raw %.3f deg, filtered %.3f deg (summed)\n", raw_jerk,
              filtered_jerk);
  EXPECT_LT(filtered_jerk, 0.5 * raw_jerk);
}

}  // namespace
}  // namespace lumar
