#include "lumar/calib/lighting_adapter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

double median(std::vector<double>& v) {
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Moves the published log ratio towards the smoothed one only once they differ by more
// than the hysteresis, and then follows it until it is nearly caught up. Returns whether
// it moved.
bool publish(double gap, bool& tracking, double threshold_log) {
  if (!tracking && gap > threshold_log) tracking = true;
  if (!tracking) return false;
  if (gap < 0.25 * threshold_log) tracking = false;
  return true;
}

}  // namespace

LightingAdapter::LightingAdapter(const LightingAdapterSettings& settings) : settings_(settings) {
  if (settings.cell_cols < 1 || settings.cell_rows < 1 || settings.time_constant_s < 0 || settings.hysteresis < 0 ||
      settings.min_cell_pixels < 1)
    throw InputError("lighting adapter: cells must be at least 1x1, times and hysteresis non-negative");
  reset();
}

void LightingAdapter::reset() {
  initialised_ = false;
  last_measurement_ = 0;
  ++version_;
  smooth_global_ = 0, published_global_ = 1, tracking_global_ = false;
  smooth_cells_ = cv::Mat::zeros(settings_.cell_rows, settings_.cell_cols, CV_64FC3);
  published_cells_ = cv::Mat::zeros(settings_.cell_rows, settings_.cell_cols, CV_64FC3);
  seen_ = cv::Mat::zeros(settings_.cell_rows, settings_.cell_cols, CV_8U);
  tracking_cells_ = cv::Mat::zeros(settings_.cell_rows, settings_.cell_cols, CV_8U);
}

int LightingAdapter::measured_cells() const { return cv::countNonZero(seen_); }

// Cells not seen yet: the median published change of the seen ones, per channel (log).
cv::Vec3d LightingAdapter::unseen_log() const {
  cv::Vec3d fill(0, 0, 0);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> seen;
    for (int k = 0; k < int(published_cells_.total()); ++k)
      if (seen_.at<uchar>(k)) seen.push_back(published_cells_.at<cv::Vec3d>(k)[c]);
    if (!seen.empty()) fill[c] = median(seen);
  }
  return fill;
}

cv::Mat LightingAdapter::cell_ratios() const {
  cv::Mat out(published_cells_.size(), CV_64FC3);
  const cv::Vec3d fill = unseen_log();
  for (int k = 0; k < int(out.total()); ++k) {
    const cv::Vec3d l = seen_.at<uchar>(k) ? published_cells_.at<cv::Vec3d>(k) : fill;
    out.at<cv::Vec3d>(k) = {std::exp(l[0]), std::exp(l[1]), std::exp(l[2])};
  }
  return out;
}

