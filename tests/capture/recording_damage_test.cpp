// Damaged or wrong inputs: torn logs are cut at the tear, everything else is an
// InputError naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "lumar/capture/recording_reader.h"
#include "lumar/capture/recording_writer.h"
#include "recording_test_support.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

const cv::Size kSize(160, 120);

RecordingSettings small_settings(const std::string& codec = "mjpeg") {
  RecordingSettings s;
  s.codec = codec;
  s.size = kSize;
  return s;
}

void write_text(const fs::path& path, const std::string& text, bool append = false) {
  std::ofstream out(path, append ? std::ios::app | std::ios::binary : std::ios::binary);
  out << text;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Recording with tracker chunks of payload sizes 10, 0, 33, 7, 100.
std::vector<tracking::ByteChunk> write_chunks(const fs::path& dir) {
  std::vector<tracking::ByteChunk> chunks;
  for (int size : {10, 0, 33, 7, 100}) {
    tracking::ByteChunk c{Nanos(size) * 1000 + 1, {}};
    for (int k = 0; k < size; ++k) c.bytes.push_back(std::uint8_t(k * 31 + size));
    chunks.push_back(c);
  }
  RecordingWriter writer(dir, {}, small_settings());
  for (const auto& c : chunks) writer.add_tracker_bytes(c);
  writer.close();
  return chunks;
}

TEST(TornTrackerLog, ChunksBeforeTheTearAreKeptAndTheRestCounted) {
  const fs::path dir = test::scratch_dir("torn-tracker") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const auto chunks = write_chunks(dir);
  const fs::path raw = dir / "tracker.raw";
  std::vector<std::uintmax_t> start;  // where each chunk begins
  std::uintmax_t pos = 0;
  for (const auto& c : chunks) {
    start.push_back(pos);
    pos += kTrackerChunkHeaderBytes + c.bytes.size();
  }
  ASSERT_EQ(fs::file_size(raw), pos);
  const RecordingReader reader(dir);

  auto expect_prefix = [&](std::size_t count, std::size_t ignored_expected) {
    std::size_t ignored = 12345;
    const auto got = reader.tracker_chunks(&ignored);
    ASSERT_EQ(got.size(), count);
    for (std::size_t i = 0; i < count; ++i) {
      EXPECT_EQ(got[i].arrival, chunks[i].arrival);
      EXPECT_EQ(got[i].bytes, chunks[i].bytes);
    }
    EXPECT_EQ(ignored, ignored_expected);
  };
  expect_prefix(5, 0);

  fs::resize_file(raw, start[4] + 20 + 50);  // mid-payload of the last chunk
  expect_prefix(4, 70);
  fs::resize_file(raw, start[3] + 11);  // mid-header of chunk 3
  expect_prefix(3, 11);
  fs::resize_file(raw, start[2] + 20);  // header of chunk 2 complete, payload missing
  expect_prefix(2, 20);
}

TEST(DamagedTrackerLog, ABadChunkIsSkippedAndTheChunksAfterItAreKept) {
  const fs::path dir = test::scratch_dir("bad-tracker") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  const auto chunks = write_chunks(dir);
  const fs::path raw = dir / "tracker.raw";
  const std::uintmax_t chunk2 = 2 * kTrackerChunkHeaderBytes + 10 + 0;

  auto flip_byte = [&](std::uintmax_t offset) {
    std::fstream f(raw, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(offset));
    const char c = char(f.get());
    f.seekp(std::streamoff(offset));
    f.put(char(c ^ 0x40));
  };
  const RecordingReader reader(dir);
  std::size_t ignored = 0;
  const std::size_t chunk2_bytes = kTrackerChunkHeaderBytes + chunks[2].bytes.size();
  auto expect_all_but_chunk2 = [&] {
    const auto got = reader.tracker_chunks(&ignored);
    ASSERT_EQ(got.size(), 4u);
    EXPECT_EQ(got[1].bytes, chunks[1].bytes);
    EXPECT_EQ(got[2].bytes, chunks[3].bytes);
    EXPECT_EQ(ignored, chunk2_bytes);
  };
  flip_byte(chunk2 + kTrackerChunkHeaderBytes + 5);  // payload byte: CRC mismatch
  expect_all_but_chunk2();
  flip_byte(chunk2 + kTrackerChunkHeaderBytes + 5);  // repaired
  EXPECT_EQ(reader.tracker_chunks(&ignored).size(), 5u);
  EXPECT_EQ(ignored, 0u);
  flip_byte(chunk2);  // magic
  expect_all_but_chunk2();
  flip_byte(chunk2);
  flip_byte(chunk2 + 12 + 3);  // the length's top byte: it claims 1 GB more than the file holds
  expect_all_but_chunk2();
  flip_byte(chunk2 + 12 + 3);

  // The first chunk's length corrupt (the case that lost every pose before): the rest is kept.
  flip_byte(12 + 1);
  EXPECT_EQ(reader.tracker_chunks(&ignored).size(), 4u);
  EXPECT_EQ(ignored, kTrackerChunkHeaderBytes + chunks[0].bytes.size());
  flip_byte(12 + 1);

  // A torn last chunk (what a crash leaves) is told apart from damage.
  std::size_t torn = 99;
  fs::resize_file(raw, fs::file_size(raw) - 30);
  EXPECT_EQ(reader.tracker_chunks(&ignored, &torn).size(), 4u);
  EXPECT_EQ(torn, ignored);
  EXPECT_EQ(torn, kTrackerChunkHeaderBytes + chunks[4].bytes.size() - 30);
  flip_byte(chunk2 + kTrackerChunkHeaderBytes + 5);  // and damage before it
  EXPECT_EQ(reader.tracker_chunks(&ignored, &torn).size(), 3u);
  EXPECT_EQ(ignored - torn, chunk2_bytes);

  // Nothing but garbage: no chunk, every byte ignored.
  std::ofstream(raw, std::ios::binary | std::ios::trunc) << std::string(4096, 'x');
  EXPECT_EQ(reader.tracker_chunks(&ignored, &torn).size(), 0u);
  EXPECT_EQ(ignored, 4096u);
  EXPECT_EQ(torn, 0u);
}

TEST(TornCsv, FinalPartialLineIsIgnoredButABadRowIsAnError) {
  const fs::path dir = test::scratch_dir("torn-csv") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  {
    RecordingWriter writer(dir, {}, small_settings());
    for (int i = 0; i < 3; ++i) writer.add_pose(test::numbered_sample(i));
    writer.add_truth(0, 0, test::numbered_pose(9));
    writer.close();
  }
  write_text(dir / "poses.csv", "123,1,0.5,0.", /*append=*/true);  // torn write
  write_text(dir / "truth.csv", "1,2,3", /*append=*/true);
  const RecordingReader reader(dir);
  EXPECT_EQ(reader.poses().size(), 3u);
  EXPECT_EQ(reader.truth().size(), 1u);

  write_text(dir / "poses.csv", "\n", /*append=*/true);  // the torn line is now complete
  EXPECT_THAT(test::input_error_message([&] { reader.poses(); }), HasSubstr("poses.csv:5"));
  write_text(dir / "truth.csv", ",4,5,6,1,0,0,nan\n", /*append=*/true);
  EXPECT_THAT(test::input_error_message([&] { reader.truth(); }), HasSubstr("truth.csv:3"));
}

TEST(RecordingReaderErrors, NameTheFileThatIsWrong) {
  const fs::path root = test::scratch_dir("reader-errors");
  const test::RemoveOnSuccess cleanup{root};
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(root / "nowhere"); }), HasSubstr("nowhere"));

  fs::create_directories(root / "empty");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(root / "empty"); }), HasSubstr("empty/session.json"));

  const fs::path dir = root / "rec";
  {
    RecordingWriter writer(dir, {}, small_settings());
    for (int i = 0; i < 3; ++i) writer.add_frame({test::numbered_image(i, kSize), i, i});
  }
  ASSERT_NO_THROW(RecordingReader{dir});
  const std::string good_session = read_text(dir / "session.json");
  write_text(dir / "session.json", "{\"format\": \"lumar-recording\", \"version\": ");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/session.json: malformed JSON"));
  write_text(dir / "session.json", "[1, 2]");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }), HasSubstr("rec/session.json"));
  auto session = nlohmann::json::parse(good_session);
  session["format"] = "something-else";
  write_text(dir / "session.json", session.dump());
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }), HasSubstr("rec/session.json"));
  session["format"] = "lumar-recording";
  session["version"] = 2;
  write_text(dir / "session.json", session.dump());
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/session.json: unsupported recording version 2"));
  session["version"] = 1;
  session["video"].erase("width");
  write_text(dir / "session.json", session.dump());
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }), HasSubstr("rec/session.json"));
  write_text(dir / "session.json", good_session);
  ASSERT_NO_THROW(RecordingReader{dir});

  write_text(dir / "frames.csv", "1,abc,0,1\n", /*append=*/true);
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }), HasSubstr("rec/frames.csv:5"));
  write_text(dir / "frames.csv", std::string(kFramesHeader) + "\n0,0,0,0\n0,1,0,2\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:3"));  // skips segment frame 1

  // Times and indices must increase and times count from 0 (once accepted silently).
  const std::string head = std::string(kFramesHeader) + "\n0,0,0,0\n";
  write_text(dir / "frames.csv", head + "1,0,0,1\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:3: time_ns 0 does not increase"));
  write_text(dir / "frames.csv", head + "2,-7,0,1\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:3: time_ns -7 is negative"));
  write_text(dir / "frames.csv", std::string(kFramesHeader) + "\n0,50,0,0\n1,40,0,1\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:3: time_ns 40 does not increase"));
  write_text(dir / "frames.csv", std::string(kFramesHeader) + "\n3,0,0,0\n3,10,0,1\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:3: index 3 does not increase"));
  // Columns go by name: the same rows with the columns reordered read the same.
  write_text(dir / "frames.csv", "time_ns,index,segment_frame,segment\n0,0,0,0\n5,1,1,0\n");
  ASSERT_EQ(RecordingReader(dir).frames().size(), 2u);
  EXPECT_EQ(RecordingReader(dir).frames()[1].time, 5);
  EXPECT_EQ(RecordingReader(dir).frames()[1].segment_frame, 1);
  write_text(dir / "frames.csv", "index,time,segment,segment_frame\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader r(dir); }),
              HasSubstr("rec/frames.csv:1: the header has no column 'time_ns'"));
  // An empty frames.csv (the writer died before its header) is a recording without frames.
  write_text(dir / "frames.csv", "");
  EXPECT_EQ(RecordingReader(dir).frames().size(), 0u);

  fs::remove(dir / "poses.csv");
  write_text(dir / "frames.csv", std::string(kFramesHeader) + "\n");
  EXPECT_THAT(test::input_error_message([&] { RecordingReader(dir).poses(); }), HasSubstr("rec/poses.csv"));
}

