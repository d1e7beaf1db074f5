// A recording written and read back gives the same frames, times, bytes and poses.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "lumar/capture/recording_reader.h"
#include "lumar/capture/recording_writer.h"
#include "recording_test_support.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;
using test::numbered_image;

constexpr int kFrames = 75;
constexpr int kChunks = 50;
constexpr int kPoses = 40;
const cv::Size kSize(320, 240);

// Frame numbers at the source, with a dropped frame after 40.
std::int64_t source_index(int i) { return i + (i > 40 ? 1 : 0); }
Nanos frame_time(int i) { return source_index(i) * test::kFramePeriod + 17; }

class RecordingRoundTrip : public testing::TestWithParam<std::string> {};

TEST_P(RecordingRoundTrip, ReadsBackWhatWasWritten) {
  const std::string codec = GetParam();
  const fs::path dir = test::scratch_dir("round-trip-" + codec) / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const nlohmann::json caller = {{"camera", {{"fx", 512.12345678901234}, {"k1", -0.25}}}, {"tracker", "fastrak"}};
  RecordingSettings settings;
  settings.codec = codec;
  settings.size = kSize;
  settings.fps = 30;
  {
    RecordingWriter writer(dir, caller, settings);
    for (int i = 0; i < kFrames; ++i) {
      writer.add_frame({numbered_image(source_index(i), kSize), frame_time(i), source_index(i)});
      writer.add_truth(source_index(i), frame_time(i), test::numbered_pose(1000 + i));
    }
    for (int i = 0; i < kChunks; ++i) writer.add_tracker_bytes(test::numbered_chunk(i));
    for (int i = 0; i < kPoses; ++i) writer.add_pose(test::numbered_sample(i));
    EXPECT_EQ(writer.frames_written(), 60);  // the last 15 frames are in the open segment
    writer.close();
    EXPECT_EQ(writer.frames_written(), kFrames);
  }

  const RecordingReader reader(dir);
  const nlohmann::json s = test::session_file(dir);
  EXPECT_EQ(s["format"], "lumar-recording");
  EXPECT_EQ(s["version"], 1);
  EXPECT_EQ(s["complete"], true);
  EXPECT_TRUE(reader.complete());
  EXPECT_EQ(s["frames"], kFrames);
  EXPECT_EQ(s["camera"], caller["camera"]);  // exact double
  EXPECT_EQ(s["tracker"], "fastrak");
  EXPECT_EQ(s["video"]["codec"], codec);
  EXPECT_EQ(s["video"]["frames_per_segment"], 30);
  EXPECT_EQ(s["video"]["width"], 320);
  EXPECT_EQ(s["video"]["height"], 240);
  EXPECT_EQ(s["video"]["fps"], 30.0);

  // Three closed segments (30, 30, 15) and nothing left under a temporary name.
  const std::string ext = codec == "ffv1" ? ".mkv" : ".avi";
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir / "video")) files.push_back(e.path().filename());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"segment-000000" + ext, "segment-000001" + ext, "segment-000002" + ext}));
  for (const auto& entry : fs::directory_iterator(dir))  // no temporary of session.json is left
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();

  const auto& frames = reader.frames();
  ASSERT_EQ(frames.size(), std::size_t(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(frames[i].index, source_index(i));
    EXPECT_EQ(frames[i].time, frame_time(i));
    EXPECT_EQ(frames[i].segment, i / 30);
    EXPECT_EQ(frames[i].segment_frame, i % 30);
  }

  // Neighbouring test frames differ far more than the codec's error, so a frame
  // decoded out of order cannot pass.
  ASSERT_GT(test::mean_abs_diff(numbered_image(7, kSize), numbered_image(8, kSize)), 10.0);
  auto source = reader.open_frames();
  EXPECT_EQ(source->frame_size(), kSize);
  EXPECT_EQ(source->nominal_fps(), 30.0);
  Frame frame;
  double worst = 0;
  int n = 0;
  while (source->read(frame)) {
    ASSERT_LT(n, kFrames);
    EXPECT_EQ(frame.index, source_index(n));
    EXPECT_EQ(frame.time, frame_time(n));
    const double diff = test::mean_abs_diff(frame.image, numbered_image(source_index(n), kSize));
    worst = std::max(worst, diff);
    ++n;
  }
  EXPECT_EQ(n, kFrames);
  if (codec == "ffv1")
    EXPECT_EQ(worst, 0.0);
  else
    EXPECT_LT(worst, 2.0);  // measured 1.2 at quality 95
  RecordProperty("worst_mean_abs_diff", std::to_string(worst));

  std::size_t ignored = 99;
  const auto chunks = reader.tracker_chunks(&ignored);
  EXPECT_EQ(ignored, 0u);
  ASSERT_EQ(chunks.size(), std::size_t(kChunks));
  for (int i = 0; i < kChunks; ++i) {
    EXPECT_EQ(chunks[i].arrival, test::numbered_chunk(i).arrival);
    EXPECT_EQ(chunks[i].bytes, test::numbered_chunk(i).bytes);
  }

  const auto poses = reader.poses();
  ASSERT_EQ(poses.size(), std::size_t(kPoses));
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_EQ(poses[i].time, test::numbered_sample(i).time);
    EXPECT_EQ(poses[i].station, test::numbered_sample(i).station);
    test::expect_same_pose(poses[i].T_transmitter_sensor, test::numbered_pose(i));
  }

  const auto truth = reader.truth();
  ASSERT_EQ(truth.size(), std::size_t(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(truth[i].index, source_index(i));
    EXPECT_EQ(truth[i].time, frame_time(i));
    test::expect_same_pose(truth[i].T_world_camera, test::numbered_pose(1000 + i));
  }
}

