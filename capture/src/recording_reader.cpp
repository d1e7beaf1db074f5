#include "lumar/capture/recording_reader.h"

#include <fstream>

#include "csv_text.h"
#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/capture/recording_source.h"
#include "lumar/capture/tracker_raw.h"

namespace lumar::capture {
namespace fs = std::filesystem;

namespace {

Pose pose_from_row(const csv::Row& row, std::size_t first) {
  Pose p;
  p.translation = {row.real(first), row.real(first + 1), row.real(first + 2)};
  p.rotation = glm::dquat(row.real(first + 3), row.real(first + 4), row.real(first + 5), row.real(first + 6));
  return p;
}

RecordingSettings video_from_session(const nlohmann::json& session, const fs::path& file) {
  const auto bad = [&](const std::string& what) -> InputError {
    return InputError(file.string() + ": \"video\" " + what + "; the recording was not written by Lumar or is damaged");
  };
  const auto it = session.find("video");
  if (it == session.end() || !it->is_object()) throw bad("is missing");
  RecordingSettings s;
  try {
    s.codec = it->at("codec").get<std::string>();
    s.frames_per_segment = it->at("frames_per_segment").get<int>();
    s.fps = it->at("fps").get<double>();
    s.size = {it->at("width").get<int>(), it->at("height").get<int>()};
    if (it->contains("quality")) s.quality = it->at("quality").get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw bad(std::string("lacks a field or has a wrong type (") + e.what() + ")");
  }
  validate_recording_settings(s, file.string() + ": \"video\"");
  return s;
}

}  // namespace

RecordingReader::RecordingReader(const fs::path& dir) : dir_(dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": no such recording directory; check the path");

  const fs::path session_file = dir / kSessionFile;
  if (!fs::exists(session_file, ec))
    throw InputError(session_file.string() + ": missing; " + dir.string() +
                     " is not a Lumar recording (or its writer died before starting)");
  const std::string text = csv::read_file(session_file);
  const nlohmann::json session_ = parse_json_text(text, session_file);
  if (!session_.is_object())
    throw InputError(session_file.string() + ": malformed session (not a JSON object); repair it" +
                     " by hand or restore it");
  const auto format = session_.find("format");
  if (format == session_.end() || !format->is_string() || format->get<std::string>() != kRecordingFormat)
    throw InputError(session_file.string() + ": \"format\" is not \"" + kRecordingFormat +
                     "\"; this is not a Lumar recording");
  const auto version = session_.find("version");
  if (version == session_.end() || !version->is_number_integer() || version->get<int>() != kRecordingVersion)
    throw InputError(session_file.string() + ": unsupported recording version " +
                     (version == session_.end() ? "(none)" : version->dump()) + "; this Lumar reads version " +
                     std::to_string(kRecordingVersion));
  video_ = video_from_session(session_, session_file);
  const auto complete = session_.find("complete");
  complete_ = complete != session_.end() && complete->is_boolean() && complete->get<bool>();
  // The session's own keys are parsed when asked for (session()): a recording made by
  // a program that wrote other keys can still be read frame by frame.
  session_json_ = std::move(session_);

  // The writer appends whole closed segments in order; anything else is damage.
  csv::for_each_row(dir / kFramesFile, kFramesHeader, 4, [&](const csv::Row& row) {
    FrameEntry e{row.integer(0), row.integer(1), row.small_integer(2), row.small_integer(3)};
    const FrameEntry* prev = frames_.empty() ? nullptr : &frames_.back();
    const bool continues = prev && e.segment == prev->segment && e.segment_frame == prev->segment_frame + 1 &&
                           e.segment_frame < video_.frames_per_segment;
    const bool starts = e.segment_frame == 0 && e.segment == (prev ? prev->segment + 1 : 0);
    if (!continues && !starts)
      row.fail("segment " + std::to_string(e.segment) + " frame " + std::to_string(e.segment_frame) +
               " is out of sequence");
    frames_.push_back(e);
  });
}

Session RecordingReader::session() const { return session_from_json(session_json_, (dir_ / kSessionFile).string()); }

fs::path RecordingReader::segment_file(int segment) const { return segment_path(dir_, video_.codec, segment); }

std::vector<tracking::ByteChunk> RecordingReader::tracker_chunks(std::size_t* ignored_bytes) const {
  const std::string data = csv::read_file(dir_ / kTrackerFile);
  return parse_tracker_chunks(data, ignored_bytes);
}

std::vector<tracking::PoseSample> RecordingReader::poses() const {
  std::vector<tracking::PoseSample> samples;
  csv::for_each_row(dir_ / kPosesFile, kPosesHeader, 9, [&](const csv::Row& row) {
    samples.push_back({row.integer(0), row.small_integer(1), pose_from_row(row, 2)});
  });
  return samples;
}

std::vector<TruthEntry> RecordingReader::truth() const {
  std::vector<TruthEntry> entries;
  const fs::path file = dir_ / kTruthFile;
  std::error_code ec;
  if (!fs::exists(file, ec)) return entries;
  csv::for_each_row(file, kTruthHeader, 9, [&](const csv::Row& row) {
    entries.push_back({row.integer(0), row.integer(1), pose_from_row(row, 2)});
  });
  return entries;
}

std::unique_ptr<FrameSource> RecordingReader::open_frames() const { return std::make_unique<RecordingSource>(*this); }

}  // namespace lumar::capture
