#pragma once
// Anything that yields timestamped camera frames: a V4L2 camera, a video file,
// an image sequence, a recording. Tests drive the same code paths through it.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "lumar/base/time.h"
#include "lumar/capture/chroma_sampling.h"

namespace lumar::capture {

struct Frame {
  cv::Mat image;            // 8-bit BGR, as the camera delivered it (distorted, display-encoded)
  Nanos time = 0;           // middle of the exposure; recordings: since the recording's start
  std::int64_t index = 0;   // frame number at the source (gaps mean dropped frames)
  ChromaSampling chroma{};  // how the camera or codec sampled its colour (1×1: each pixel its own, or not known)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Next frame; false at the end of the stream. Throws RuntimeError on a failing
  // device and InputError on corrupt input.
  virtual bool read(Frame& frame) = 0;
  virtual cv::Size frame_size() const = 0;
  virtual double nominal_fps() const = 0;
  virtual std::string describe() const = 0;  // for messages: "recording recordings/orbit"
  // How long each frame's shutter is open (0: not known): a camera's exposure time, a
  // recording's session shutter_s. The overlay's motion blur and `lumar record` use it.
  virtual Nanos shutter_time() const { return 0; }
};

}  // namespace lumar::capture
