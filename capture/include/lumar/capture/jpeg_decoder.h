#pragma once
// One JPEG image (an MJPEG camera's frame, or a frame of an MJPEG recording) to BGR, with
// libjpeg: the decoder OpenCV's imdecode uses, so that a recording replays with the colours
// the live camera gave. FFmpeg's MJPEG path through OpenCV (swscale's colour conversion)
// darkens every frame by 0.4–0.9 levels, 1–2 % in linear light (docs/capture.md, "MJPEG").
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>

namespace lumar::capture {

struct DecodedJpeg {
  cv::Mat bgr;       // CV_8UC3; empty when the bytes are not a JPEG libjpeg can decode
  int warnings = 0;  // libjpeg's warnings (e.g. data cut short), counted, not printed
};

DecodedJpeg decode_jpeg(std::span<const std::uint8_t> jpeg);

}  // namespace lumar::capture
