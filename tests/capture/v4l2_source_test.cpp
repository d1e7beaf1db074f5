// The real V4L2 capture code against a scripted camera: negotiation, streaming,
// sequence gaps, timeouts, EAGAIN, corrupt buffers and unplugging.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "lumar/capture/v4l2_source.h"
#include "recording_test_support.h"
#include "scripted_v4l2_device.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
using test::ScriptedCamera;
using test::ScriptedV4l2Device;
using test::ScriptStep;
using testing::HasSubstr;

constexpr Nanos kStart = 5'000'000'000;  // kernel times of the scripted frames start here
constexpr Nanos kPeriod = 33'333'000;

// YUYV bytes of a frame whose 2x1 pixel pairs carry (Y0, U, Y1, V) from the index,
// so the decoded colour can be checked against BT.601 by hand.
std::vector<std::uint8_t> yuyv_payload(int w, int h, int frame) {
  std::vector<std::uint8_t> p(std::size_t(w) * h * 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; x += 2) {
      std::uint8_t* q = &p[(std::size_t(y) * w + x) * 2];
      q[0] = std::uint8_t(40 + (x * 3 + frame * 7) % 180);
      q[1] = std::uint8_t(90 + (y * 5) % 80);
      q[2] = std::uint8_t(40 + (x * 3 + 1 + frame * 7) % 180);
      q[3] = std::uint8_t(100 + (frame * 11) % 60);
    }
  return p;
}

// BT.601 limited range, the conversion OpenCV applies to YUYV.
cv::Vec3b bt601_bgr(int Y, int U, int V) {
  const double c = 1.164 * (Y - 16), d = U - 128, e = V - 128;
  auto sat = [](double v) { return std::uint8_t(std::clamp(std::lround(v), 0L, 255L)); };
  return {sat(c + 2.018 * d), sat(c - 0.391 * d - 0.813 * e), sat(c + 1.596 * e)};
}

ScriptStep frame_step(std::uint32_t seq, std::vector<std::uint8_t> payload, Nanos t = -1) {
  ScriptStep s;
  s.kind = ScriptStep::Frame;
  s.sequence = seq;
  s.timestamp = t >= 0 ? t : kStart + Nanos(seq) * kPeriod;
  s.payload = std::move(payload);
  return s;
}

ScriptStep step(ScriptStep::Kind kind) {
  ScriptStep s;
  s.kind = kind;
  return s;
}

struct Opened {
  ScriptedV4l2Device* device;
  std::shared_ptr<const ScriptedV4l2Device::Log> log;
  std::unique_ptr<V4l2Source> source;
};

Opened open_scripted(ScriptedCamera cam, V4l2Settings settings = {}) {
  auto dev = std::make_unique<ScriptedV4l2Device>(std::move(cam));
  Opened r{dev.get(), dev->log(), nullptr};
  r.source = std::make_unique<V4l2Source>(settings, std::move(dev));
  return r;
}

