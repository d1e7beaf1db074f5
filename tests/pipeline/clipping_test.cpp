// The overlay measures how much of the objects clips to white (Overlay::objects_clipped):
// nothing on the sample at its exposure, nearly all of the figurine at 40 times it (every
// channel of a diffuse object of albedo 0.45 lit as in the sample room saturates), and
// the measure follows a change of exposure on the next frame.
#include <gtest/gtest.h>

#include <cstdio>

#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

double clipped_after_one_frame(pipeline::ReplayOverlay& overlay) {
  overlay.run(1, [](const pipeline::OverlayFrame&) { return true; });
  EXPECT_TRUE(overlay.overlay().objects_clipped().has_value());
  return overlay.overlay().objects_clipped().value_or(-1);
}

TEST(OverlayClipping, MeasuresTheShareOfTheObjectsThatClipsToWhite) {
  pipeline::ReplayOverlaySettings settings;
  settings.poses = pipeline::PoseSource::Truth;
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/orbit", settings);
  EXPECT_FALSE(overlay.overlay().objects_clipped().has_value()) << "nothing measured before a frame";
  const double normal = clipped_after_one_frame(overlay);
  overlay.overlay().set_exposure_scale(40.0);
  const double bright = clipped_after_one_frame(overlay);
  overlay.overlay().set_exposure_scale(1.0);
  const double again = clipped_after_one_frame(overlay);
  std::printf("objects clipped: %.4f at the sample's exposure, %.4f at 40x, %.4f back at 1x\n", normal, bright, again);
  EXPECT_LT(normal, 0.01);
  EXPECT_GT(bright, 0.8);
  EXPECT_GT(bright, pipeline::Overlay::kClipWarnShare);
  EXPECT_DOUBLE_EQ(again, normal);
}

}  // namespace
}  // namespace lumar
