#include "lumar/capture/recording_source.h"

#include "lumar/base/error.h"
#include "lumar/capture/jpeg_decoder.h"
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
  // FFmpeg reads both codecs' files. An MJPEG segment's frames come out as the JPEG bytes
  // each was stored as (raw mode) and are decoded by libjpeg, as the live camera's are:
  // FFmpeg's own decoding converts colour through swscale and darkens them by 0.4–0.9
  // levels (jpeg_decoder.h). OpenCV's MJPEG reader decodes with libjpeg too, but lets it
  // print "Corrupt JPEG data" for the frames OpenCV 4.6's writer cut short (opencv#24171,
  // about one in 32; their last 16×16 block decodes 2–3 levels off).
  std::error_code ec;
  if (!std::filesystem::exists(segment_file_, ec) || !capture_.open(segment_file_.string(), cv::CAP_FFMPEG))
    fail_truncated();
  jpeg_ = video_.codec == "mjpeg";
  if (jpeg_ && !capture_.set(cv::CAP_PROP_FORMAT, -1))
    throw RuntimeError(segment_file_.string() + ": OpenCV's FFmpeg reader cannot hand over the stored JPEG frames");
  if (!jpeg_) chroma_ = chroma_sampling_of(capture_);  // MJPEG: from its first frame's header (read)
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
  if (jpeg_) {
    const cv::Mat packet = image;  // the JPEG's bytes, kept while they are read
    const std::span<const std::uint8_t> bytes(packet.ptr<std::uint8_t>(), packet.total() * packet.elemSize());
    if (decoded_ == 0) chroma_ = chroma_sampling_of_jpeg(bytes);
    image = decode_jpeg(bytes).bgr;
    if (image.empty()) fail_truncated();
  }
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
