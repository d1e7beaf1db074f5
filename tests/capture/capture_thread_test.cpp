// The capture thread and its queue policies, on real footage (tree.avi) and on the
// scripted camera. No timing assertions: each test waits for a state, not a duration.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "lumar/capture/capture_thread.h"
#include "lumar/capture/image_sequence_source.h"
#include "lumar/capture/v4l2_source.h"
#include "lumar/capture/video_file_source.h"
#include "recording_test_support.h"
#include "scripted_v4l2_device.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

fs::path tree() { return test::shared_dir() / "data" / "video" / "tree.avi"; }

// Every frame of tree.avi read directly: the reference for what the thread delivers.
std::vector<Frame> tree_frames() {
  VideoFileSource s(tree());
  std::vector<Frame> out;
  Frame f;
  while (s.read(f)) out.push_back(f);
  return out;
}

// Waits (up to a generous deadline, so a broken build fails instead of hanging) until
// `ready` holds.
template <class F>
bool eventually(F&& ready) {
  const Nanos deadline = monotonic_now() + 20 * kNanosPerSecond;
  while (!ready()) {
    if (monotonic_now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

TEST(CaptureThread, RecordingPolicyDeliversEveryFrameAndReportsBackPressure) {
  const auto reference = tree_frames();
  ASSERT_EQ(reference.size(), 68u);
  FrameQueue queue(2, QueuePolicy::KeepAll);
  CaptureThread thread(std::make_unique<VideoFileSource>(tree()), queue);
  // Nobody pops yet: the thread fills the queue and must then wait, not drop.
  ASSERT_TRUE(eventually([&] { return queue.stats().back_pressure == 1; }));
  EXPECT_EQ(queue.size(), 2u);
  std::vector<Frame> got;
  Frame f;
  while (queue.pop(f, kNanosPerSecond)) got.push_back(f);
  EXPECT_TRUE(queue.closed());
  thread.join();
  EXPECT_EQ(thread.end(), CaptureEnd::EndOfStream);
  EXPECT_EQ(thread.message(), "");
  ASSERT_EQ(got.size(), reference.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, reference[i].index);
    EXPECT_EQ(got[i].time, reference[i].time);
    if (i % 10 == 0) {
      EXPECT_EQ(cv::norm(got[i].image, reference[i].image, cv::NORM_INF), 0.0);
    }
  }
  const QueueStats st = queue.stats();
  EXPECT_EQ(st.pushed, 68u);
  EXPECT_EQ(st.popped, 68u);
  EXPECT_EQ(st.stale_dropped, 0u);
  EXPECT_GE(st.back_pressure, 1u);
  EXPECT_EQ(st.high_water, 2u);
}

TEST(CaptureThread, LivePolicyKeepsTheNewestFrameAndCountsStaleOnes) {
  const auto reference = tree_frames();
  FrameQueue queue(1, QueuePolicy::KeepNewest);
  CaptureThread thread(std::make_unique<VideoFileSource>(tree()), queue);
  thread.join();  // a consumer that never kept up at all
  EXPECT_EQ(thread.end(), CaptureEnd::EndOfStream);
  Frame f;
  ASSERT_TRUE(queue.pop(f, 0));
  EXPECT_EQ(f.index, reference.back().index);
  EXPECT_EQ(cv::norm(f.image, reference.back().image, cv::NORM_INF), 0.0);
  EXPECT_FALSE(queue.pop(f, 0));
  const QueueStats st = queue.stats();
  EXPECT_EQ(st.pushed, 68u);
  EXPECT_EQ(st.stale_dropped, 67u);
  EXPECT_EQ(st.back_pressure, 0u);
}

TEST(CaptureThread, StopEndsAThreadBlockedOnAFullQueue) {
  FrameQueue queue(1, QueuePolicy::KeepAll);
  CaptureThread thread(std::make_unique<VideoFileSource>(tree()), queue);
  ASSERT_TRUE(eventually([&] { return queue.stats().back_pressure == 1; }));
  thread.stop();
  EXPECT_EQ(thread.end(), CaptureEnd::Stopped);
  EXPECT_EQ(thread.frames_read(), 2u);  // one queued, one refused when the queue closed
  Frame f;
  EXPECT_TRUE(queue.pop(f, 0));  // what was queued can still be taken
  EXPECT_FALSE(queue.pop(f, 0));
}

TEST(CaptureThread, ASourceErrorEndsTheThreadWithItsMessage) {
  const auto dir = test::scratch_dir("capture_thread_error");
  test::RemoveOnSuccess cleanup{dir};
  for (int i = 0; i < 3; ++i)
    cv::imwrite((dir / ("f" + std::to_string(i) + ".png")).string(), test::numbered_image(i, {32, 24}));
  std::ofstream(dir / "f3.png") << "torn";
  FrameQueue queue(8, QueuePolicy::KeepAll);
  CaptureThread thread(std::make_unique<ImageSequenceSource>(ImageSequenceSettings{dir.string(), {}, 10}), queue);
  Frame f;
  int n = 0;
  while (queue.pop(f, kNanosPerSecond)) ++n;
  thread.join();
  EXPECT_EQ(n, 3);
  EXPECT_EQ(thread.end(), CaptureEnd::Failed);
  EXPECT_TRUE(thread.input_error());
  EXPECT_THAT(thread.message(), HasSubstr("f3.png: cannot decode"));
}

TEST(CaptureThread, AnUnpluggedCameraEndsTheThreadCleanly) {
  test::ScriptedCamera cam;
  for (std::uint32_t k = 0; k < 5; ++k) {
    test::ScriptStep s;
    s.sequence = k;
    s.timestamp = 1'000'000'000 + Nanos(k) * 33'000'000;
    s.payload.assign(std::size_t(cam.width) * cam.height * 2, 128);
    cam.steps.push_back(s);
  }
  test::ScriptStep unplug;
  unplug.kind = test::ScriptStep::UnplugDqbuf;
  cam.steps.push_back(unplug);
  FrameQueue queue(16, QueuePolicy::KeepAll);
  CaptureThread thread(std::make_unique<V4l2Source>(V4l2Settings{}, std::make_unique<test::ScriptedV4l2Device>(cam)),
                       queue);
  Frame f;
  int n = 0;
  while (queue.pop(f, kNanosPerSecond)) ++n;
  thread.join();
  EXPECT_EQ(n, 5);
  EXPECT_EQ(thread.end(), CaptureEnd::Vanished);
  EXPECT_FALSE(thread.input_error());
  EXPECT_THAT(thread.message(), HasSubstr("/dev/video0: the camera disappeared (unplugged?) after 5 frames"));
}

TEST(RealTimeSource, PlaysAFileOnTheMonotonicClockAtItsOwnSpacing) {
  const auto reference = tree_frames();
  const double speed = 50;  // 10 frames of tree.avi in ~40 ms
  RealTimeSource source(std::make_unique<VideoFileSource>(tree()), speed);
  Frame f;
  Nanos first = 0;
  for (std::size_t i = 0; i < 10; ++i) {
    const Nanos before = monotonic_now();
    ASSERT_TRUE(source.read(f));
    if (i == 0) first = f.time;
    EXPECT_GE(f.time, i == 0 ? before : first);
    EXPECT_LE(f.time, monotonic_now());  // never handed out before its time
    EXPECT_EQ(f.time - first, std::llround(double(reference[i].time - reference[0].time) / speed));
    EXPECT_EQ(f.index, reference[i].index);
  }
  EXPECT_NEAR(source.nominal_fps(), 15.0 * speed, 0.01 * speed);
}

TEST(FrameQueue, RejectsZeroCapacityAndPushesAfterClose) {
  EXPECT_THROW(FrameQueue(0, QueuePolicy::KeepAll), InputError);
  FrameQueue q(2, QueuePolicy::KeepNewest);
  q.close();
  EXPECT_FALSE(q.push(Frame{}));
  Frame f;
  EXPECT_FALSE(q.pop(f, 1'000'000));
}

}  // namespace
}  // namespace lumar::capture