TEST(V4l2Source, NegotiatesThePreferredFormatBuffersAndControls) {
  ScriptedCamera cam;
  cam.formats = {{"MJPG", false}, {"YUYV", false}};
  V4l2Settings s;
  s.fps = 25;
  s.exposure_100us = 50;
  s.gain = 7;
  auto r = open_scripted(cam, s);
  const V4l2Format& f = r.source->format();
  EXPECT_EQ(f.fourcc, "YUYV");  // first in our preference, not the device's order
  EXPECT_EQ(f.width, 64);       // the camera's only size, not the 640x480 asked for
  EXPECT_EQ(f.height, 48);
  EXPECT_EQ(r.source->frame_size(), cv::Size(64, 48));
  EXPECT_NEAR(r.source->nominal_fps(), 25.0, 1e-9);
  EXPECT_EQ(f.buffers, 4);
  EXPECT_EQ(r.log->buffers_requested, 4u);
  EXPECT_EQ(r.log->maps, 4);
  EXPECT_TRUE(r.log->streamed_on);
  EXPECT_THAT(f.offered, testing::ElementsAre("MJPG", "YUYV"));
  EXPECT_EQ(r.log->controls.at(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_MANUAL);  // auto exposure locked
  EXPECT_EQ(r.log->controls.at(V4L2_CID_EXPOSURE_ABSOLUTE), 50);
  EXPECT_EQ(r.log->controls.at(V4L2_CID_GAIN), 7);

  // Asking for MJPEG only gets MJPEG.
  s.formats = {"MJPG"};
  auto m = open_scripted(cam, s);
  EXPECT_EQ(m.source->format().fourcc, "MJPG");
  EXPECT_EQ(m.log->chosen_format, ScriptedV4l2Device::code("MJPG"));
}

TEST(V4l2Source, PrefersNativeFormatsToLibv4l2Emulation) {
  ScriptedCamera cam;
  cam.formats = {{"BGR3", true}, {"H264", false}, {"RGB3", false}};
  cam.has_exposure_controls = false;  // a camera without controls still streams
  auto r = open_scripted(cam);
  EXPECT_EQ(r.source->format().fourcc, "RGB3");
  EXPECT_FALSE(r.source->format().emulated);
  EXPECT_TRUE(r.source->format().controls_set.empty());
  EXPECT_EQ(r.source->shutter_time(), 0);  // its exposure time is not known: no motion blur

  cam.formats = {{"BGR3", true}, {"H264", false}};
  auto e = open_scripted(cam);
  EXPECT_EQ(e.source->format().fourcc, "BGR3");
  EXPECT_TRUE(e.source->format().emulated);
}

TEST(V4l2Source, RefusesUnusableDevicesWithOneLine) {
  ScriptedCamera cam;
  cam.formats = {{"H264", false}, {"NV12", false}};
  std::string msg = test::input_error_message([&] { open_scripted(cam); });
  EXPECT_THAT(msg, HasSubstr("/dev/video0"));
  EXPECT_THAT(msg, HasSubstr("offers: H264 NV12"));

  V4l2Settings s;
  s.path = "/dev/video7";
  msg = test::input_error_message([&] { open_scripted(ScriptedCamera{}, s); });
  EXPECT_THAT(msg, HasSubstr("/dev/video7: no such camera"));

  ScriptedCamera meta;
  meta.device_caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  msg = test::input_error_message([&] { open_scripted(meta); });
  EXPECT_THAT(msg, HasSubstr("not a video capture node"));

  ScriptedCamera stingy;
  stingy.max_buffers = 2;
  auto dev = std::make_unique<ScriptedV4l2Device>(stingy);
  auto log = dev->log();
  try {
    V4l2Source source(V4l2Settings{}, std::move(dev));
    ADD_FAILURE() << "2 buffers were accepted";
  } catch (const RuntimeError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("only 2 capture buffers"));
  }
  EXPECT_EQ(log->unmaps, log->maps);  // a failed open leaks nothing
  EXPECT_EQ(log->closes, log->opens);
}

TEST(V4l2Source, StreamsYuyvFramesWithMidExposureKernelTimes) {
  ScriptedCamera cam;
  for (std::uint32_t k = 0; k < 6; ++k) cam.steps.push_back(frame_step(100 + k, yuyv_payload(64, 48, int(k))));
  auto r = open_scripted(cam);
  Frame f;
  for (int k = 0; k < 6; ++k) {
    ASSERT_TRUE(r.source->read(f));
    EXPECT_EQ(f.index, k);
    // UVC-style end-of-frame stamps, exposure 10 ms: the middle is 5 ms earlier.
    EXPECT_EQ(f.time, kStart + (100 + k) * kPeriod - 5'000'000);
    ASSERT_EQ(f.image.type(), CV_8UC3);
    ASSERT_EQ(f.image.size(), cv::Size(64, 48));
    const auto p = yuyv_payload(64, 48, k);
    int worst = 0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        const std::uint8_t* q = &p[(std::size_t(y) * 64 + (x & ~1)) * 2];
        const cv::Vec3b want = bt601_bgr(q[(x & 1) ? 2 : 0], q[1], q[3]);
        const cv::Vec3b got = f.image.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(got[c]) - int(want[c])));
      }
    EXPECT_LE(worst, 2) << "frame " << k;  // OpenCV's fixed-point BT.601 vs the formula
    EXPECT_EQ(f.chroma, (ChromaSampling{2, 1})) << "YUYV: one chroma sample per two pixels of a row";
  }
  const V4l2Stats& st = r.source->stats();
  EXPECT_EQ(st.frames, 6u);
  EXPECT_EQ(st.dropped, 0u);
  EXPECT_EQ(st.dequeue_stamped, 0u);
}

