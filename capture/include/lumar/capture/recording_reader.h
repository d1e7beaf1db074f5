#pragma once
// Reads a recording (layout in recording_format.h), including one cut short by a
// crash: only closed segments are listed, and torn tails of the logs are ignored.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "lumar/capture/frame_source.h"
#include "lumar/capture/recording_format.h"
#include "lumar/capture/session.h"
#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::capture {

class RecordingReader {
 public:
  // Reads session.json and frames.csv. InputError naming the file for a missing
  // directory, a missing or malformed session.json, a wrong format or version, or
  // a malformed frames.csv row.
  explicit RecordingReader(const std::filesystem::path& dir);

  const std::filesystem::path& directory() const { return dir_; }
  // The session (camera, radiometry, tracker, rig, ...): InputError naming session.json
  // when it does not read as one.
  Session session() const;
  const RecordingSettings& video() const { return video_; }  // from session.json "video"
  bool complete() const { return complete_; }                // closed cleanly (false after a crash)
  const std::vector<FrameEntry>& frames() const { return frames_; }
  std::filesystem::path segment_file(int segment) const;

  // The whole chunks (parse_tracker_chunks); `ignored_bytes` gets the bytes in none,
  // `torn_tail_bytes` those of them that are a last chunk cut short.
  std::vector<tracking::ByteChunk> tracker_chunks(std::size_t* ignored_bytes = nullptr,
                                                  std::size_t* torn_tail_bytes = nullptr) const;
  std::vector<tracking::PoseSample> poses() const;
  std::vector<TruthEntry> truth() const;             // empty when there is no truth.csv
  std::unique_ptr<FrameSource> open_frames() const;  // a RecordingSource

 private:
  std::filesystem::path dir_;
  nlohmann::json session_json_;  // parsed by session()
  bool complete_ = false;
  RecordingSettings video_;
  std::vector<FrameEntry> frames_;
};

}  // namespace lumar::capture