class TruncatedSegment : public testing::TestWithParam<std::string> {};

TEST_P(TruncatedSegment, IsAnInputErrorNamingTheSegment) {
  const std::string codec = GetParam();
  const fs::path dir = test::scratch_dir("truncated-" + codec) / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};
  {
    RecordingWriter writer(dir, {}, small_settings(codec));
    for (int i = 0; i < 60; ++i) writer.add_frame({test::numbered_image(i, kSize), i, i});
  }
  const RecordingReader reader(dir);
  const fs::path segment = reader.segment_file(1);
  fs::resize_file(segment, fs::file_size(segment) / 2);

  auto source = reader.open_frames();
  Frame frame;
  int decoded = 0;
  const std::string message = test::input_error_message([&] {
    while (source->read(frame)) ++decoded;
  });
  EXPECT_GE(decoded, 30);  // all of segment 0
  EXPECT_LT(decoded, 60);
  EXPECT_THAT(message, HasSubstr(segment.string() + ": truncated or corrupt video (decoded "));
  EXPECT_THAT(message, HasSubstr(" of 30 frames)"));
  RecordProperty("message", message);

  fs::remove(segment);
  source = reader.open_frames();
  decoded = 0;
  EXPECT_THAT(test::input_error_message([&] {
                while (source->read(frame)) ++decoded;
              }),
              HasSubstr(segment.string() + ": truncated or corrupt video (decoded 0 of 30 frames)"));
  EXPECT_EQ(decoded, 30);
}

