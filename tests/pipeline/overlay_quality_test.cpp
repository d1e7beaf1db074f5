// The overlay's quality knobs (OverlayQuality) reach the compositor and the volume and
// stay across a scene swap; `--quality auto` (choose_quality) keeps to its budget.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include "lumar/base/error.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/pipeline/quality_choice.h"
#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(OverlayQuality, TheKnobsReachTheCompositorAndSurviveASceneSwap) {
  pipeline::ReplayOverlaySettings full, cheap;
  cheap.overlay.quality.shading = ObjectShading::PerVertex;
  cheap.overlay.quality.shadows.lines_per_patch = 2;
  cheap.overlay.quality.exact_lights = 2;
  pipeline::ReplayOverlay a(test::source_dir() / "recordings/orbit", full),
      b(test::source_dir() / "recordings/orbit", cheap);
  ASSERT_NE(a.compositor().shadows(), nullptr);
  ASSERT_NE(b.compositor().shadows(), nullptr);
  // The same receivers and emitter patches, about a quarter of the lines (a line the
  // proxy blocks is not kept).
  const double ratio =
      double(a.compositor().shadows()->lines().lines.size()) / double(b.compositor().shadows()->lines().lines.size());
  EXPECT_NEAR(ratio, 4.0, 0.4);
  EXPECT_EQ(b.compositor().object_shading(), ObjectShading::PerVertex);
  EXPECT_GT(a.compositor().irradiance_volume()->lights.size(), 2u);  // the sample's lamps and window
  EXPECT_EQ(b.compositor().irradiance_volume()->lights.size(), 2u);
  b.overlay().set_scene(std::make_shared<const LoadedScene>(b.scene()));
  EXPECT_EQ(b.compositor().object_shading(), ObjectShading::PerVertex);
  EXPECT_EQ(b.compositor().shadow_quality().lines_per_patch, 2);
  EXPECT_EQ(b.compositor().irradiance_volume()->lights.size(), 2u);
}

TEST(OverlayQuality, ShadowMapsOfTheAskedSizeAndObjectsStayWhereTheyWere) {
  pipeline::ReplayOverlaySettings s;
  s.overlay.quality.shadow_map = 32;
  pipeline::ReplayOverlay replay(test::source_dir() / "recordings/orbit", s);
  ASSERT_NE(replay.compositor().irradiance_volume(), nullptr);
  EXPECT_EQ(replay.compositor().irradiance_volume()->shadow_n, 32);
  const glm::dmat4 moved = glm::translate(replay.compositor().object_pose(0), glm::dvec3(0.1, 0.0, 0.05));
  replay.compositor().set_object_pose(0, moved);

  pipeline::OverlayQuality q = replay.overlay().quality();
  q.shadow_map = 64, q.exact_lights = 3, q.shading = ObjectShading::PerVertex, q.coverage_mesh_px = 2.0;
  replay.overlay().set_quality(q);
  EXPECT_TRUE(replay.overlay().quality() == q);
  EXPECT_EQ(replay.compositor().renderer().coverage_mesh_error(), 2.0) << "the new compositor's renderer has it too";
  EXPECT_EQ(q.describe(), "vertex, 8 lines, 3 lights, 64 px shadow maps, 2 px coverage meshes");
  EXPECT_EQ(replay.compositor().irradiance_volume()->shadow_n, 64);
  EXPECT_EQ(replay.compositor().irradiance_volume()->lights.size(), 3u);
  EXPECT_EQ(replay.compositor().object_shading(), ObjectShading::PerVertex);
  EXPECT_TRUE(replay.compositor().object_pose(0) == moved) << "a new compositor must not put the objects back";

  pipeline::OverlayQuality bad = q;
  bad.shadow_map = 4;
  EXPECT_THROW(replay.overlay().set_quality(bad), InputError);
  bad = q, bad.exact_lights = kMaxExactLights + 1;
  EXPECT_THROW(replay.overlay().set_quality(bad), InputError);
  bad = q, bad.coverage_mesh_px = -1.0;
  EXPECT_THROW(replay.overlay().set_quality(bad), InputError);
  EXPECT_TRUE(replay.overlay().quality() == q) << "a refused quality changes nothing";
  // Back to the manifest's light count.
  q.exact_lights.reset();
  replay.overlay().set_quality(q);
  EXPECT_GT(replay.compositor().irradiance_volume()->lights.size(), 3u);
}

