#pragma once
// Calibration views sampled from any frame source: a video file, an image sequence, a
// recording or a live camera (`lumar calibrate --source SPEC --every N`).
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "lumar/calib/checkerboard_calibration.h"
#include "lumar/capture/frame_source.h"

namespace lumar::calib {

struct NamedImage {
  std::string name;  // "FILE#frame" for video frames
  cv::Mat image;
};

// Every `every`-th frame the source delivers (frame 0 first), at most max_frames; named
// "<source>#<frame index>". Throws InputError when `every` < 1 or no frame arrives.
std::vector<NamedImage> sample_frames(capture::FrameSource& source, int every, int max_frames = 500);

// detect_checkerboard_views for images already in memory (same checks and errors).
CheckerboardViews detect_checkerboard_views(const std::vector<NamedImage>& images, cv::Size inner_corners,
                                            double square_size_m);

}  // namespace lumar::calib
