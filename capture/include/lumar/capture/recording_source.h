#pragma once
// Frames of a recording's video segments, in order, with the times of frames.csv.
#include <cstddef>
#include <filesystem>
#include <opencv2/videoio.hpp>
#include <vector>

#include "lumar/capture/frame_source.h"
#include "lumar/capture/recording_format.h"

namespace lumar::capture {

class RecordingReader;

class RecordingSource : public FrameSource {
 public:
  // `shutter_time`: what shutter_time() says (0: not known); a recording played as a
  // camera says its session's (open_frame_source).
  explicit RecordingSource(const RecordingReader& recording, Nanos shutter_time = 0);

  // InputError "<segment path>: truncated or corrupt video (decoded K of N frames)"
  // when a segment fails to open or yields fewer frames than frames.csv lists.
  bool read(Frame& frame) override;
  cv::Size frame_size() const override { return video_.size; }
  double nominal_fps() const override { return video_.fps; }
  std::string describe() const override { return "recording " + dir_.string(); }
  Nanos shutter_time() const override { return shutter_; }

 private:
  void open_segment(int segment);
  [[noreturn]] void fail_truncated() const;

  std::filesystem::path dir_;
  RecordingSettings video_;
  std::vector<FrameEntry> frames_;
  std::size_t next_ = 0;
  Nanos shutter_ = 0;

  cv::VideoCapture capture_;
  int segment_ = -1;  // the open segment
  std::filesystem::path segment_file_;
  int segment_rows_ = 0;   // frames.csv rows for it
  int decoded_ = 0;        // frames decoded from it so far
  bool jpeg_ = false;      // MJPEG: capture_ hands over each frame's JPEG bytes
  ChromaSampling chroma_;  // its decoder's pixel format's, or its first JPEG's
};

}  // namespace lumar::capture
