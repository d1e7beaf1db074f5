#include "lumar/capture/video_file_source.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"

namespace lumar::capture {

VideoFileSource::VideoFileSource(const std::filesystem::path& path) : path_(path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string() + ": no such video file; check the path");
  // FFmpeg only: it reports real presentation timestamps, and the other backends
  // (GStreamer, image sequences) would only add noise to the error path.
  if (!capture_.open(path.string(), cv::CAP_FFMPEG))
    throw InputError(path.string() + ": OpenCV cannot open this video; convert it to a common" +
                     " format (e.g. H.264 MP4 or MJPEG AVI)");
  const double fps = capture_.get(cv::CAP_PROP_FPS);
  fps_ = std::isfinite(fps) && fps > 0 ? fps : 0;
  chroma_ = chroma_sampling_of(capture_);
  if (!decode(first_)) throw InputError(path.string() + ": no decodable video frame; the file is empty or corrupt");
  first_pending_ = true;
  size_ = first_.image.size();
}

bool VideoFileSource::decode(Frame& frame) {
  cv::Mat image;  // fresh each time: the caller may keep the previous frame
  if (!capture_.read(image) || image.empty()) return false;
  if (image.depth() != CV_8U)
    throw InputError(path_.string() + ": decodes to a pixel depth other than 8 bits; convert it");
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  frame.image = image;
  frame.chroma = chroma_;
  frame.time = Nanos(std::llround(capture_.get(cv::CAP_PROP_POS_MSEC) * 1e6));
  const std::int64_t slot = fps_ > 0 ? std::llround(nanos_to_seconds(frame.time) * fps_) : 0;
  frame.index = std::max(slot, next_index_);
  next_index_ = frame.index + 1;
  return true;
}

bool VideoFileSource::read(Frame& frame) {
  if (first_pending_) {
    frame = std::move(first_);
    first_pending_ = false;
    return true;
  }
  if (!decode(frame)) return false;
  if (frame.image.size() != size_)
    throw InputError(path_.string() + ": frame " + std::to_string(frame.index) +
                     " changes size mid-stream; Lumar needs a fixed frame size");
  return true;
}

}  // namespace lumar::capture
