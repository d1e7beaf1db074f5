// The camera's absolute pose from one frame against the room the proxy and the map
// predict (pipeline::ProxyAlignment), on the shipped orbit, started from the tracker's
// noisy pose (4.6 px mean, 12 px worst) and measured against the true one. The orbit's
// video is the map projected onto this very proxy, so the alignment is near exact here;
// image_aided_pose_test.cpp holds it to a room unlike the proxy.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "lumar/pipeline/proxy_alignment.h"
#include "lumar/pipeline/registration_error.h"
#include "lumar/pipeline/replay_overlay.h"
#include "test_paths.h"

namespace lumar {
namespace {

struct Aligned {
  pipeline::ReplayOverlay overlay{test::source_dir() / "recordings/orbit"};
  RayScene proxy;
  std::optional<pipeline::ProxyAlignment> align;
  Aligned() {
    proxy.add_static(overlay.scene().room);
    proxy.commit();
    align.emplace(overlay.replay().session().camera, proxy, overlay.overlay().room_prediction());
  }
};

TEST(ProxyAlignment, FindsTheCameraFromTheTrackersGuess) {
  Aligned a;
  const auto& replay = a.overlay.replay();
  // Where the objects' points project, as registration_error measures it.
  const CameraIntrinsics& pinhole = a.overlay.compositor().output_camera();
  const auto& points = a.overlay.compositor().object_points();
  auto frames = replay.open_frames();
  capture::Frame frame;
  double sum_tracker = 0, sum = 0, worst = 0, ms = 0, inliers = 0;
  int n = 0;
  while (frames->read(frame)) {
    const auto truth = replay.true_camera_pose(frame.index);
    const auto tracked = replay.tracked_camera_pose(frame.time);
    ASSERT_TRUE(truth && tracked);
    const auto t0 = std::chrono::steady_clock::now();
    const auto aligned = a.align->align(frame.image, *tracked);
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(aligned) << "frame " << frame.index;
    const double e = pipeline::projection_error_px(pinhole, points, aligned->T_world_camera, *truth);
    sum_tracker += pipeline::projection_error_px(pinhole, points, *tracked, *truth);
    sum += e, worst = std::max(worst, e), inliers += aligned->inliers, ++n;
    EXPECT_LT(aligned->rms_px, 0.6) << "frame " << frame.index;
  }
  std::printf("%d frames: tracker %.2f px mean; aligned %.3f px mean, %.3f worst; %.0f inliers, %.0f ms a frame\n", n,
              sum_tracker / n, sum / n, worst, inliers / n, ms / n);
  EXPECT_EQ(n, 48);
  EXPECT_LT(sum / n, 0.15);
  EXPECT_LT(worst, 0.4);
}

// A frame that shows nothing of the room (a flat grey) gives no pose, and neither does a
// guess so far off that nothing is where it predicts.
TEST(ProxyAlignment, GivesNothingWhereTheFrameDoesNotShowThePredictedRoom) {
  Aligned a;
  const auto& replay = a.overlay.replay();
  auto frames = replay.open_frames();
  capture::Frame frame;
  ASSERT_TRUE(frames->read(frame));
  const Pose truth = *replay.true_camera_pose(frame.index);
  const cv::Mat grey(frame.image.size(), frame.image.type(), cv::Scalar(128, 128, 128));
  EXPECT_FALSE(a.align->align(grey, truth));
  const Pose turned{axis_angle_deg({0, 1, 0}, 60.0) * truth.rotation, truth.translation};
  const auto far_off = a.align->align(frame.image, turned);
  EXPECT_FALSE(far_off) << "a 60-degree-off guess, which a 24 px search cannot correct, gave a pose "
                        << (far_off ? rotation_angle_deg(far_off->T_world_camera.rotation, truth.rotation) : 0.0)
                        << " degrees from the truth";
  ASSERT_TRUE(a.align->align(frame.image, truth));  // the same frame, with a good guess
}

}  // namespace
}  // namespace lumar
