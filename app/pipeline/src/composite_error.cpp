#include "lumar/pipeline/composite_error.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace lumar::pipeline {

namespace {

const cv::Size kBox(5, 5);

cv::Mat box(const cv::Mat& image) {
  cv::Mat out;
  cv::blur(image, out, kBox, cv::Point(-1, -1), cv::BORDER_REFLECT);
  return out;
}

// Σ|a − b| and Σ b over the region's pixels and channels.
void accumulate(const cv::Mat& a, const cv::Mat& b, const cv::Mat& region, double& difference, double& truth) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar sd = cv::sum(d.setTo(0, ~region)), sb = cv::sum(b.clone().setTo(0, ~region));
  difference += sd[0] + sd[1] + sd[2];
  truth += sb[0] + sb[1] + sb[2];
}

double percent(double difference, double truth) { return truth > 0 ? 100.0 * difference / truth : 0.0; }

}  // namespace

CompositeRegions composite_regions(const cv::Mat& mask, const cv::Mat& truth_linear, const cv::Mat& empty_linear) {
  CV_Assert(mask.type() == CV_8UC1 && truth_linear.type() == CV_32FC3 && empty_linear.type() == CV_32FC3);
  CompositeRegions r;
  // Distances between pixel centres: inside, to the nearest pixel outside; outside, to the
  // nearest pixel inside (1 next to the outline, which runs half a pixel from each).
  cv::Mat inside, outside;
  cv::distanceTransform(mask, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(~mask, outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  r.object = inside > 2.5f;                        // more than 2 px in from the outline
  const cv::Mat grown = mask | (outside <= 1.5f);  // up to 1 px out
  r.edge = grown & ~r.object;
  // Changed by more than 1 % in any channel, outside the objects.
  cv::Mat difference, threshold;
  cv::absdiff(truth_linear, empty_linear, difference);
  threshold = empty_linear * 0.01;
  cv::Mat changed;
  cv::compare(difference, threshold, changed, cv::CMP_GT);
  std::vector<cv::Mat> channels;
  cv::split(changed, channels);
  r.shadow = (channels[0] | channels[1] | channels[2]) & ~grown;
  return r;
}

CompositeErrorMeter::CompositeErrorMeter(const calib::CameraResponse& response) {
  for (int c = 0; c < 3; ++c) {
    lut_[size_t(c)] = cv::Mat(1, 256, CV_32FC1);
    for (int v = 0; v < 256; ++v) lut_[size_t(c)].at<float>(v) = response(c, v);
  }
}

cv::Mat CompositeErrorMeter::linear(const cv::Mat& bgr8) const {
  CV_Assert(bgr8.type() == CV_8UC3);
  cv::Mat out(bgr8.size(), CV_32FC3);
  for (int y = 0; y < bgr8.rows; ++y) {
    const auto* in = bgr8.ptr<cv::Vec3b>(y);
    auto* o = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < bgr8.cols; ++x)
      for (int c = 0; c < 3; ++c) o[x][c] = lut_[size_t(c)].at<float>(in[x][c]);
  }
  return out;
}

namespace {

// Dark specks: pixels inside the mask (with their eight neighbours) below a quarter of
// the median of their 3×3 neighbourhood in luminance, at full resolution, where the
// truth's pixel is not one: what a ray into a hole of an open scan makes. Luminance, not
// one channel: a codec that shares chroma among pixels (4:2:0) moves a single channel of
// a pixel with its neighbours' colour, but keeps each pixel's own luma.
std::int64_t count_specks(const cv::Mat& composite, const cv::Mat& truth, const cv::Mat& mask) {
  const auto dark = [](const cv::Mat& linear) {
    cv::Mat g, median;
    cv::transform(linear, g, cv::Matx13f(0.0722f, 0.7152f, 0.2126f));  // B, G, R: Rec. 709's luminance
    cv::medianBlur(g, median, 3);
    return g < 0.25 * median;
  };
  cv::Mat inside;
  cv::erode(mask, inside, cv::Mat());
  return cv::countNonZero(dark(composite) & ~dark(truth) & inside);
}

}  // namespace

void CompositeErrorMeter::add(const cv::Mat& composite, const cv::Mat& truth, const cv::Mat& other_seed,
                              const cv::Mat& empty, const cv::Mat& mask) {
  const cv::Mat c_raw = linear(composite), t_raw = linear(truth);
  const cv::Mat c = box(c_raw), t = box(t_raw), o = box(linear(other_seed)), e = box(linear(empty));
  const CompositeRegions regions = composite_regions(mask, t, e);
  const std::array<const cv::Mat*, 3> masks{&regions.object, &regions.edge, &regions.shadow};
  for (std::size_t k = 0; k < 3; ++k) {
    accumulate(c, t, *masks[k], composite_[k].difference, composite_[k].truth);
    accumulate(o, t, *masks[k], floor_[k].difference, floor_[k].truth);
    pixels_[k] += cv::countNonZero(*masks[k]);
  }
  specks_ += count_specks(c_raw, t_raw, mask);
  // Noise: what the box filter takes away, in the object region.
  cv::Mat rc = c_raw - c, rt = t_raw - t;
  rc = rc.mul(rc);
  rt = rt.mul(rt);
  const cv::Scalar sc = cv::sum(rc.setTo(0, ~regions.object)), st = cv::sum(rt.setTo(0, ~regions.object));
  residual_composite_ += sc[0] + sc[1] + sc[2];
  residual_truth_ += st[0] + st[1] + st[2];
  ++frames_;
}

CompositeError CompositeErrorMeter::result() const {
  CompositeError r;
  r.frames = frames_;
  r.pixels = pixels_;
  r.object_err = percent(composite_[0].difference, composite_[0].truth);
  r.edge_err = percent(composite_[1].difference, composite_[1].truth);
  r.shadow_err = percent(composite_[2].difference, composite_[2].truth);
  r.noise_floor_object_err = percent(floor_[0].difference, floor_[0].truth);
  r.noise_floor_edge_err = percent(floor_[1].difference, floor_[1].truth);
  r.noise_floor_shadow_err = percent(floor_[2].difference, floor_[2].truth);
  r.specks = specks_;
  r.noise_ratio = residual_truth_ > 0 ? std::sqrt(residual_composite_ / residual_truth_) : 0.0;
  return r;
}

}  // namespace lumar::pipeline