INSTANTIATE_TEST_SUITE_P(Codecs, TruncatedSegment, testing::Values("mjpeg", "ffv1"));

TEST(RecordingWriterErrors, RefusesAnOccupiedDirectoryAndBadFrames) {
  const fs::path root = test::scratch_dir("writer-errors");
  const test::RemoveOnSuccess cleanup{root};
  fs::create_directories(root / "busy");
  write_text(root / "busy" / "keep.txt", "precious");
  EXPECT_THAT(test::input_error_message([&] { RecordingWriter w(root / "busy", {}, small_settings()); }),
              HasSubstr("busy: directory is not empty"));
  EXPECT_TRUE(fs::exists(root / "busy" / "keep.txt"));
  write_text(root / "file", "x");
  EXPECT_THAT(test::input_error_message([&] { RecordingWriter w(root / "file", {}, small_settings()); }),
              HasSubstr("file: exists and is not a directory"));

  RecordingSettings bad = small_settings("h264");
  EXPECT_THAT(test::input_error_message([&] { RecordingWriter w(root / "codec", {}, bad); }), HasSubstr("h264"));
  EXPECT_THAT(test::input_error_message([&] {
                RecordingWriter w(root / "arr", {1, 2}, small_settings());
              }),
              HasSubstr("JSON object"));

  RecordingWriter writer(root / "rec", {}, small_settings());
  EXPECT_THAT(test::input_error_message([&] {
                writer.add_frame({test::numbered_image(0, {320, 240}), 0, 0});
              }),
              HasSubstr("320x240"));
  cv::Mat gray(kSize, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(writer.add_frame({gray, 0, 0}), InputError);
  writer.close();
  EXPECT_EQ(RecordingReader(root / "rec").frames().size(), 0u);
  EXPECT_THROW(writer.add_frame({test::numbered_image(0, kSize), 0, 0}), RuntimeError);
}

}  // namespace
}  // namespace lumar::capture
