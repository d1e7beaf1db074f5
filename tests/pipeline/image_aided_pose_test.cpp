// Image-aided tracking on synthetic recordings, against their true poses, with absolute
// fixes from the frame aligned with the room the proxy predicts (the default): the shipped
// orbit and walk, and more made here: a room unlike the proxy the overlay is given (a low
// table, a box, a cabinet, a wall 3 cm off with a recess), a rest-then-turn (held 2 s, 30 deg/s for 1 s,
// held), and what goes wrong with video: ten dropped frames, a textureless view, a panel
// sliding across half the view, motion blur. The tracker has 0.75 deg / 2.5 mm noise and 20 ms
// latency in all of them. Registration is measured as `lumar regress` measures it
// (pipeline::registration_error).
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

#include "lumar/calib/camera_file.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/image_aided_pose.h"
#include "lumar/pipeline/registration_error.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/sim/synthetic_recording.h"
#include "test_paths.h"

namespace lumar {
namespace {

std::filesystem::path synthesize(const std::string& name, const std::function<void(sim::SynthSettings&)>& change) {
  static const test::Scratch scratch("image-aided-pose");
  sim::SynthSettings s;
  s.scene = test::source_dir() / "data/scenes/room/scene.json";
  s.out = scratch.dir / name;
  s.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.supersample = 1;
  change(s);
  sim::synthesize_recording(s);
  return s.out;
}

struct Both {
  pipeline::RegistrationError tracker, fused;
  int worse = 0;  // frames where the fused pose is worse than the tracker's by over 1 px
};

Both measure(const std::filesystem::path& recording, const pipeline::ReplayOverlaySettings& settings = {}) {
  pipeline::ReplayOverlay overlay(recording, settings);
  Both b{pipeline::registration_error(overlay, pipeline::PoseSource::Tracker),
         pipeline::registration_error(overlay, pipeline::PoseSource::Fused)};
  std::string which;
  for (std::size_t k = 0; k < b.fused.px.size(); ++k)
    if (b.fused.px[k] > b.tracker.px[k] + 1.0) {
      char line[64];
      std::snprintf(line, sizeof line, " %zu (%.2f against %.2f)", k, b.fused.px[k], b.tracker.px[k]);
      ++b.worse, which += line;
    }
  std::printf(
      "%s: tracker mean %.2f px, p95 %.2f; fused mean %.2f px, p95 %.2f, jitter %.2f px, lag %.1f ms, "
      "overshoot %.2f px, largest jump %.2f px (tracker: %.2f px, %.1f ms, %.2f px, %.2f px); %d frames worse by "
      "over 1 px:%s\n",
      recording.filename().c_str(), b.tracker.mean, b.tracker.p95, b.fused.mean, b.fused.p95, b.fused.jitter_px,
      b.fused.lag_ms, b.fused.overshoot_px, b.fused.jump_px, b.tracker.jitter_px, b.tracker.lag_ms,
      b.tracker.overshoot_px, b.tracker.jump_px, b.worse, which.c_str());
  EXPECT_EQ(b.fused.px.size(), b.tracker.px.size());
  return b;
}

// The video alone: the true pose for the first frame, no tracker after it. What is left is
// the drift of the chain of frame-to-frame poses from the corners on the proxy.
TEST(ImageAidedPose, TheVideoAloneFollowsTheCameraFromItsFirstPose) {
  const capture::RecordingReplay replay(test::source_dir() / "recordings/orbit");
  const LoadedScene scene = load_scene_files(replay.scene_path());
  pipeline::ImageAidedPose fused(replay.session().camera, scene.room);
  const CameraIntrinsics pinhole = replay.session().camera.without_distortion();
  std::vector<glm::dvec3> points;
  for (std::size_t i = 0; i < scene.objects[0].model.positions.size(); i += 97)
    points.emplace_back(scene.objects[0].T_world_model *
                        glm::dvec4(glm::dvec3(scene.objects[0].model.positions[i]), 1.0));
  auto frames = replay.open_frames();
  capture::Frame frame;
  double sum = 0, last = 0;
  int n = 0;
  while (frames->read(frame)) {
    const auto truth = replay.true_camera_pose(frame.index);
    const auto pose = fused.update(frame, frame.index == 0 ? truth : std::nullopt);
    ASSERT_TRUE(pose && truth);
    last = pipeline::projection_error_px(pinhole, points, *pose, *truth), sum += last, ++n;
  }
  std::printf(
      "the video alone from the true first pose: mean %.2f px, last frame %.2f px over %d frames; %.0f "
      "inliers\n",
      sum / n, last, n, fused.stats().inliers);
  EXPECT_EQ(fused.stats().visual_frames, n - 1);
  EXPECT_LT(sum / n, 0.5);
  EXPECT_LT(last, 1.0);
}

// The shipped recordings: the tracker's 4.6-5.1 px mean (9 px p95) to a fraction of a
// pixel, from the first frame on: it is aligned with the room the proxy predicts.
TEST(ImageAidedPose, SteadiesTheTrackerOnTheSampleRecordings) {
  for (const char* name : {"orbit", "walk"}) {
    const Both b = measure(test::source_dir() / "recordings" / name);
    EXPECT_LT(b.fused.mean, 0.5) << name;  // the issue: <= 1.0
    EXPECT_LT(b.fused.p95, 1.0) << name;   // the issue: <= 2.5
    EXPECT_LT(b.fused.px[0], 0.5) << name << ": the first frame's fix";
    EXPECT_EQ(b.worse, 0) << name;
    EXPECT_LT(b.fused.jump_px, 1.0) << name;
    EXPECT_GT(b.tracker.jump_px, 5.0) << name;
  }
}

// Without absolute fixes the fused pose starts as the tracker's and becomes the running
// mean of its offsets from the video's path, so the first frames are as bad as a few
// tracker samples: the fixes are what bring the p95 down.
TEST(ImageAidedPose, WithoutFixesTheStartIsTheTrackersMean) {
  pipeline::ReplayOverlaySettings settings;
  settings.image_aided.fusion.fix_worth = 0;
  const Both b = measure(test::source_dir() / "recordings/orbit", settings);
  EXPECT_NEAR(b.fused.px[0], b.tracker.px[0], 1e-9) << "the first frame is the tracker's";
  EXPECT_LT(b.fused.mean, 1.1);
  EXPECT_GT(b.fused.p95, 2.5);
}

// The video shows a low table, a box and a cabinet the proxy does not have, and a wall 3 cm
// further back with a recess in it: the corners on them get the wrong depth, and the
// fixes' matches on them are wrong; RANSAC must leave them out. The targets for
// the sample (mean <= 1 px, p95 <= 2.5 px) hold here too.
TEST(ImageAidedPose, HoldsInARoomUnlikeTheProxy) {
  const Both b = measure(synthesize("room-differs", [](sim::SynthSettings& s) { s.room_differs = true; }));
  EXPECT_LT(b.fused.mean, 0.6);
  EXPECT_LT(b.fused.p95, 1.0);
  EXPECT_EQ(b.worse, 0);
  EXPECT_LT(b.fused.jump_px, 1.0);  // the fixes pull without a jump
}

// Held 2 s, turned at 30 deg/s for 1 s, held: the jitter, lag and overshoot.
TEST(ImageAidedPose, RestThenTurnNeitherJittersNorLagsNorOvershoots) {
  const Both b = measure(synthesize("rest-turn", [](sim::SynthSettings& s) {
    s.path = "rest-turn";
    s.frames = 108;
    s.fps = 24;
  }));
  EXPECT_LT(b.fused.jitter_px, 0.3);
  EXPECT_LT(std::abs(b.fused.lag_ms), 5.0);
  EXPECT_LT(b.fused.overshoot_px, 1.0);
  EXPECT_GT(b.tracker.jitter_px, 3.0);  // what it steadies
  EXPECT_LT(b.fused.mean, 0.5);
  EXPECT_EQ(b.worse, 0);
}

// Ten frames missing: the video cannot bridge 12.8 degrees of turn on the rug's stripes,
// the tracker's motion does, and the frame after the gap is aligned with the proxy's room.
TEST(ImageAidedPose, BridgesTenDroppedFrames) {
  const auto recording = synthesize("dropped", [](sim::SynthSettings& s) { s.faults.dropped = {20, 10}; });
  ASSERT_EQ(capture::RecordingReplay(recording).reader().frames().size(), 38u);
  const Both b = measure(recording);
  EXPECT_LT(b.fused.mean, 0.5);
  EXPECT_EQ(b.worse, 0);
  EXPECT_LT(b.fused.jump_px, 1.0);
}

// The video cannot tell for half a second (a flat wall), or half of it moves on its own (a
// panel walking through), or every frame is smeared by a full frame period of motion
// (about 1.3 degrees, 12 px): no frame is worse than the tracker's by over 1 px, and the
// objects never jump by over 1 px from one frame to the next (the tracker's: 17 px).
TEST(ImageAidedPose, DegradesGracefully) {
  const std::vector<std::pair<std::string, std::function<void(sim::SynthSettings&)>>> cases{
      {"textureless",
       [](sim::SynthSettings& s) {
         s.faults.textureless = {16, 12};
       }},
      {"occluder",
       [](sim::SynthSettings& s) {
         s.faults.occluder = {12, 24};
       }},
      {"motion-blur", [](sim::SynthSettings& s) { s.faults.motion_blur_s = 1.0 / 24; }}};
  for (const auto& [name, change] : cases) {
    const Both b = measure(synthesize(name, change));
    EXPECT_LT(b.fused.mean, 1.2) << name;
    EXPECT_EQ(b.worse, 0) << name;
    EXPECT_LT(b.fused.jump_px, 1.0) << name;
    EXPECT_GT(b.tracker.jump_px, 5.0) << name;
  }
}

}  // namespace
}  // namespace lumar