TEST(V4l2Source, DecodesMjpegFrames) {
  ScriptedCamera cam;
  cam.formats = {{"MJPG", false}};
  std::vector<cv::Mat> originals, decoded;
  for (int k = 0; k < 3; ++k) {
    originals.push_back(test::numbered_image(k, {64, 48}));
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", originals.back(), jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
    decoded.push_back(cv::imdecode(jpeg, cv::IMREAD_COLOR));
    cam.steps.push_back(frame_step(std::uint32_t(k), jpeg));
  }
  ScriptStep bad = frame_step(3, {0xFF, 0xD8, 0x00, 0x01});  // a torn JPEG: skipped, counted
  cam.steps.push_back(bad);
  auto r = open_scripted(cam);
  Frame f;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(r.source->read(f));
    // Exactly the JPEG's pixels (only bytesused bytes of the buffer were decoded), and
    // close to the picture that was encoded, unlike the other frames.
    EXPECT_EQ(cv::norm(f.image, decoded[std::size_t(k)], cv::NORM_INF), 0.0);
    EXPECT_EQ(f.chroma, (ChromaSampling{2, 2})) << "the JPEG's own header: libjpeg's 4:2:0";
    EXPECT_LT(test::mean_abs_diff(f.image, originals[std::size_t(k)]), 5.0);
    for (int other = 0; other < 3; ++other)
      if (other != k) {
        EXPECT_GT(test::mean_abs_diff(f.image, originals[std::size_t(other)]), 10.0);
      }
  }
  EXPECT_THROW(r.source->read(f), RuntimeError);  // then the script ends: a stall, not a hang
  EXPECT_EQ(r.source->stats().corrupt, 1u);
}

TEST(V4l2Source, CountsSequenceGapsAsDroppedFrames) {
  ScriptedCamera cam;
  for (std::uint32_t seq : {5u, 6u, 7u, 10u, 11u, 15u}) cam.steps.push_back(frame_step(seq, yuyv_payload(64, 48, 0)));
  ScriptStep broken = frame_step(16, yuyv_payload(64, 48, 0));
  broken.error_flag = true;  // the driver says the buffer is damaged
  cam.steps.push_back(broken);
  cam.steps.push_back(frame_step(17, yuyv_payload(64, 48, 0)));
  auto r = open_scripted(cam);
  std::vector<std::int64_t> indices;
  Frame f;
  for (int k = 0; k < 7; ++k) {
    ASSERT_TRUE(r.source->read(f));
    indices.push_back(f.index);
  }
  EXPECT_THAT(indices, testing::ElementsAre(0, 1, 2, 5, 6, 10, 12));
  EXPECT_EQ(r.source->stats().dropped, 2u + 3u);  // 8, 9 and 12, 13, 14
  EXPECT_EQ(r.source->stats().corrupt, 1u);       // 16: delivered by the camera, unusable
  EXPECT_EQ(r.source->stats().frames, 7u);
}

TEST(V4l2Source, WaitsOutSlowFramesAndEagainButNotAStall) {
  ScriptedCamera cam;
  cam.steps.push_back(step(ScriptStep::Timeout));
  cam.steps.push_back(step(ScriptStep::Timeout));
  cam.steps.push_back(step(ScriptStep::Eagain));
  cam.steps.push_back(frame_step(0, yuyv_payload(64, 48, 0)));
  V4l2Settings s;
  s.poll_timeout = 100'000'000;
  s.frame_timeout = 1'000'000'000;
  auto r = open_scripted(cam, s);
  Frame f;
  ASSERT_TRUE(r.source->read(f));
  EXPECT_EQ(r.source->stats().poll_timeouts, 2u);
  EXPECT_EQ(r.source->stats().eagain, 1u);

  // Nothing more comes: read gives up after frame_timeout / poll_timeout = 10 polls.
  const int polls_before = r.log->polls;
  try {
    r.source->read(f);
    ADD_FAILURE() << "a stalled camera returned a frame";
  } catch (const CameraVanished&) {
    ADD_FAILURE() << "a stall is not an unplug";
  } catch (const RuntimeError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("/dev/video0: no frame for 1.0"));
  }
  EXPECT_EQ(r.log->polls - polls_before, 10);
  EXPECT_EQ(r.source->stats().poll_timeouts, 12u);
}

