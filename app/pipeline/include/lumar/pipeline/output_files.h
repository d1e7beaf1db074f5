#pragma once
// The overlay's outputs, whole or not at all (lumar/base/output_file.h): a video, a
// folder of PNG frames, a contact sheet.
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lumar/base/output_file.h"

namespace lumar::pipeline {

// RuntimeError (exit 1) when the video cannot be created, or when at commit() it does
// not hold every frame written (a full disk): the final name is then never taken.
class VideoOutput {
 public:
  VideoOutput(std::filesystem::path path, double fps, cv::Size size);
  ~VideoOutput();
  void write(const cv::Mat& bgr8);
  void commit();
  const std::string& codec() const { return codec_; }

 private:
  OutputFile file_;
  cv::VideoWriter writer_;
  std::string codec_;
  std::int64_t frames_ = 0;
};

class FramesOutput {
 public:
  explicit FramesOutput(std::filesystem::path dir);     // the folder must not exist yet
  void write(std::int64_t index, const cv::Mat& bgr8);  // frame-000123.png
  void commit();

 private:
  OutputFolder folder_;
};

// What `lumar overlay` writes of its frames, whichever path made them: a video, a folder
// of PNG frames, and a contact sheet of eight frames spread evenly over the run (which
// needs the run's length, `expected_frames`). Each appears whole at commit() or not at all.
struct OverlayOutputSettings {
  std::string video, frames_dir, contact_sheet;  // empty: not written
  double fps = 30;
  cv::Size size;
  std::int64_t expected_frames = 0;
};

class OverlayOutputs {
 public:
  // InputError for a bad path (a contact sheet that is not .png, a folder that exists).
  explicit OverlayOutputs(const OverlayOutputSettings& settings);
  void write(std::int64_t index, const cv::Mat& bgr8);
  void commit();
  // " -> out.mp4 (avc1)", or "" without a video.
  std::string describe() const;

 private:
  OverlayOutputSettings settings_;
  std::optional<VideoOutput> video_;
  std::optional<FramesOutput> frames_;
  std::vector<std::pair<std::int64_t, cv::Mat>> sheet_;
  std::int64_t seen_ = 0;
};

// Tiles frames (each scaled to `tile_width`, aspect kept) into rows of `columns`, with
// the frame index in a corner, and writes the PNG atomically.
void write_contact_sheet(const std::filesystem::path& png, const std::vector<std::pair<std::int64_t, cv::Mat>>& frames,
                         int columns = 4, int tile_width = 320);

}  // namespace lumar::pipeline
