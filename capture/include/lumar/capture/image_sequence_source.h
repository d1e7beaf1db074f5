#pragma once
// Frames from numbered image files: a folder (every .png .jpg .jpeg .bmp .tif .tiff
// .ppm in it) or a glob ("shots/frame-*.png"), in natural order (frame-2 before
// frame-10). Times come from a timestamp table or a fixed rate:
//
//   timestamps CSV:  file,time_ns        header line, then one row per frame; `file`
//                    frame-000.png,0     relative to the images' folder; the rows give
//                    frame-001.png,33366667   the order; times strictly increase
//
// Without a table, frame i is at i / fps. Frame::index is the position in the sequence.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lumar/capture/frame_source.h"

namespace lumar::capture {

struct ImageSequenceSettings {
  std::string pattern;               // folder or glob
  std::filesystem::path timestamps;  // CSV as above; empty: use fps
  double fps = 0;                    // > 0 when there is no timestamp table
};

class ImageSequenceSource final : public FrameSource {
 public:
  // Lists the files and decodes the first one. InputError naming the folder, glob,
  // table or file for: no images, a missing file, a bad table row, times that do not
  // increase, no fps and no table, an undecodable first image.
  explicit ImageSequenceSource(ImageSequenceSettings settings);

  // InputError naming the file when an image does not decode or changes size.
  bool read(Frame& frame) override;
  cv::Size frame_size() const override { return size_; }
  double nominal_fps() const override { return fps_; }
  std::string describe() const override { return "image sequence " + settings_.pattern; }

  const std::vector<std::filesystem::path>& files() const { return files_; }
  const std::vector<Nanos>& times() const { return times_; }

 private:
  // The i-th image; `chroma`, when given, gets a JPEG's sampling (1×1 for other formats).
  cv::Mat decode(std::size_t i, ChromaSampling* chroma = nullptr) const;

  ImageSequenceSettings settings_;
  std::vector<std::filesystem::path> files_;
  std::vector<Nanos> times_;
  cv::Size size_;
  double fps_ = 0;
  std::size_t next_ = 0;
  // The first image, decoded to learn the size, kept for the first read().
  cv::Mat first_;
  ChromaSampling first_chroma_;
};

}  // namespace lumar::capture
