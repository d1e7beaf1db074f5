// Image sequences and video files as frame sources, checked against the frames and
// counts of an independent reader (cv::VideoCapture read to the end).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "lumar/capture/image_sequence_source.h"
#include "lumar/capture/video_file_source.h"
#include "recording_test_support.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

fs::path video(const char* name) { return test::shared_dir() / "data" / "video" / name; }

// Plain OpenCV reading to the end: the independent count, and every 50th frame.
struct Decoded {
  int count = 0;
  std::vector<cv::Mat> every_50th;
};
Decoded decode_all(const fs::path& path) {
  cv::VideoCapture cap(path.string(), cv::CAP_FFMPEG);
  Decoded out;
  cv::Mat m;
  while (cap.read(m)) {
    if (out.count % 50 == 0) out.every_50th.push_back(m.clone());
    ++out.count;
  }
  return out;
}

TEST(VideoFileSource, SharedVideosGiveEveryFrameWithIncreasingTimes) {
  // README counts: vtest.avi 795 frames at 10 fps; tree.avi 444 slots of which 68 hold
  // a picture (the others are AVI null frames, see video_file_source.h).
  for (const auto& [name, pictures, fps] : {std::tuple{"vtest.avi", 795, 10.0}, std::tuple{"tree.avi", 68, 15.0}}) {
    const auto reference = decode_all(video(name));
    EXPECT_EQ(reference.count, pictures) << name;
    VideoFileSource source(video(name));
    EXPECT_NEAR(source.nominal_fps(), fps, 1e-3);
    Frame f;
    int n = 0;
    Nanos previous = -1;
    std::int64_t previous_index = -1;
    while (source.read(f)) {
      ASSERT_LT(n, reference.count) << name;
      EXPECT_GT(f.time, previous) << name << " frame " << n;
      EXPECT_GT(f.index, previous_index);
      // A picture at slot i plays at i / fps.
      EXPECT_NEAR(double(f.time), double(f.index) * 1e9 / source.nominal_fps(), 1e3);
      if (n % 50 == 0) {
        EXPECT_EQ(cv::norm(f.image, reference.every_50th[std::size_t(n / 50)], cv::NORM_INF), 0.0) << name << " " << n;
      }
      previous = f.time;
      previous_index = f.index;
      ++n;
    }
    EXPECT_EQ(n, pictures) << name;
  }
}

struct Sequence {
  fs::path dir;
  std::vector<cv::Mat> frames;
  std::vector<Nanos> times;
};

// The first n pictures of tree.avi as PNG files frame-1.png ... frame-n.png (not
// zero-padded, so only a natural sort gets the order right), with their video times.
Sequence write_sequence(const std::string& name, int n) {
  Sequence s{test::scratch_dir(name), {}, {}};
  VideoFileSource source(video("tree.avi"));
  Frame f;
  for (int i = 0; i < n && source.read(f); ++i) {
    s.frames.push_back(f.image.clone());
    s.times.push_back(f.time);
    cv::imwrite((s.dir / ("frame-" + std::to_string(i + 1) + ".png")).string(), f.image);
  }
  return s;
}

void write_table(const fs::path& file, const std::vector<std::string>& rows) {
  std::ofstream out(file);
  out << "file,time_ns\n";
  for (const auto& r : rows) out << r << "\n";
}

TEST(ImageSequenceSource, TimestampTableGivesTheFramesAndTimesItLists) {
  const Sequence s = write_sequence("imgseq_table", 24);
  test::RemoveOnSuccess cleanup{s.dir};
  std::vector<std::string> rows;
  for (std::size_t i = 0; i < s.frames.size(); ++i)
    rows.push_back("frame-" + std::to_string(i + 1) + ".png," + std::to_string(s.times[i]));
  write_table(s.dir / "times.csv", rows);
  ImageSequenceSource source({s.dir.string(), s.dir / "times.csv", 0});
  EXPECT_EQ(source.frame_size(), cv::Size(320, 240));
  Frame f;
  std::size_t n = 0;
  while (source.read(f)) {
    ASSERT_LT(n, s.frames.size());
    EXPECT_EQ(f.index, std::int64_t(n));
    EXPECT_EQ(f.time, s.times[n]);
    EXPECT_EQ(cv::norm(f.image, s.frames[n], cv::NORM_INF), 0.0) << "frame " << n;  // PNG is lossless
    ++n;
  }
  EXPECT_EQ(n, s.frames.size());
  // The table's span over its frame count.
  EXPECT_NEAR(source.nominal_fps(), 23.0 / nanos_to_seconds(s.times.back() - s.times.front()), 1e-9);
}

