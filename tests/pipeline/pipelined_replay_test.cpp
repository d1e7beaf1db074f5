// The pipelined replay (ReplayOverlay::run with pipelined = true): decoding, compositing
// and the sink on three threads give the frames the serial run gives, in order, and a
// stop or an error in any stage ends the run without a hang.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "lumar/base/error.h"
#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

pipeline::ReplayOverlaySettings settings(gl::CompositeFeatures features = {}) {
  pipeline::ReplayOverlaySettings s;
  s.poses = pipeline::PoseSource::Tracker;
  s.overlay.features = features;  // noise on: its seed is the frame's number, the same in both runs
  return s;
}

std::vector<cv::Mat> composites(bool pipelined, int frames, std::vector<std::int64_t>* indices = nullptr,
                                const char* recording = "recordings/orbit",
                                const pipeline::ReplayOverlaySettings& s = settings()) {
  pipeline::ReplayOverlay overlay(test::source_dir() / recording, s);
  std::vector<cv::Mat> out;
  overlay.run(
      frames,
      [&](const pipeline::OverlayFrame& f) {
        out.push_back(f.composite);
        if (indices) indices->push_back(f.index);
        return true;
      },
      pipelined);
  const pipeline::StageTimes& t = overlay.times();
  EXPECT_EQ(t.frames, frames);
  EXPECT_GT(t.decode, 0.0);
  EXPECT_GT(t.latency, t.objects);  // from the decode's start to the sink's end
  return out;
}

// The pipelined run's frames are the serial run's, bit for bit, in order; the first and the
// last differ (each frame is its own image, not a buffer the next one overwrites, and the
// recording moves).
void expect_serial_frames(int frames, const char* recording, const pipeline::ReplayOverlaySettings& s) {
  std::vector<std::int64_t> indices;
  const std::vector<cv::Mat> serial = composites(false, frames, nullptr, recording, s),
                             pipelined = composites(true, frames, &indices, recording, s);
  ASSERT_EQ(pipelined.size(), serial.size());
  for (std::size_t i = 0; i < serial.size(); ++i) {
    EXPECT_EQ(indices[i], std::int64_t(i));
    EXPECT_EQ(cv::norm(serial[i], pipelined[i], cv::NORM_INF), 0.0) << "frame " << i;
  }
  EXPECT_GT(cv::norm(pipelined.front(), pipelined.back(), cv::NORM_L1), 0.0);
}

TEST(PipelinedReplay, GivesTheSerialRunsFramesInOrder) { expect_serial_frames(10, "recordings/orbit", settings()); }

// The walk's figurines move every frame: their shadows, bounce and light per vertex are
// worked out a frame ahead on their own thread (Overlay::prepare) and must be the serial
// run's, frame by frame.
TEST(PipelinedReplay, MovingObjectsPreparedAheadGiveTheSerialFrames) {
  pipeline::ReplayOverlaySettings s = settings();
  for (const ObjectShading shading : {ObjectShading::PerVertex, ObjectShading::PerPixel}) {
    s.overlay.quality.shading = shading;
    expect_serial_frames(8, "recordings/walk", s);
  }
}

// A run stopped by its sink drops frames that were prepared ahead but never drawn
// (ReplayOverlay::run then calls Compositor::forget_prepared): their shadows and light
// must not be taken for uploaded. Frame 1 prepared and dropped, then composited: what a
// fresh overlay gives for frame 1 (without forgetting, frame 0's shadows and light stay).
TEST(PipelinedReplay, FramesPreparedAndDroppedAreNotTakenForDrawn) {
  pipeline::ReplayOverlaySettings s = settings();
  s.overlay.quality.shading = ObjectShading::PerVertex;
  pipeline::ReplayOverlay dropped(test::source_dir() / "recordings/walk", s),
      fresh(test::source_dir() / "recordings/walk", s);
  std::vector<capture::Frame> frames(2);
  auto source = fresh.replay().open_frames();
  for (capture::Frame& f : frames) {
    ASSERT_TRUE(source->read(f));
    f.image = f.image.clone();
  }
  const auto composite = [&](pipeline::ReplayOverlay& o, const capture::Frame& f) {
    return o.overlay().composite(f, o.camera_pose(f)).composite;
  };
  composite(dropped, frames[0]);
  dropped.overlay().prepare(frames[1].time);  // handed to no one
  dropped.compositor().forget_prepared();
  composite(fresh, frames[0]);
  const cv::Mat want = composite(fresh, frames[1]);
  EXPECT_EQ(cv::norm(composite(dropped, frames[1]), want, cv::NORM_INF), 0.0);
}

// Lighting adaptation changes the light on the GL thread between frames: nothing is
// prepared ahead then, and the pipelined run composites each frame whole.
TEST(PipelinedReplay, WithTheLightingAdaptedNothingIsPreparedAhead) {
  pipeline::ReplayOverlaySettings s = settings();
  s.overlay.adapt_lighting_every = 10;
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/walk", s);
  EXPECT_FALSE(overlay.overlay().can_prepare_ahead());
  EXPECT_THROW(overlay.overlay().prepare(0), RuntimeError);
  int seen = 0;
  overlay.run(
      3, [&](const pipeline::OverlayFrame&) { return ++seen > 0; }, true);
  EXPECT_EQ(seen, 3);
  EXPECT_EQ(overlay.times().frames, 3);
}

TEST(PipelinedReplay, StopsWhenTheSinkSaysSo) {
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/orbit", settings());
  int seen = 0;
  overlay.run(
      0, [&](const pipeline::OverlayFrame&) { return ++seen < 3; }, true);
  EXPECT_EQ(seen, 3);
  // Frames already composited when the sink stopped are dropped, at most the queue's depth and one in hand.
  EXPECT_LE(overlay.times().frames, 3 + pipeline::ReplayOverlay::kPipelineDepth + 1);
}

TEST(PipelinedReplay, ASinkErrorReachesTheCaller) {
  pipeline::ReplayOverlay overlay(test::source_dir() / "recordings/orbit", settings());
  int seen = 0;
  EXPECT_THROW(overlay.run(
                   0,
                   [&](const pipeline::OverlayFrame&) -> bool {
                     if (++seen == 2) throw std::runtime_error("disk full");
                     return true;
                   },
                   true),
               std::runtime_error);
  EXPECT_EQ(seen, 2);
  // The overlay is still usable: a serial run afterwards composites.
  int after = 0;
  overlay.run(2, [&](const pipeline::OverlayFrame&) { return ++after > 0; });
  EXPECT_EQ(after, 2);
}

}  // namespace
}  // namespace lumar
