#pragma once
// One text form for every frame source, as the command line gives it:
//   video:FILE            a video file (FFmpeg), presentation timestamps
//   images:DIR_OR_GLOB    an image sequence (timestamp table or fixed rate)
//   v4l2:/dev/videoN      a V4L2 camera
//   recording:DIR         the video of a Lumar recording
#include <filesystem>
#include <memory>
#include <string>

#include "lumar/capture/frame_source.h"
#include "lumar/capture/v4l2_source.h"

namespace lumar::capture {

struct SourceOptions {
  std::filesystem::path timestamps;  // images: the file,time_ns table
  double fps = 0;                    // images: fixed rate without a table
  V4l2Settings v4l2;                 // v4l2: everything but the path
};

struct OpenedSource {
  std::unique_ptr<FrameSource> source;
  bool live = false;  // a camera: frames come at their own pace, times are CLOCK_MONOTONIC
};

// Throws InputError naming the spec for an unknown kind or an empty path, and whatever
// the source's constructor throws.
OpenedSource open_frame_source(const std::string& spec, const SourceOptions& options = {});

}  // namespace lumar::capture
