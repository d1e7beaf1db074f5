#include "lumar/capture/jpeg_decoder.h"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE

#include <jpeglib.h>

namespace lumar::capture {

namespace {

// libjpeg reports a fatal error by calling error_exit, which must not return: jump back.
struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf back;
  int warnings = 0;
};

void error_exit(j_common_ptr info) { std::longjmp(reinterpret_cast<ErrorManager*>(info->err)->back, 1); }

// Level −1 is a warning (corrupt data it worked around), higher levels trace messages.
// The default prints to stderr: for an MJPEG recording with a frame cut short (OpenCV 4.6's
// writer, opencv#24171) that is a line per such frame.
void emit_message(j_common_ptr info, int level) {
  if (level < 0) ++reinterpret_cast<ErrorManager*>(info->err)->warnings;
}

// Only trivially destructible locals here: a longjmp back to setjmp skips no destructor.
// `bgr` lives in the caller's frame, so its state is well defined after a jump.
bool decode_into(std::span<const std::uint8_t> jpeg, ErrorManager& errors, cv::Mat& bgr) {
  jpeg_decompress_struct info{};
  info.err = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = error_exit;
  errors.pub.emit_message = emit_message;
  if (setjmp(errors.back)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, jpeg.data(), static_cast<unsigned long>(jpeg.size()));
  const bool ok =
      jpeg_read_header(&info, TRUE) == JPEG_HEADER_OK && (info.num_components == 3 || info.num_components == 1);
  if (ok) {
    info.out_color_space = JCS_EXT_BGR;  // libjpeg-turbo's; a grey image is spread to three channels
    jpeg_start_decompress(&info);
    bgr.create(int(info.output_height), int(info.output_width), CV_8UC3);
    while (info.output_scanline < info.output_height) {
      JSAMPROW row = bgr.ptr<JSAMPLE>(int(info.output_scanline));
      jpeg_read_scanlines(&info, &row, 1);
    }
    jpeg_finish_decompress(&info);
  }
  jpeg_destroy_decompress(&info);
  return ok;
}

}  // namespace

DecodedJpeg decode_jpeg(std::span<const std::uint8_t> jpeg) {
  DecodedJpeg out;
  if (jpeg.size() < 4) return out;
  ErrorManager errors{};
  if (!decode_into(jpeg, errors, out.bgr)) return {};
  out.warnings = errors.warnings;
  return out;
}

}  // namespace lumar::capture
