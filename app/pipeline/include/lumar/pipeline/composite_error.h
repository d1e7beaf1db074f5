#pragma once
// The composite against the frame the camera would have seen (docs/ground_truth.md,
// "The measure"): in linear light, after a 5×5 box filter so that noise averages out,
// over three regions of each frame, from the truth's object mask:
//  - object: the mask eroded by 2 px;
//  - edge: the 3 px band around the outline (1 px outside, 2 px inside, the rest of the mask);
//  - shadow: room pixels (outside the mask dilated by 1 px) where the truth differs from
//    the empty room by more than 1 %.
// Each error is Σ|composite − truth| / Σ truth over its region and the three channels, in
// percent; noise_ratio is the RMS of the high-pass residual (the image less its 5×5 box
// filter) in the object region, composite over truth. The same errors between the truth
// and its other-seed twin are the noise floor, the best any composite can do.
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

#include "lumar/calib/camera_response.h"

namespace lumar::pipeline {

struct CompositeRegions {
  cv::Mat object, edge, shadow;  // CV_8UC1, 255 inside
};

// The regions of one frame: `mask` (CV_8UC1, 255 where an object is seen), the truth
// and the empty room both linear (CV_32FC3, box-filtered).
CompositeRegions composite_regions(const cv::Mat& mask, const cv::Mat& truth_linear, const cv::Mat& empty_linear);

struct CompositeError {
  int frames = 0;
  std::array<std::int64_t, 3> pixels{};                 // object, edge, shadow, over every frame
  double object_err = 0, edge_err = 0, shadow_err = 0;  // percent of the region's mean truth
  double noise_ratio = 0;
  double noise_floor_object_err = 0, noise_floor_edge_err = 0, noise_floor_shadow_err = 0;
  // Isolated dark pixels of the composite inside the mask (below a quarter of their 3×3
  // median, full resolution) that the truth does not have: an open scan's holes.
  std::int64_t specks = 0;
};

class CompositeErrorMeter {
 public:
  // `response`: how the video's 8-bit values map to linear light (the session's).
  explicit CompositeErrorMeter(const calib::CameraResponse& response);

  // One frame, every image CV_8UC3 BGR in the composite's (undistorted) geometry:
  // the composite, its truth, the other-seed truth and the empty room (as the sensor saw
  // it, with the truth's noise: the video before its compression); the mask CV_8UC1.
  void add(const cv::Mat& composite, const cv::Mat& truth, const cv::Mat& other_seed, const cv::Mat& empty,
           const cv::Mat& mask);
  CompositeError result() const;

  // 8-bit BGR to linear CV_32FC3 through the response.
  cv::Mat linear(const cv::Mat& bgr8) const;

 private:
  struct Sums {
    double difference = 0, truth = 0;
  };
  std::array<cv::Mat, 3> lut_;                 // per channel, 256 entries
  std::array<Sums, 3> composite_{}, floor_{};  // per region
  std::array<std::int64_t, 3> pixels_{};
  double residual_composite_ = 0, residual_truth_ = 0;
  std::int64_t specks_ = 0;
  int frames_ = 0;
};

}  // namespace lumar::pipeline
