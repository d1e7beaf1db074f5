#pragma once
// Frames of any video file OpenCV can decode (through FFmpeg), timed by the
// container's presentation timestamps (CAP_PROP_POS_MSEC), converted to ns.
//
// Only coded pictures are frames. Frame::index is the picture's slot at the
// nominal rate, round(pts * fps) (kept increasing), so a gap in the indices marks
// slots where the file holds no new picture — e.g. AVI "null" chunks, which
// repeat the previous picture: tree.avi has 444 slots but only 68 pictures.
#include <cstdint>
#include <filesystem>
#include <opencv2/videoio.hpp>

#include "lumar/capture/frame_source.h"

namespace lumar::capture {

class VideoFileSource : public FrameSource {
 public:
  // InputError naming the file when it is missing or has no decodable frame.
  explicit VideoFileSource(const std::filesystem::path& path);

  bool read(Frame& frame) override;
  cv::Size frame_size() const override { return size_; }
  double nominal_fps() const override { return fps_; }  // as the container says; 0 if unknown
  std::string describe() const override { return "video file " + path_.string(); }

 private:
  bool decode(Frame& frame);

  std::filesystem::path path_;
  cv::VideoCapture capture_;
  cv::Size size_;
  double fps_ = 0;
  std::int64_t next_index_ = 0;  // lowest index the next frame may have
  ChromaSampling chroma_;        // the decoder's pixel format's
  Frame first_;                  // decoded in the constructor to prove the file decodes
  bool first_pending_ = false;
};

}  // namespace lumar::capture
