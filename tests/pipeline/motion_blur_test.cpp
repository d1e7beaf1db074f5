// The objects' motion blur against the truth of a camera whose shutter stays open (synth
// --motion-blur: the room and the objects physically present, each averaged over five
// instants of the shutter): the walk's figurine passing a still camera, whose motion the
// overlay knows exactly from its path, and an orbit fast enough to smear the figurine,
// whose camera between frames comes from the truth's spline
// (RecordingReplay::true_camera_pose_at). Each composite with the motion blur against the
// same without it (docs/ground_truth.md, "Motion blur").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "lumar/calib/camera_file.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/truth_comparison.h"
#include "lumar/sim/synthetic_recording.h"
#include "test_paths.h"

namespace lumar {
namespace {

std::filesystem::path synthesize(const std::string& name, const std::function<void(sim::SynthSettings&)>& change) {
  static const test::Scratch scratch("motion-blur");
  sim::SynthSettings s;
  s.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.out = scratch.dir / name;
  s.supersample = 1;
  s.truth = true;
  s.truth_strata = 8;
  change(s);
  sim::synthesize_recording(s);
  return s.out;
}

struct WithAndWithout {
  pipeline::CompositeError with, without;
};

WithAndWithout measure(const std::filesystem::path& recording, const char* what) {
  WithAndWithout out;
  for (const bool on : {true, false}) {
    pipeline::ReplayOverlaySettings settings;
    settings.overlay.features.motion_blur = on;
    (on ? out.with : out.without) = pipeline::compare_with_truth(recording, settings)->error;
  }
  std::printf("%s: object %.2f -> %.2f %%, edge %.2f -> %.2f %%, shadow %.2f -> %.2f %% with the motion blur\n", what,
              out.without.object_err, out.with.object_err, out.without.edge_err, out.with.edge_err,
              out.without.shadow_err, out.with.shadow_err);
  return out;
}

TEST(MotionBlur, FollowsAFigurineWalkingPastAStillCamera) {
  // 12 frames/s, the shutter open 80 ms: the figurine (0.45 m/s) moves about 9 px in it.
  const auto recording = synthesize("walk", [](sim::SynthSettings& s) {
    s.scene = test::source_dir() / "data/scenes/room/walk.json";
    s.path = "still";
    s.frames = 12;
    s.fps = 12;
    s.faults.motion_blur_s = 0.08;
    s.truth_frames = {5};
  });
  EXPECT_DOUBLE_EQ(capture::RecordingReplay(recording).session().radiometry.shutter_s, 0.08);
  const WithAndWithout e = measure(recording, "walk");
  EXPECT_LT(e.with.edge_err, e.without.edge_err - 0.3);
  EXPECT_LT(e.with.object_err, e.without.object_err - 0.15);
  EXPECT_LT(e.with.shadow_err, e.without.shadow_err + 0.05);
}

TEST(MotionBlur, FollowsTheCameraBetweenTheTruthsFrames) {
  // 8 frames/s over the orbit's 60 degrees, the shutter open 100 ms: the camera turns
  // 7 degrees while it is open.
  const auto recording = synthesize("orbit", [](sim::SynthSettings& s) {
    s.scene = test::source_dir() / "data/scenes/room/scene.json";
    s.frames = 8;
    s.fps = 8;
    s.faults.motion_blur_s = 0.1;
    s.truth_frames = {3};
  });
  const WithAndWithout e = measure(recording, "orbit");
  EXPECT_LT(e.with.edge_err, 0.85 * e.without.edge_err);
  EXPECT_LT(e.with.object_err, 0.9 * e.without.object_err);

  // Between frames the truth's spline keeps to the orbit, a horizontal circle, where a
  // chord cuts it by its sagitta.
  const capture::RecordingReplay replay(recording);
  const auto& truth = replay.reader().truth();
  ASSERT_EQ(truth.size(), 8u);
  const auto xz = [](const Pose& p) { return glm::dvec2(p.translation.x, p.translation.z); };
  // The circle through frames 0, 4 and 7 (the perpendicular bisectors of two chords meet at its centre).
  const glm::dvec2 a = xz(truth[0].T_world_camera), b = xz(truth[4].T_world_camera), c = xz(truth[7].T_world_camera);
  const double d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
  const glm::dvec2 centre((glm::dot(a, a) * (b.y - c.y) + glm::dot(b, b) * (c.y - a.y) + glm::dot(c, c) * (a.y - b.y)) / d,
                          (glm::dot(a, a) * (c.x - b.x) + glm::dot(b, b) * (a.x - c.x) + glm::dot(c, c) * (b.x - a.x)) / d);
  const double radius = glm::length(a - centre);
  for (const int k : {0, 3, 6}) {  // the first and the last interval have one frame beside them
    const Nanos mid = (truth[k].time + truth[k + 1].time) / 2;
    const Pose chord = interpolate(truth[k].T_world_camera, truth[k + 1].T_world_camera, 0.5);
    const Pose spline = *replay.true_camera_pose_at(mid);
    const double sagitta = radius - glm::length(xz(chord) - centre),
                 off = std::abs(radius - glm::length(xz(spline) - centre));
    std::printf("between frames %d and %d: the chord %.2f mm inside the orbit, the spline %.3f mm off it\n", k, k + 1,
                1e3 * sagitta, 1e3 * off);
    EXPECT_GT(sagitta, 1e-3);
    EXPECT_LT(off, 0.1 * sagitta);
  }
  EXPECT_LT(glm::length(replay.true_camera_pose_at(truth[3].time)->translation - truth[3].T_world_camera.translation),
            1e-12);
}

}  // namespace
}  // namespace lumar
