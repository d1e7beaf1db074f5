// The overlay follows the room's light as it changes (issue: "lighting follows the
// room"): two synthetic recordings, a lamp on the ceiling going out and the window's light
// turning warmer, replayed with --adapt-lighting. The objects' irradiance is measured on
// the figurine's vertices from the compositor's volume, every frame, against the volume
// built from the changed map (the truth) and the one built from the captured map (what
// the objects would keep without adapting).
#include <gtest/gtest.h>

#include <cstdio>

#include "lumar/calib/camera_file.h"
#include "lumar/pipeline/lighting_followed.h"
#include "lumar/sim/light_change.h"
#include "lumar/sim/synthetic_recording.h"
#include "test_paths.h"

namespace lumar {
namespace {

constexpr gl::CompositeFeatures kNoFeatures{false, false, false, false, false};

std::filesystem::path scene_file() { return test::source_dir() / "data/scenes/room/scene.json"; }

// The sample room's two light changes (sim::sample_room_light_changes), recorded once.
sim::SynthSettings recorded(std::size_t which, const std::filesystem::path& dir) {
  const sim::SynthSettings s = sim::sample_room_light_changes(
      scene_file(), calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics,
      dir)[which];
  sim::synthesize_recording(s);
  return s;
}

pipeline::LightingFollowed follow(const sim::SynthSettings& recording) {
  const sim::LightChange& change = *recording.light_change;
  pipeline::ReplayOverlaySettings rs;
  rs.poses = pipeline::PoseSource::Truth;
  rs.overlay.features = kNoFeatures;
  rs.overlay.adapt_lighting_every = 2;
  rs.overlay.volume_cache = false;
  const LoadedScene scene = load_scene_files(scene_file());
  const auto f =
      pipeline::follow_lighting_change(recording.out, sim::changed_environment_map(scene, change), change.at_s, rs);
  std::printf(
      "without adapting %.1f %%; adapted: %.1f %% before the change (against the captured map), %.1f %% at the end, "
      "within 5 %% from %.2f s after the change; largest step in brightness %.2f %%; %d re-bakes, the longest "
      "frame's fade step %.1f ms, adaptation %.1f ms per frame\n",
      100 * f.baseline_err, 100 * f.before_err, 100 * f.end_err, f.settled_after_s, 100 * f.worst_step, f.bakes,
      f.worst_fade_step_ms, f.adaptation_ms_per_frame);
  std::printf("the shadow on the floor against the changed map's: %.1f %% relit, %.1f %% as captured\n",
              100 * f.shadow_err, 100 * f.shadow_baseline_err);
  return f;
}

void expect_followed(const pipeline::LightingFollowed& f) {
  EXPECT_GT(f.baseline_err, 0.06) << "the change should matter to the object more than the tolerance";
  EXPECT_LT(f.end_err, 0.05);
  EXPECT_GE(f.settled_after_s, 0.0) << "never within 5 % of the changed map's lighting";
  EXPECT_LE(f.settled_after_s, 3.0);
  EXPECT_LE(f.worst_step, 0.02) << "the object's brightness popped";
  EXPECT_LT(f.before_err, 0.05) << "adapting changed the lighting of a room that had not changed";
  EXPECT_LT(f.shadow_err, 0.6 * f.shadow_baseline_err) << "the shadow should follow the light";
}

TEST(LightingChange, ALampGoingOutIsFollowedWithinThreeSecondsWithoutAPop) {
  const test::Scratch scratch("lighting-change-lamp");
  expect_followed(follow(recorded(0, scratch.dir)));
}

TEST(LightingChange, AWindowTurningWarmerIsFollowedPerColour) {
  const test::Scratch scratch("lighting-change-window");
  expect_followed(follow(recorded(1, scratch.dir)));
}

}  // namespace
}  // namespace lumar