// The choice's decision rule, on the numbers it measured (no assertion on speed itself):
// the reference is full quality and differs from itself by nothing; every kept setting is
// within the budget and faster than the best before it; a budget nothing meets keeps
// full quality; the overlay is left at the choice with its clocks cleared.
TEST(QualityChoice, KeepsToItsBudgetAndLeavesTheOverlayAtItsChoice) {
  pipeline::ReplayOverlaySettings s;
  s.poses = pipeline::PoseSource::Tracker;
  pipeline::ReplayOverlay replay(test::source_dir() / "recordings/walk", s);
  const std::vector<pipeline::ProbeFrame> probes = replay.probe_frames(3);
  ASSERT_EQ(probes.size(), 3u);
  EXPECT_LT(probes[0].frame.index, probes[1].frame.index);
  EXPECT_GT(probes[2].frame.index, std::int64_t(replay.replay().reader().frames().size() / 2))
      << "spread over the recording";

  const pipeline::OverlayQuality full = replay.overlay().quality();
  const auto tight = pipeline::choose_quality(replay.overlay(), probes, {.percent = 1e-4, .frames = 2});
  ASSERT_GE(tight.trials.size(), 3u);
  EXPECT_EQ(tight.chosen, 0u);
  EXPECT_TRUE(tight.full().quality == full);
  EXPECT_EQ(tight.full().difference.object_err, 0.0);
  EXPECT_EQ(tight.full().difference.shadow_err, 0.0);
  // Per vertex is the first step: it changes the figurines' pixels a little.
  EXPECT_EQ(tight.trials[1].quality.shading, ObjectShading::PerVertex);
  EXPECT_GT(tight.trials[1].difference.object_err, 0.01);
  EXPECT_LT(tight.trials[1].difference.object_err, 3.0);
  EXPECT_TRUE(replay.overlay().quality() == full);

  const pipeline::QualityBudget budget{.percent = 1.5, .frames = 2};
  const auto choice = pipeline::choose_quality(replay.overlay(), probes, budget);
  EXPECT_TRUE(replay.overlay().quality() == choice.choice().quality);
  EXPECT_TRUE(choice.choice().kept);
  double best_ms = choice.full().ms_per_frame;
  for (std::size_t i = 1; i < choice.trials.size(); ++i) {
    const auto& t = choice.trials[i];
    const bool within = t.difference.object_err <= budget.percent && t.difference.edge_err <= budget.percent &&
                        t.difference.shadow_err <= budget.percent;
    EXPECT_EQ(t.kept, within && t.ms_per_frame < (1.0 - pipeline::kQualityMinGain) * best_ms) << i;
    if (t.kept) best_ms = t.ms_per_frame;
  }
  EXPECT_EQ(choice.choice().ms_per_frame, best_ms);
  EXPECT_EQ(replay.times().frames, 0);
  EXPECT_FALSE(replay.overlay().first_composite_time());
  EXPECT_THROW(pipeline::choose_quality(replay.overlay(), {probes[0]}, budget), InputError);
  for (const auto& p : probes) EXPECT_TRUE(p.shutter_cameras.empty());  // the walk has no shutter time
}

// With a shutter time the trials draw the motion blur, as the run will: each probe carries
// the camera at the shutter's instants, the frame's own pose in the middle.
TEST(QualityChoice, ProbesCarryTheCameraOverTheShutter) {
  pipeline::ReplayOverlaySettings s;
  s.poses = pipeline::PoseSource::Tracker;
  s.overlay.shutter_s = 0.04;
  pipeline::ReplayOverlay replay(test::source_dir() / "recordings/walk", s);
  const std::vector<pipeline::ProbeFrame> probes = replay.probe_frames(2);
  ASSERT_EQ(probes.size(), 2u);
  for (const auto& p : probes) {
    ASSERT_EQ(p.shutter_cameras.size(), 3u);
    ASSERT_TRUE(p.shutter_cameras[0] && p.shutter_cameras[1] && p.shutter_cameras[2]);
    EXPECT_EQ(p.shutter_cameras[1]->translation, p.T_world_camera.translation);
  }
}

}  // namespace
}  // namespace lumar
