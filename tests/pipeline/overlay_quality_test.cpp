// The overlay's quality knobs reach the compositor (OverlaySettings::shading and
// ::shadow_quality) and stay across a scene swap.
#include <gtest/gtest.h>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(OverlayQuality, TheKnobsReachTheCompositorAndSurviveASceneSwap) {
  pipeline::ReplayOverlaySettings full, cheap;
  cheap.overlay.shading = ObjectShading::PerVertex;
  cheap.overlay.shadow_quality.lines_per_patch = 2;
  cheap.overlay.exact_lights = 2;
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

}  // namespace
}  // namespace lumar
