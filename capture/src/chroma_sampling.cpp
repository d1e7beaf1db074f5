#include "lumar/capture/chroma_sampling.h"

#include <algorithm>

namespace lumar::capture {

namespace {

constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return std::uint32_t(std::uint8_t(a)) | std::uint32_t(std::uint8_t(b)) << 8 | std::uint32_t(std::uint8_t(c)) << 16 |
         std::uint32_t(std::uint8_t(d)) << 24;
}

}  // namespace

ChromaSampling chroma_sampling_of_pixel_format(std::uint32_t code) {
  // FFmpeg's tags for its pixel formats (libavcodec/raw.c); the JPEG ("J") variants share them.
  switch (code) {
    case fourcc('I', '4', '2', '0'):
    case fourcc('I', 'Y', 'U', 'V'):
    case fourcc('Y', 'V', '1', '2'):
    case fourcc('N', 'V', '1', '2'):
    case fourcc('N', 'V', '2', '1'):
      return {2, 2};
    case fourcc('Y', '4', '2', 'B'):
    case fourcc('Y', 'V', '1', '6'):
    case fourcc('Y', 'U', 'Y', '2'):
    case fourcc('Y', 'U', 'Y', 'V'):
    case fourcc('U', 'Y', 'V', 'Y'):
    case fourcc('H', 'D', 'Y', 'C'):
      return {2, 1};
    default:
      return {};
  }
}

ChromaSampling chroma_sampling_of(const cv::VideoCapture& capture) {
  const double code = capture.get(cv::CAP_PROP_CODEC_PIXEL_FORMAT);  // -1 or 0 when not known
  return code > 0 && code < 4294967296.0 ? chroma_sampling_of_pixel_format(std::uint32_t(code)) : ChromaSampling{};
}

ChromaSampling chroma_sampling_of_jpeg(std::span<const std::uint8_t> jpeg) {
  if (jpeg.size() < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) return {};
  std::size_t at = 2;
  // Marker segments up to the frame header: FF, the marker, a 2-byte length that counts itself.
  while (at + 4 <= jpeg.size()) {
    if (jpeg[at] != 0xFF) return {};
    const std::uint8_t marker = jpeg[at + 1];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    const std::size_t length = std::size_t(jpeg[at + 2]) << 8 | jpeg[at + 3];
    if (length < 2 || at + 2 + length > jpeg.size()) return {};
    // SOF0 to SOF15, less DHT (C4), JPG (C8) and DAC (CC).
    const bool frame_header = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame_header) {
      const std::uint8_t* h = jpeg.data() + at + 4;  // precision, height (2), width (2), components
      const std::size_t components = length >= 8 ? h[5] : 0;
      if (components < 3 || length < 8 + 3 * components) return {};
      // Each component: id, sampling factors (horizontal << 4 | vertical), quantisation table.
      int h_max = 1, v_max = 1;
      for (std::size_t c = 0; c < components; ++c)
        h_max = std::max(h_max, h[6 + 3 * c + 1] >> 4), v_max = std::max(v_max, h[6 + 3 * c + 1] & 15);
      const int h_chroma = std::max(1, h[6 + 3 + 1] >> 4), v_chroma = std::max(1, h[6 + 3 + 1] & 15);
      return {h_max / h_chroma, v_max / v_chroma};
    }
    if (marker == 0xDA) return {};  // scan data before any frame header
    at += 2 + length;
  }
  return {};
}

}  // namespace lumar::capture