INSTANTIATE_TEST_SUITE_P(Codecs, RecordingRoundTrip, testing::Values("mjpeg", "ffv1"));

TEST(RecordingWriter, EmptyRecordingHasNoFramesAndNoTruthFile) {
  const fs::path dir = test::scratch_dir("empty-recording");  // exists and is empty: allowed
  const test::RemoveOnSuccess cleanup{dir};
  RecordingSettings settings;
  settings.size = kSize;
  RecordingWriter(dir, nullptr, settings).close();
  const RecordingReader reader(dir);
  EXPECT_TRUE(reader.complete());
  EXPECT_EQ(test::session_file(dir)["frames"], 0);
  EXPECT_TRUE(reader.frames().empty());
  EXPECT_TRUE(reader.tracker_chunks().empty());
  EXPECT_TRUE(reader.poses().empty());
  EXPECT_TRUE(reader.truth().empty());
  EXPECT_FALSE(fs::exists(dir / "truth.csv"));
  Frame frame;
  EXPECT_FALSE(reader.open_frames()->read(frame));
}

// Capture, tracker and truth arrive on different threads in the live system.
TEST(RecordingWriter, StreamsFromSeparateThreadsAreAllKeptInOrder) {
  const fs::path dir = test::scratch_dir("threads") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const cv::Size size(160, 120);
  RecordingSettings settings;
  settings.codec = "ffv1";
  settings.size = size;
  settings.frames_per_segment = 10;
  {
    RecordingWriter writer(dir, {}, settings);
    std::thread frames([&] {
      for (int i = 0; i < 45; ++i) writer.add_frame({numbered_image(i, size), i, i});
    });
    std::thread tracker([&] {
      for (int i = 0; i < 400; ++i) writer.add_tracker_bytes(test::numbered_chunk(i));
    });
    std::thread poses([&] {
      for (int i = 0; i < 400; ++i) writer.add_pose(test::numbered_sample(i));
    });
    for (int i = 0; i < 45; ++i) writer.add_truth(i, i, test::numbered_pose(i));
    frames.join();
    tracker.join();
    poses.join();
  }  // the destructor closes
  const RecordingReader reader(dir);
  EXPECT_TRUE(reader.complete());
  ASSERT_EQ(reader.frames().size(), 45u);
  const auto chunks = reader.tracker_chunks();
  ASSERT_EQ(chunks.size(), 400u);
  for (int i = 0; i < 400; ++i) EXPECT_EQ(chunks[i].bytes, test::numbered_chunk(i).bytes);
  const auto poses = reader.poses();
  ASSERT_EQ(poses.size(), 400u);
  for (int i = 0; i < 400; ++i) EXPECT_EQ(poses[i].time, test::numbered_sample(i).time);
  EXPECT_EQ(reader.truth().size(), 45u);
  auto source = reader.open_frames();
  Frame frame;
  for (int i = 0; i < 45; ++i) {
    ASSERT_TRUE(source->read(frame));
    EXPECT_EQ(test::mean_abs_diff(frame.image, numbered_image(i, size)), 0.0);
  }
  EXPECT_FALSE(source->read(frame));
}

