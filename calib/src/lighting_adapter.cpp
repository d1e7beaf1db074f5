#include "lumar/calib/lighting_adapter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

double median(std::vector<float>& v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Moves the published log ratio towards the smoothed one only once they differ by more
// than the hysteresis, and then follows it until it is nearly caught up.
void publish(double smoothed_log, double& published_log, bool& tracking, double threshold_log) {
  const double gap = std::abs(smoothed_log - published_log);
  if (!tracking && gap > threshold_log) tracking = true;
  if (tracking) {
    published_log = smoothed_log;
    if (gap < 0.25 * threshold_log) tracking = false;
  }
}

}  // namespace

LightingAdapter::LightingAdapter(const LightingAdapterSettings& settings) : settings_(settings) {
  if (settings.grid_cols < 1 || settings.grid_rows < 1 || settings.time_constant_s < 0 || settings.hysteresis < 0)
    throw InputError("lighting adapter: grid must be at least 1x1 and times and hysteresis non-negative");
  reset();
}

void LightingAdapter::reset() {
  initialised_ = false;
  last_measurement_ = 0;
  smooth_global_ = 0, published_global_ = 1, tracking_global_ = false;
  smooth_regions_ = cv::Mat::zeros(settings_.grid_rows, settings_.grid_cols, CV_64F);
  published_regions_ = cv::Mat::ones(settings_.grid_rows, settings_.grid_cols, CV_64F);
  tracking_regions_ = cv::Mat::zeros(settings_.grid_rows, settings_.grid_cols, CV_8U);
}

void LightingAdapter::update(const cv::Mat& observed, const cv::Mat& predicted, Nanos time, const cv::Mat& valid) {
  if (observed.size() != predicted.size() || observed.type() != predicted.type() ||
      (observed.type() != CV_32FC3 && observed.type() != CV_32FC1) ||
      (!valid.empty() && (valid.size() != observed.size() || valid.type() != CV_8UC1)))
    throw InputError("lighting adapter: observed, predicted and valid images must be float images of one size");
  const int channels = observed.channels();
  const int gr = settings_.grid_rows, gc = settings_.grid_cols;
  std::vector<float> all;
  std::vector<std::vector<float>> cells(std::size_t(gr) * gc);
  for (int y = 0; y < observed.rows; ++y) {
    const float* o = observed.ptr<float>(y);
    const float* p = predicted.ptr<float>(y);
    const uchar* v = valid.empty() ? nullptr : valid.ptr<uchar>(y);
    const int cell_row = std::min(gr - 1, y * gr / observed.rows);
    for (int x = 0; x < observed.cols; ++x) {
      if (v && !v[x]) continue;
      float so = 0, sp = 0;
      bool clipped = false;
      for (int c = 0; c < channels; ++c) {
        so += o[x * channels + c], sp += p[x * channels + c];
        if (settings_.max_observed > 0 && o[x * channels + c] >= settings_.max_observed) clipped = true;
      }
      if (clipped || sp < settings_.min_predicted * channels || !(so > 0.f) || !std::isfinite(so)) continue;
      const float r = std::log(so / sp);
      all.push_back(r);
      cells[std::size_t(cell_row) * gc + std::min(gc - 1, x * gc / observed.cols)].push_back(r);
    }
  }
  if (int(all.size()) < settings_.min_pixels) {
    last_measurement_ = 0;
    return;
  }
  const double global = median(all);
  last_measurement_ = std::exp(global);
  cv::Mat measured(gr, gc, CV_64F);
  for (int k = 0; k < gr * gc; ++k)
    measured.at<double>(k / gc, k % gc) = int(cells[k].size()) >= settings_.min_pixels ? median(cells[k]) : global;

  const double threshold = std::log1p(settings_.hysteresis);
  if (!initialised_) {
    // The first measurement is taken as it is: there is nothing to flicker against.
    initialised_ = true;
    smooth_global_ = global;
    measured.copyTo(smooth_regions_);
    published_global_ = std::exp(global);
    cv::exp(measured, published_regions_);
    last_time_ = time;
    return;
  }
  const double dt = std::max(0.0, nanos_to_seconds(time - last_time_));
  last_time_ = time;
  const double alpha = settings_.time_constant_s > 0 ? 1.0 - std::exp(-dt / settings_.time_constant_s) : 1.0;
  smooth_global_ += alpha * (global - smooth_global_);
  double published_log = std::log(published_global_);
  publish(smooth_global_, published_log, tracking_global_, threshold);
  published_global_ = std::exp(published_log);
  for (int r = 0; r < gr; ++r)
    for (int c = 0; c < gc; ++c) {
      double& s = smooth_regions_.at<double>(r, c);
      s += alpha * (measured.at<double>(r, c) - s);
      double pl = std::log(published_regions_.at<double>(r, c));
      bool tracking = tracking_regions_.at<uchar>(r, c) != 0;
      publish(s, pl, tracking, threshold);
      published_regions_.at<double>(r, c) = std::exp(pl);
      tracking_regions_.at<uchar>(r, c) = tracking ? 1 : 0;
    }
}

}  // namespace lumar::calib
