#include "lumar/sim/video_faults.h"

#include <opencv2/imgproc.hpp>

namespace lumar::sim {

cv::Mat occluder_texture(cv::Size frame) {
  cv::RNG rng(12345);
  cv::Mat small(std::max(8, frame.height / 24), std::max(8, frame.width / 48), CV_32FC3);
  rng.fill(small, cv::RNG::UNIFORM, cv::Scalar::all(0.02), cv::Scalar::all(0.25));
  cv::Mat panel;
  cv::resize(small, panel, cv::Size(frame.width / 2, frame.height), 0, 0, cv::INTER_CUBIC);
  return cv::max(panel, 0.01);
}

void apply_video_faults(const VideoFaults& faults, int k, const cv::Mat& panel, cv::Mat& radiance) {
  if (faults.textureless.contains(k)) radiance.setTo(cv::mean(radiance));
  if (faults.occluder.contains(k) && !panel.empty()) {
    // From just off the left edge to just off the right, over the range.
    const double u = (k - faults.occluder.from + 0.5) / faults.occluder.count;
    const int x0 = int(std::lround(-panel.cols + u * (radiance.cols + panel.cols)));
    const int a = std::max(0, x0), b = std::min(radiance.cols, x0 + panel.cols);
    if (b > a) {
      cv::Mat src;
      cv::resize(panel, src, cv::Size(panel.cols, radiance.rows));
      src(cv::Range::all(), cv::Range(a - x0, b - x0)).copyTo(radiance(cv::Range::all(), cv::Range(a, b)));
    }
  }
}

}  // namespace lumar::sim
