// VideoFileSource on real footage and on a file whose timestamps we know.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "lumar/capture/recording_reader.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/capture/video_file_source.h"
#include "recording_test_support.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

// The slots of an AVI's video stream that hold a picture, from its idx1 index:
// zero-length chunks are "null frames" that repeat the previous picture.
std::vector<std::int64_t> avi_picture_slots(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string data{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto le32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(std::uint8_t(data[at + i])) << (8 * i);
    return v;
  };
  const std::size_t idx1 = data.rfind("idx1");
  EXPECT_NE(idx1, std::string::npos);
  std::vector<std::int64_t> slots;
  std::int64_t slot = 0;
  for (std::size_t e = idx1 + 8; e + 16 <= idx1 + 8 + le32(idx1 + 4); e += 16) {
    const std::string id = data.substr(e, 4);
    if (id != "00dc" && id != "00db") continue;
    if (le32(e + 12) > 0) slots.push_back(slot);
    ++slot;
  }
  EXPECT_EQ(slot, 444);  // the frame count the README gives
  return slots;
}

TEST(VideoFileSource, DecodesTreeAviWithItsTimestamps) {
  const fs::path path = test::shared_dir() / "data" / "video" / "tree.avi";
  VideoFileSource source(path);
  EXPECT_EQ(source.frame_size(), cv::Size(320, 240));
  EXPECT_NEAR(source.nominal_fps(), 15.0, 1e-3);  // the header says 1e6 / 66667
  EXPECT_THAT(source.describe(), HasSubstr("tree.avi"));
  const double period = 1e9 / source.nominal_fps();

  std::vector<std::int64_t> indices;
  Frame frame;
  Nanos previous = -1;
  while (source.read(frame)) {
    EXPECT_EQ(frame.image.size(), cv::Size(320, 240));
    EXPECT_EQ(frame.image.type(), CV_8UC3);
    EXPECT_GT(frame.time, previous);
    EXPECT_NEAR(double(frame.time), double(frame.index) * period, 1e3) << "frame " << frame.index;
    previous = frame.time;
    indices.push_back(frame.index);
  }
  EXPECT_FALSE(source.read(frame));
  // 68 pictures in 444 slots of 1/15 s; the rest are null chunks.
  EXPECT_EQ(indices, avi_picture_slots(path));
  EXPECT_EQ(indices.size(), 68u);
  ASSERT_FALSE(indices.empty());
  EXPECT_EQ(indices.front(), 0);
  EXPECT_EQ(indices.back(), 443);
}

// A segment written at 25 fps: presentation times are exactly k/25 s, and an
// FFV1 segment decodes bit-exactly through the generic source too.
TEST(VideoFileSource, ReadsARecordingSegmentExactly) {
  const fs::path dir = test::scratch_dir("video-file-source") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const cv::Size size(160, 120);
  RecordingSettings settings;
  settings.codec = "ffv1";
  settings.size = size;
  settings.fps = 25;
  {
    RecordingWriter writer(dir, {}, settings);
    for (int i = 0; i < 12; ++i) writer.add_frame({test::numbered_image(i, size), i, i});
  }
  VideoFileSource source(RecordingReader(dir).segment_file(0));
  EXPECT_NEAR(source.nominal_fps(), 25.0, 1e-9);
  Frame frame;
  int n = 0;
  while (source.read(frame)) {
    EXPECT_NEAR(double(frame.time), n * 40e6, 1e3);
    EXPECT_EQ(test::mean_abs_diff(frame.image, test::numbered_image(n, size)), 0.0);
    ++n;
  }
  EXPECT_EQ(n, 12);
}

TEST(VideoFileSource, MissingOrUndecodableFileIsAnInputError) {
  const fs::path root = test::scratch_dir("video-file-errors");
  const test::RemoveOnSuccess cleanup{root};
  EXPECT_THAT(test::input_error_message([&] { VideoFileSource s(root / "absent.avi"); }),
              HasSubstr("absent.avi: no such video file"));
  std::ofstream(root / "notes.avi") << "this is not a video\n";
  EXPECT_THAT(test::input_error_message([&] { VideoFileSource s(root / "notes.avi"); }), HasSubstr("notes.avi"));
}

}  // namespace
}  // namespace lumar::capture