void LightingAdapter::update(const cv::Mat& observed, const cv::Mat& predicted, const cv::Mat& map_uv, Nanos time,
                             const cv::Mat& valid) {
  if (observed.size() != predicted.size() || observed.type() != CV_32FC3 || predicted.type() != CV_32FC3 ||
      map_uv.size() != observed.size() || map_uv.type() != CV_32FC2 ||
      (!valid.empty() && (valid.size() != observed.size() || valid.type() != CV_8UC1)))
    throw InputError(
        "lighting adapter: observed and predicted must be CV_32FC3, map_uv CV_32FC2 and valid CV_8UC1, all of one "
        "size");
  const int rows = settings_.cell_rows, cols = settings_.cell_cols;
  const double max_observed = settings_.max_observed > 0 ? settings_.max_observed : HUGE_VAL;
  std::vector<double> all;
  std::vector<cv::Vec3d> sum_observed(std::size_t(rows) * cols), sum_predicted(sum_observed.size());
  std::vector<int> count(sum_observed.size(), 0);
  for (int y = 0; y < observed.rows; ++y) {
    const cv::Vec3f* o = observed.ptr<cv::Vec3f>(y);
    const cv::Vec3f* p = predicted.ptr<cv::Vec3f>(y);
    const cv::Vec2f* uv = map_uv.ptr<cv::Vec2f>(y);
    const uchar* v = valid.empty() ? nullptr : valid.ptr<uchar>(y);
    for (int x = 0; x < observed.cols; ++x) {
      if ((v && !v[x]) || uv[x][0] < 0.f || uv[x][1] < 0.f) continue;
      const double sp = double(p[x][0]) + p[x][1] + p[x][2];
      if (!(sp >= 3 * settings_.min_predicted) || !std::isfinite(sp)) continue;
      // A clipped channel says only "at least this bright": where the map predicts that
      // much too, take it as unchanged; otherwise as the clipping level.
      cv::Vec3d seen;
      bool clipped = false;
      for (int c = 0; c < 3; ++c) {
        seen[c] = o[x][c];
        if (seen[c] >= max_observed) seen[c] = std::max(max_observed, double(p[x][c])), clipped = true;
      }
      if (!std::isfinite(seen[0] + seen[1] + seen[2])) continue;
      const int cx = std::clamp(int(uv[x][0] * cols), 0, cols - 1), cy = std::clamp(int(uv[x][1] * rows), 0, rows - 1);
      const std::size_t cell = std::size_t(cy) * cols + cx;
      sum_observed[cell] += seen;
      sum_predicted[cell] += cv::Vec3d(p[x][0], p[x][1], p[x][2]);
      ++count[cell];
      const double so = seen[0] + seen[1] + seen[2];
      if (!clipped && so > 0) all.push_back(std::log(so / sp));
    }
  }
  if (int(all.size()) < settings_.min_pixels) {
    last_measurement_ = 0;
    return;
  }
  const double global = median(all);
  last_measurement_ = std::exp(global);

  const double threshold = std::log1p(settings_.hysteresis);
  const bool first = !initialised_;
  const double dt = first ? 0.0 : std::max(0.0, nanos_to_seconds(time - last_time_));
  last_time_ = time;
  initialised_ = true;
  const double alpha = settings_.time_constant_s > 0 ? 1.0 - std::exp(-dt / settings_.time_constant_s) : 1.0;
  // The first measurement is taken as it is: there is nothing to flicker against.
  if (first) {
    smooth_global_ = global;
    published_global_ = std::exp(global);
  } else {
    smooth_global_ += alpha * (global - smooth_global_);
    const double published_log = std::log(published_global_);
    if (publish(std::abs(smooth_global_ - published_log), tracking_global_, threshold))
      published_global_ = std::exp(smooth_global_);
  }
  bool moved = false;
  const cv::Vec3d unseen = unseen_log();
  for (std::size_t k = 0; k < count.size(); ++k) {
    if (count[k] < settings_.min_cell_pixels) continue;
    cv::Vec3d measured;
    bool usable = true;
    for (int c = 0; c < 3; ++c) {
      // A channel that is black in the map has no ratio; a light that went out has a
      // tiny one, floored so that its log stays finite.
      if (!(sum_predicted[k][c] > 0)) usable = false;
      measured[c] = std::log(std::max(1e-3, sum_observed[k][c] / std::max(1e-30, sum_predicted[k][c])));
    }
    if (!usable) continue;
    cv::Vec3d& s = smooth_cells_.at<cv::Vec3d>(int(k));
    cv::Vec3d& published = published_cells_.at<cv::Vec3d>(int(k));
    if (!seen_.at<uchar>(int(k))) {
      // A cell coming into view starts from what it was assumed to be (the median
      // change), and moves only if it differs by more than the hysteresis.
      seen_.at<uchar>(int(k)) = 1;
      s = measured;
      published = unseen;
    } else {
      s += alpha * (measured - s);
    }
    const double gap =
        std::max({std::abs(s[0] - published[0]), std::abs(s[1] - published[1]), std::abs(s[2] - published[2])});
    bool tracking = tracking_cells_.at<uchar>(int(k)) != 0;
    if (publish(gap, tracking, threshold)) published = s, moved = true;
    tracking_cells_.at<uchar>(int(k)) = tracking ? 1 : 0;
  }
  if (moved) ++version_;
}

}  // namespace lumar::calib
