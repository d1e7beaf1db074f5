#include "lumar/capture/recording_source.h"

#include "lumar/base/error.h"
#include "lumar/capture/recording_reader.h"

namespace lumar::capture {

RecordingSource::RecordingSource(const RecordingReader& recording, Nanos shutter_time)
    : dir_(recording.directory()), video_(recording.video()), frames_(recording.frames()), shutter_(shutter_time) {}

void RecordingSource::fail_truncated() const {
  throw InputError(segment_file_.string() + ": truncated or corrupt video (decoded " + std::to_string(decoded_) +
                   " of " + std::to_string(segment_rows_) +
                   " frames); the recording is damaged, replay only the frames before it");
}

void RecordingSource::open_segment(int segment) {
  capture_.release();
  segment_ = segment;
  segment_file_ = segment_path(dir_, video_.codec, segment);
  segment_rows_ = 0;
  for (std::size_t i = next_; i < frames_.size() && frames_[i].segment == segment; ++i) ++segment_rows_;
  decoded_ = 0;
  // FFmpeg for both codecs. OpenCV's own MJPEG reader converts colour slightly more
  // exactly (mean error 0.49 levels at quality 95, against 0.83), but OpenCV 4.6's MJPEG
  // encoder cuts the last bytes of about one frame in 32 (opencv#24171) and libjpeg then
  // prints "Corrupt JPEG data" on stderr for each; FFmpeg decodes them silently.
  const int api = cv::CAP_FFMPEG;
  std::error_code ec;
  if (!std::filesystem::exists(segment_file_, ec) || !capture_.open(segment_file_.string(), api)) fail_truncated();
  chroma_ = chroma_sampling_of(capture_);
}

bool RecordingSource::read(Frame& frame) {
  if (next_ >= frames_.size()) {
    capture_.release();
    return false;
  }
  const FrameEntry& entry = frames_[next_];
  if (entry.segment != segment_) open_segment(entry.segment);
  cv::Mat image;  // fresh each time: the caller may keep the previous frame
  if (!capture_.read(image) || image.empty()) fail_truncated();
  ++decoded_;
  if (image.size() != video_.size || image.type() != CV_8UC3)
    throw InputError(segment_file_.string() + ": frame " + std::to_string(decoded_ - 1) + " decodes as " +
                     std::to_string(image.cols) + "x" + std::to_string(image.rows) + ", but session.json says " +
                     std::to_string(video_.size.width) + "x" + std::to_string(video_.size.height) +
                     " BGR; the recording is damaged");
  frame.image = image;
  frame.chroma = chroma_;
  frame.time = entry.time;
  frame.index = entry.index;
  ++next_;
  return true;
}

}  // namespace lumar::capture
