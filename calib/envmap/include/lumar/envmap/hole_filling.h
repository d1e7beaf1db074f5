#pragma once
// What a stitched map does where the sweep saw nothing (often the floor under the
// camera): fill it plausibly from its border, and show where and how often the sphere
// was covered.
#include <filesystem>
#include <opencv2/core.hpp>

#include "lumar/scene/envmap.h"

namespace lumar::calib {

// Push-pull (Gortler et al. 1996): averages the known pixels down a pyramid, then fills
// each unknown pixel from the coarsest level that knows its neighbourhood, smoothly
// (bilinear up-sampling, wrapping in azimuth). `known` is CV_8UC1 or any type compared
// with 0, map size. Known pixels are left untouched. Returns how many pixels were filled.
int fill_holes_push_pull(EnvironmentMap& map, const cv::Mat& known);

// Coverage as a picture (CV_8UC3, BGR, map size): holes (count 0) magenta, covered
// pixels grey, brighter the more frames saw them (saturating at 8).
cv::Mat coverage_image(const cv::Mat& coverage_count);

// A contact sheet of the map, tone-mapped for viewing: the map at -4, 0 and +4 stops
// around an exposure that puts its median luminance at 18 % grey, one above the other,
// sRGB 8-bit (CV_8UC3, BGR). With a non-empty coverage count, filled holes are hatched.
cv::Mat contact_sheet(const EnvironmentMap& map, const cv::Mat& coverage_count = cv::Mat());

}  // namespace lumar::calib