// An MJPEG recording replays with the levels it was written with, as a live MJPEG camera's
// frames decode (libjpeg). FFmpeg's decoding through swscale made every frame darker by
// 0.49 / 0.89 / 0.43 levels in B / G / R at quality 95: 1–2 % in linear light, which the
// composite's error took for a wrong shadow.
TEST(RecordingSource, MjpegFramesKeepTheirLevels) {
  const fs::path dir = test::scratch_dir("mjpeg-levels") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const cv::Size size(320, 240);
  constexpr int kCount = 40;
  const auto frame_image = [&](int i) { return test::noisy_numbered_image(i, size, 4, 3); };
  RecordingSettings settings;
  settings.size = size;
  settings.quality = 95;
  {
    RecordingWriter writer(dir, {}, settings);
    for (int i = 0; i < kCount; ++i) writer.add_frame({frame_image(i), i * test::kFramePeriod, i});
  }
  const RecordingReader reader(dir);
  auto source = reader.open_frames();
  Frame frame;
  cv::Scalar bias(0, 0, 0);
  int n = 0;
  testing::internal::CaptureStderr();  // libjpeg would print a line for each frame cut short
  while (source->read(frame)) {
    bias += cv::mean(frame.image) - cv::mean(frame_image(n));
    EXPECT_EQ(frame.chroma, (ChromaSampling{2, 2})) << n;  // OpenCV's writer stores 4:2:0
    ++n;
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(n, kCount);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(bias[c] / n), 0.1) << "channel " << c;
  RecordProperty("mean_bias_levels", std::to_string(bias[1] / n));
}

// OpenCV 4.6's MJPEG writer silently ignores a quality passed to open(); the
// setting must still reach the encoder.
TEST(RecordingWriter, MjpegQualityReachesTheEncoder) {
  const fs::path root = test::scratch_dir("mjpeg-quality");
  const test::RemoveOnSuccess cleanup{root};
  std::uintmax_t bytes[2] = {};
  double error[2] = {};
  const int qualities[2] = {50, 95};
  for (int k = 0; k < 2; ++k) {
    const fs::path dir = root / std::to_string(qualities[k]);
    RecordingSettings settings;
    settings.size = kSize;
    settings.quality = qualities[k];
    settings.frames_per_segment = 5;
    RecordingWriter writer(dir, {}, settings);
    for (int i = 0; i < 5; ++i) writer.add_frame({numbered_image(i, kSize), i, i});
    writer.close();
    bytes[k] = fs::file_size(dir / "video" / "segment-000000.avi");
    const RecordingReader reader(dir);
    EXPECT_EQ(test::session_file(dir)["video"]["quality"], qualities[k]);
    auto source = reader.open_frames();
    Frame frame;
    for (int i = 0; source->read(frame); ++i)
      error[k] = std::max(error[k], test::mean_abs_diff(frame.image, numbered_image(i, kSize)));
  }
  EXPECT_LT(bytes[0] * 10, bytes[1] * 9);  // quality 50 is smaller (measured 0.80x)...
  EXPECT_GT(error[0], error[1]);           // ...and less accurate
}

}  // namespace
}  // namespace lumar::capture
