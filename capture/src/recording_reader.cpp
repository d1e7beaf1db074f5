#include "lumar/capture/recording_reader.h"

#include <cmath>
#include <functional>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/json_file.h"
#include "lumar/capture/recording_source.h"
#include "lumar/capture/tracker_raw.h"

namespace lumar::capture {
namespace fs = std::filesystem;

namespace {

// A recording's file; a missing one means the recording is incomplete or is not one.
std::string read_recording_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec))
    throw InputError(file.string() + ": missing; the recording is incomplete or not a recording");
  return read_input_file(file, "recording file");
}

// The recording's CSV logs: columns by name, a torn last line ignored (see recording_format.h).
void for_each_log_row(const fs::path& file, const std::string& header, const std::function<void(const csv::Row&)>& fn) {
  std::vector<std::string> names;
  for (std::size_t a = 0, b; a <= header.size(); a = b + 1) {
    b = std::min(header.find(',', a), header.size());
    names.push_back(header.substr(a, b - a));
  }
  csv::for_each_row(file, read_recording_file(file), {names}, csv::LastLine::kIgnoreTorn, fn);
}

Pose pose_from_row(const csv::Row& row) {
  Pose p;
  p.translation = {row.real("x"), row.real("y"), row.real("z")};
  const glm::dquat q(row.real("qw"), row.real("qx"), row.real("qy"), row.real("qz"));
  const double norm = glm::length(q);
  if (!(std::abs(norm - 1.0) < 1e-3))
    row.fail("the quaternion qw,qx,qy,qz has length " + std::to_string(norm) + ", not 1; the file is corrupt");
  p.rotation = q;
  return p;
}

Nanos time_of(const csv::Row& row) {
  const Nanos t = row.integer("time_ns");
  if (t < 0) row.fail("time_ns " + std::to_string(t) + " is negative; times count from the recording's start");
  return t;
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
  const std::string text = read_recording_file(session_file);
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

  // The writer appends whole closed segments in order, frames in increasing index and
  // time; anything else is damage.
  const fs::path frames_file = dir / kFramesFile;
  for_each_log_row(frames_file, kFramesHeader, [&](const csv::Row& row) {
    const FrameEntry e{row.integer("index"), time_of(row), row.small_integer("segment"),
                       row.small_integer("segment_frame")};
    const FrameEntry* prev = frames_.empty() ? nullptr : &frames_.back();
    const bool continues = prev && e.segment == prev->segment && e.segment_frame == prev->segment_frame + 1 &&
                           e.segment_frame < video_.frames_per_segment;
    const bool starts = e.segment_frame == 0 && e.segment == (prev ? prev->segment + 1 : 0);
    const std::string damaged = "; the file is corrupt (fix or delete the line)";
    if (!continues && !starts)
      row.fail("segment " + std::to_string(e.segment) + " frame " + std::to_string(e.segment_frame) +
               " is out of sequence" + damaged);
    if (e.index < 0) row.fail("index " + std::to_string(e.index) + " is negative" + damaged);
    if (prev && e.index <= prev->index)
      row.fail("index " + std::to_string(e.index) + " does not increase (the line before has " +
               std::to_string(prev->index) + ")" + damaged);
    if (prev && e.time <= prev->time)
      row.fail("time_ns " + std::to_string(e.time) + " does not increase (the line before has " +
               std::to_string(prev->time) + ")" + damaged);
    frames_.push_back(e);
  });
}

Session RecordingReader::session() const { return session_from_json(session_json_, (dir_ / kSessionFile).string()); }

fs::path RecordingReader::segment_file(int segment) const { return segment_path(dir_, video_.codec, segment); }

std::vector<tracking::ByteChunk> RecordingReader::tracker_chunks(std::size_t* ignored_bytes,
                                                                 std::size_t* torn_tail_bytes) const {
  const std::string data = read_recording_file(dir_ / kTrackerFile);
  return parse_tracker_chunks(data, ignored_bytes, torn_tail_bytes);
}

std::vector<tracking::PoseSample> RecordingReader::poses() const {
  std::vector<tracking::PoseSample> samples;
  for_each_log_row(dir_ / kPosesFile, kPosesHeader, [&](const csv::Row& row) {
    // A pose's time may be before the first frame's (the tracker's latency is taken off it).
    samples.push_back({row.integer("time_ns"), row.small_integer("station"), pose_from_row(row)});
  });
  return samples;
}

std::vector<TruthEntry> RecordingReader::truth() const {
  std::vector<TruthEntry> entries;
  const fs::path file = dir_ / kTruthFile;
  std::error_code ec;
  if (!fs::exists(file, ec)) return entries;
  for_each_log_row(file, kTruthHeader, [&](const csv::Row& row) {
    entries.push_back({row.integer("index"), time_of(row), pose_from_row(row)});
  });
  return entries;
}

std::unique_ptr<FrameSource> RecordingReader::open_frames() const { return std::make_unique<RecordingSource>(*this); }

}  // namespace lumar::capture
