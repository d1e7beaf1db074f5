// Image-aided tracking on the shipped synthetic recordings, against their true poses.
// The registration error is measured as `lumar regress` measures it: where the objects'
// points project with a pose against with the true one (pipeline::projection_error_px).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/image_aided_pose.h"
#include "lumar/pipeline/registration_error.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

struct Errors {
  std::vector<double> px;  // per frame
  double mean() const {
    double s = 0;
    for (double e : px) s += e;
    return px.empty() ? 0 : s / px.size();
  }
  double worst() const { return px.empty() ? 0 : *std::max_element(px.begin(), px.end()); }
  double p95() const {
    std::vector<double> s = px;
    std::sort(s.begin(), s.end());
    return s.empty() ? 0 : s[std::size_t(std::ceil(0.95 * s.size())) - 1];
  }
};

// Every frame of `name` through ImageAidedPose with `tracker(frame)` as the tracker's pose.
Errors run(const std::string& name, const std::function<std::optional<Pose>(const capture::Frame&)>& tracker,
           const pipeline::ImageAidedSettings& settings = {}, pipeline::ImageAidedPose::Stats* stats = nullptr) {
  const capture::RecordingReplay replay(test::source_dir() / "recordings" / name);
  const LoadedScene scene = load_scene_files(replay.scene_path());
  pipeline::ImageAidedPose fused(replay.session().camera, scene.room, settings);
  const CameraIntrinsics pinhole = replay.session().camera.without_distortion();
  auto frames = replay.open_frames();
  capture::Frame frame;
  Errors out;
  while (frames->read(frame)) {
    const auto pose = fused.update(frame, tracker(frame));
    const auto truth = replay.true_camera_pose(frame.index);
    std::vector<glm::dvec3> points;
    for (const auto& o : scene.objects) {
      const glm::dmat4 T = o.pose_at(nanos_to_seconds(frame.time));
      for (std::size_t i = 0; i < o.model.positions.size(); i += 97)
        points.emplace_back(T * glm::dvec4(glm::dvec3(o.model.positions[i]), 1.0));
    }
    if (pose && truth) out.px.push_back(pipeline::projection_error_px(pinhole, points, *pose, *truth));
  }
  if (stats) *stats = fused.stats();
  return out;
}

// The video alone: the true pose for the first frame, no tracker after it. What is left is
// the drift of the chain of frame-to-frame poses from the corners on the proxy.
TEST(ImageAidedPose, TheVideoAloneFollowsTheCameraFromItsFirstPose) {
  for (const char* name : {"orbit", "walk"}) {
    const capture::RecordingReplay replay(test::source_dir() / "recordings" / name);
    pipeline::ImageAidedPose::Stats stats;
    const Errors video = run(
        name,
        [&](const capture::Frame& f) { return f.index == 0 ? replay.true_camera_pose(0) : std::optional<Pose>(); }, {},
        &stats);
    std::printf(
        "%s, the video alone from the true first pose: mean %.2f px, last frame %.2f px; %d of %d frames, %.0f "
        "inliers\n",
        name, video.mean(), video.px.back(), stats.visual_frames, stats.frames, stats.inliers);
    EXPECT_EQ(stats.visual_frames, stats.frames - 1);
    EXPECT_LT(video.mean(), 1.0) << name;
  }
}

// The tracker's poses steadied by the video, against the tracker's alone.
TEST(ImageAidedPose, SteadiesTheTrackersPosesOnTheSampleRecordings) {
  for (const char* name : {"orbit", "walk"}) {
    const capture::RecordingReplay replay(test::source_dir() / "recordings" / name);
    const auto tracker = [&](const capture::Frame& f) { return replay.tracked_camera_pose(f.time); };
    const Errors alone = run(name, [&](const capture::Frame& f) { return replay.tracked_camera_pose(f.time); },
                             {.fusion = {.tracker_gain = 1.0}});
    const Errors fused = run(name, tracker);
    // Settled: the last second. The first frames can be no better than the mean of the
    // tracker's samples so far (sigma / sqrt(n)), since nothing else is absolute.
    double settled = 0;
    for (std::size_t i = fused.px.size() - 24; i < fused.px.size(); ++i) settled += fused.px[i] / 24;
    std::printf("%s: tracker alone mean %.2f px, p95 %.2f px; fused mean %.2f px, p95 %.2f px, last second %.2f px\n",
                name, alone.mean(), alone.p95(), fused.mean(), fused.p95(), settled);
    EXPECT_LT(fused.mean(), 1.1) << name;
    EXPECT_LT(fused.mean(), 0.3 * alone.mean()) << name;
    EXPECT_LT(settled, 0.5) << name;
    EXPECT_LE(fused.px[0], alone.px[0] + 1e-9) << "the first frame is the tracker's";
  }
}

}  // namespace
}  // namespace lumar
