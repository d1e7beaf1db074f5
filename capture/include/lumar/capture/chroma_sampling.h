#pragma once
// How a camera or codec samples colour: in YCbCr, how many neighbouring pixels share one
// chroma (Cb, Cr) sample while each keeps its own luma. JPEG and H.264 share one among 2×2
// (4:2:0), YUYV among 2×1 (4:2:2). The overlay gives rendered pixels the same sampling, so
// that their colour bleeds into the video's around them as the camera's own objects' does
// (docs/ground_truth.md, "Chroma").
#include <cstdint>
#include <opencv2/videoio.hpp>
#include <span>

namespace lumar::capture {

struct ChromaSampling {
  int horizontal = 1, vertical = 1;  // pixels per chroma sample along x and y; 1×1: each its own, or not known
  bool subsampled() const { return horizontal > 1 || vertical > 1; }
  bool operator==(const ChromaSampling&) const = default;
};

// Of a decoder's pixel format, a fourcc as OpenCV's CAP_PROP_CODEC_PIXEL_FORMAT reports
// FFmpeg's (I420, Y42B, YUY2, 444P, ...); 1×1 for RGB and for formats it does not know.
ChromaSampling chroma_sampling_of_pixel_format(std::uint32_t fourcc);

// Of what an open capture decodes to (its CAP_PROP_CODEC_PIXEL_FORMAT); 1×1 if it does not say.
ChromaSampling chroma_sampling_of(const cv::VideoCapture& capture);

// Of a JPEG image (an MJPEG frame), from the sampling factors in its frame header; 1×1
// for a grey image or bytes that hold no frame header.
ChromaSampling chroma_sampling_of_jpeg(std::span<const std::uint8_t> jpeg);

}  // namespace lumar::capture