TEST(ImageSequenceSource, GlobAtAFixedRateInNaturalOrder) {
  const Sequence s = write_sequence("imgseq_glob", 12);
  test::RemoveOnSuccess cleanup{s.dir};
  std::ofstream(s.dir / "notes.txt") << "not an image";
  ImageSequenceSource source({(s.dir / "frame-*.png").string(), {}, 24.0});
  ASSERT_EQ(source.files().size(), 12u);
  EXPECT_EQ(source.files()[9].filename(), "frame-10.png");  // after frame-9, not after frame-1
  Frame f;
  for (std::size_t n = 0; n < 12; ++n) {
    ASSERT_TRUE(source.read(f));
    EXPECT_EQ(f.time, std::llround(double(n) * 1e9 / 24.0));
    EXPECT_EQ(cv::norm(f.image, s.frames[n], cv::NORM_INF), 0.0) << "frame " << n;
  }
  EXPECT_FALSE(source.read(f));

  ImageSequenceSource folder({s.dir.string(), {}, 24.0});  // a folder: its image files
  EXPECT_EQ(folder.files().size(), 12u);
}

// Opening decodes the first image (for the frame size); the first read gives that
// decoding rather than reading the file again: the file overwritten in between does not
// change frame 0, and the next frames are read as usual.
TEST(ImageSequenceSource, TheFirstImageIsDecodedOnce) {
  const Sequence s = write_sequence("imgseq_first_once", 3);
  test::RemoveOnSuccess cleanup{s.dir};
  ImageSequenceSource source({(s.dir / "frame-*.png").string(), {}, 24.0});
  std::ofstream(s.dir / "frame-1.png", std::ios::trunc) << "not an image any more";
  Frame f;
  for (std::size_t n = 0; n < 3; ++n) {
    ASSERT_TRUE(source.read(f));
    EXPECT_EQ(cv::norm(f.image, s.frames[n], cv::NORM_INF), 0.0) << "frame " << n;
  }
}

TEST(ImageSequenceSource, BadInputIsOneLineNamingTheFile) {
  const Sequence s = write_sequence("imgseq_bad", 3);
  test::RemoveOnSuccess cleanup{s.dir};
  const fs::path table = s.dir / "times.csv";
  using test::input_error_message;

  write_table(table, {"frame-1.png,0", "frame-7.png,10"});
  EXPECT_THAT(input_error_message([&] {
                ImageSequenceSource({s.dir.string(), table, 0});
              }),
              HasSubstr("times.csv:3: image"));
  write_table(table, {"frame-1.png,100", "frame-2.png,100"});
  EXPECT_THAT(input_error_message([&] {
                ImageSequenceSource({s.dir.string(), table, 0});
              }),
              HasSubstr("times.csv:3: time 100 does not increase"));
  write_table(table, {"frame-1.png,1e9"});
  EXPECT_THAT(input_error_message([&] {
                ImageSequenceSource({s.dir.string(), table, 0});
              }),
              HasSubstr("times.csv:2: time_ns '1e9' is not an integer"));
  EXPECT_THAT(input_error_message([&] {
                ImageSequenceSource({s.dir.string(), {}, 0});
              }),
              HasSubstr("needs a timestamp table or a frame rate"));
  EXPECT_THAT(input_error_message([&] {
                ImageSequenceSource({(s.dir / "nothing-*.png").string(), {}, 10});
              }),
              HasSubstr("no image files"));

  // A frame of another size, and a file that is not an image, fail when read.
  cv::imwrite((s.dir / "frame-2.png").string(), cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0)));
  std::ofstream(s.dir / "frame-3.png") << "garbage";
  ImageSequenceSource source({s.dir.string(), {}, 10});
  Frame f;
  ASSERT_TRUE(source.read(f));
  EXPECT_THAT(input_error_message([&] { source.read(f); }), HasSubstr("frame-2.png: is 10x10"));
  EXPECT_THAT(input_error_message([&] { source.read(f); }), HasSubstr("frame-3.png: cannot decode"));
}

}  // namespace
}  // namespace lumar::capture
