#pragma once
// Calibration views sampled from a video file (`lumar calibrate --video FILE --every N`).
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "lumar/calib/checkerboard_calibration.h"

namespace lumar::calib {

struct NamedImage {
  std::string name;  // "FILE#frame" for video frames
  cv::Mat image;
};

// Every `every`-th frame of the video (frame 0 first), at most max_frames. Throws
// InputError when the file is missing, cannot be decoded, or `every` < 1.
std::vector<NamedImage> sample_video_frames(const std::filesystem::path& video, int every, int max_frames = 500);

// detect_checkerboard_views for images already in memory (same checks and errors).
CheckerboardViews detect_checkerboard_views(const std::vector<NamedImage>& images, cv::Size inner_corners,
                                            double square_size_m);

}  // namespace lumar::calib
