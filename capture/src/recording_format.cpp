#include "lumar/capture/recording_format.h"

#include <cmath>
#include <cstdio>

#include "lumar/base/error.h"

namespace lumar::capture {
namespace {

std::string segment_stem(int segment) {
  char name[32];
  std::snprintf(name, sizeof name, "segment-%06d", segment);
  return name;
}

// The container each codec goes in; FFmpeg picks the muxer from the extension.
std::string container_extension(const std::string& codec) { return codec == "ffv1" ? ".mkv" : ".avi"; }

}  // namespace

void validate_recording_settings(const RecordingSettings& s, const std::string& what) {
  if (s.codec != "mjpeg" && s.codec != "ffv1")
    throw InputError(what + ": unknown video codec \"" + s.codec + "\"; use \"mjpeg\" or \"ffv1\"");
  if (s.quality < 1 || s.quality > 100)
    throw InputError(what + ": MJPEG quality " + std::to_string(s.quality) +
                     " is outside 1..100; use 95 for near-lossless");
  if (s.frames_per_segment < 1)
    throw InputError(what + ": frames_per_segment must be at least 1, not " + std::to_string(s.frames_per_segment));
  if (!std::isfinite(s.fps) || s.fps <= 0)
    throw InputError(what + ": fps must be a positive number, not " + std::to_string(s.fps));
  if (s.size.width <= 0 || s.size.height <= 0)
    throw InputError(what + ": frame size " + std::to_string(s.size.width) + "x" + std::to_string(s.size.height) +
                     " is empty; give the camera's size");
}

std::filesystem::path segment_path(const std::filesystem::path& dir, const std::string& codec, int segment) {
  return dir / kVideoDir / (segment_stem(segment) + container_extension(codec));
}

std::filesystem::path partial_segment_path(const std::filesystem::path& dir, const std::string& codec, int segment) {
  return dir / kVideoDir / (segment_stem(segment) + ".partial" + container_extension(codec));
}

}  // namespace lumar::capture
