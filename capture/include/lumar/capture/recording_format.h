#pragma once
// The on-disk layout of a recording: a directory that a crash cannot tear.
//
//   session.json        caller's JSON plus "format", "version", "complete", "frames"
//                       (at close), "video"; replaced atomically at open and close
//   video/segment-NNNNNN.avi|.mkv   closed segments only (MJPEG or FFV1); a segment
//                       is written as segment-NNNNNN.partial.avi|.mkv and renamed
//   frames.csv          index,time_ns,segment,segment_frame — rows of a segment are
//                       appended only after the segment was closed and renamed
//   tracker.raw         chunks: little-endian {u32 magic "LTRK", i64 arrival_ns,
//                       u32 length, u32 zlib crc32 of payload} + payload
//   poses.csv           time_ns,station,x,y,z,qw,qx,qy,qz (transmitter frame, metres)
//   truth.csv           index,time_ns,x,y,z,qw,qx,qy,qz (optional: true T_world_camera)
//
// Times are nanoseconds since the start of the recording. A final line without
// '\n' (or a torn final tracker chunk) is a write cut short by a crash; readers
// ignore it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"

namespace lumar::capture {

inline constexpr const char* kRecordingFormat = "lumar-recording";
inline constexpr int kRecordingVersion = 1;

inline constexpr const char* kSessionFile = "session.json";
inline constexpr const char* kFramesFile = "frames.csv";
inline constexpr const char* kTrackerFile = "tracker.raw";
inline constexpr const char* kPosesFile = "poses.csv";
inline constexpr const char* kTruthFile = "truth.csv";
inline constexpr const char* kVideoDir = "video";

inline constexpr const char* kFramesHeader = "index,time_ns,segment,segment_frame";
inline constexpr const char* kPosesHeader = "time_ns,station,x,y,z,qw,qx,qy,qz";
inline constexpr const char* kTruthHeader = "index,time_ns,x,y,z,qw,qx,qy,qz";

// tracker.raw chunk header: magic, arrival_ns, length, crc32 (20 bytes, no padding).
inline constexpr std::uint32_t kTrackerChunkMagic = 0x4B52544Cu;  // bytes "LTRK"
inline constexpr std::size_t kTrackerChunkHeaderBytes = 4 + 8 + 4 + 4;

struct RecordingSettings {
  std::string codec = "mjpeg";  // "mjpeg" (near-lossless, .avi) or "ffv1" (lossless, .mkv)
  int quality = 95;             // MJPEG quality 1..100; ignored by ffv1
  int frames_per_segment = 30;
  double fps = 30;  // nominal, written into the container and session.json
  cv::Size size;    // every frame must be BGR8 of this size
};

// Throws InputError "<what>: ..." when a setting is out of range or the codec unknown.
void validate_recording_settings(const RecordingSettings& settings, const std::string& what);

// One row of frames.csv.
struct FrameEntry {
  std::int64_t index = 0;  // frame number at the source (gaps are dropped frames)
  Nanos time = 0;          // since the start of the recording
  int segment = 0;
  int segment_frame = 0;  // position within the segment, from 0
};

// One row of truth.csv.
struct TruthEntry {
  std::int64_t index = 0;
  Nanos time = 0;
  Pose T_world_camera;
};

// "video/segment-000012.avi" (or .mkv for ffv1) inside `dir`.
std::filesystem::path segment_path(const std::filesystem::path& dir, const std::string& codec, int segment);
// The name a segment has while it is being written: "video/segment-000012.partial.avi".
std::filesystem::path partial_segment_path(const std::filesystem::path& dir, const std::string& codec, int segment);

}  // namespace lumar::capture
