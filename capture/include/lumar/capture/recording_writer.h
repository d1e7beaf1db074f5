#pragma once
// Writes a recording (layout in recording_format.h) so that a crash at any moment
// leaves a readable directory: video goes in segments that only count once closed
// and renamed, the frame table only names closed segments, and the tracker bytes,
// poses and truth are flushed and fdatasync'd at least every 100 ms.
//
// Each add_* call may come from a different thread (capture, tracker, renderer).
// add_frame encodes in the calling thread and, every frames_per_segment frames,
// closes the segment and syncs it to disk; call it from a thread that may block for
// a few milliseconds.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "lumar/base/pose.h"
#include "lumar/capture/frame_source.h"
#include "lumar/capture/recording_format.h"
#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::capture {

class RecordingWriter {
 public:
  // Creates `dir` (it must not exist, or be an empty directory: else InputError).
  // `session` is the caller's JSON object (intrinsics, tracker settings, rig, ...);
  // the writer owns and overwrites its keys "format", "version", "complete",
  // "frames" and "video". Throws InputError for bad settings or a non-object session.
  RecordingWriter(const std::filesystem::path& dir, nlohmann::json session, RecordingSettings settings);
  ~RecordingWriter();  // closes if not closed; never throws (logs a failure)
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // frame.image must be BGR8 of settings.size (else InputError); frame.time is
  // already since the recording's start.
  void add_frame(const Frame& frame);
  void add_tracker_bytes(const tracking::ByteChunk& chunk);
  void add_pose(const tracking::PoseSample& sample);  // InputError for a non-finite pose
  void add_truth(std::int64_t index, Nanos time, const Pose& T_world_camera);

  // Closes the open segment, syncs everything, and rewrites session.json with
  // "complete": true and "frames". Idempotent. RuntimeError on an I/O failure.
  void close();

  std::int64_t frames_written() const;  // frames in closed segments
  const std::filesystem::path& directory() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lumar::capture