TEST(V4l2Source, StampsAtDequeueWithoutMonotonicTimestamps) {
  ScriptedCamera cam;
  cam.timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
  for (std::uint32_t k = 0; k < 3; ++k) cam.steps.push_back(frame_step(k, yuyv_payload(64, 48, 0), 17));
  auto r = open_scripted(cam);
  Frame f;
  Nanos previous = 0;
  for (int k = 0; k < 3; ++k) {
    const Nanos before = monotonic_now();
    ASSERT_TRUE(r.source->read(f));
    EXPECT_GE(f.time, before);  // not the meaningless 17 ns the buffer carries
    EXPECT_LE(f.time, monotonic_now());
    EXPECT_GT(f.time, previous);
    previous = f.time;
  }
  EXPECT_EQ(r.source->stats().dequeue_stamped, 3u);
}

TEST(V4l2Source, StartOfExposureStampsMoveForward) {
  ScriptedCamera cam;
  cam.timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
  cam.steps.push_back(frame_step(0, yuyv_payload(64, 48, 0), kStart));
  V4l2Settings s;
  s.exposure_100us = 200;  // 20 ms
  auto r = open_scripted(cam, s);
  EXPECT_EQ(r.source->shutter_time(), 20'000'000);  // what the overlay's motion blur spans
  Frame f;
  ASSERT_TRUE(r.source->read(f));
  EXPECT_EQ(f.time, kStart + 10'000'000);
}

void expect_clean_unplug(ScriptStep::Kind how) {
  ScriptedCamera cam;
  for (std::uint32_t k = 0; k < 3; ++k) cam.steps.push_back(frame_step(k, yuyv_payload(64, 48, 0)));
  cam.steps.push_back(step(how));
  auto r = open_scripted(cam);
  Frame f;
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(r.source->read(f));
  try {
    r.source->read(f);
    ADD_FAILURE() << "an unplugged camera returned a frame";
  } catch (const CameraVanished& e) {
    EXPECT_EQ(std::string(e.what()),
              "/dev/video0: the camera disappeared (unplugged?) after 3 frames; plug it back in and start again");
  }
  EXPECT_THROW(r.source->read(f), CameraVanished);  // and stays gone, at once
  const auto log = r.log;
  r.source.reset();
  EXPECT_EQ(log->unmaps, 4);
  EXPECT_EQ(log->closes, 1);
}

TEST(V4l2Source, UnplugSeenByPollEndsCleanly) { expect_clean_unplug(ScriptStep::UnplugPoll); }
TEST(V4l2Source, UnplugSeenByDqbufEndsCleanly) { expect_clean_unplug(ScriptStep::UnplugDqbuf); }

TEST(V4l2Devices, ListsVideoNodesInNumericOrderWithTheirCapabilities) {
  const auto dir = test::scratch_dir("v4l2_enumeration");
  test::RemoveOnSuccess cleanup{dir};
  for (const char* name : {"video10", "video2", "video0", "videox", "vbi0"}) std::ofstream(dir / name).put('x');
  ScriptedCamera cam;
  cam.paths = {(dir / "video0").string(), (dir / "video2").string()};
  cam.unopenable = {(dir / "video10").string()};
  ScriptedV4l2Device device(cam);
  const auto list = list_v4l2_devices(device, dir);
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0].path, (dir / "video0").string());
  EXPECT_EQ(list[1].path, (dir / "video2").string());
  EXPECT_EQ(list[2].path, (dir / "video10").string());
  EXPECT_EQ(list[0].card, "Scripted camera");
  EXPECT_EQ(list[0].driver, "scripted");
  EXPECT_TRUE(list[0].video_capture);
  EXPECT_TRUE(list[0].streaming);
  EXPECT_THAT(list[2].problem, HasSubstr("Permission denied"));
  EXPECT_EQ(device.log()->closes, device.log()->opens);
}

}  // namespace
}  // namespace lumar::capture
