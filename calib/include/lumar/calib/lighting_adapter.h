#pragma once
// Keeps the environment map's lighting current while the overlay runs: compares what
// the camera sees of the room (live video, linearised) with what the map predicts for
// the same view (the proxy room textured from the map's capture point, e.g.
// gl::Renderer::render_room_radiance), and estimates how much brighter or darker the
// room has become, globally and per image region. Estimates are robust (median of log
// ratios over well-exposed pixels), smoothed over time, and published with hysteresis:
// changes smaller than a threshold never reach the lighting, so it does not flicker,
// while a real change is followed smoothly until it has been caught up.
#include <opencv2/core.hpp>

#include "lumar/base/time.h"

namespace lumar::calib {

struct LightingAdapterSettings {
  double time_constant_s = 0.5;      // exponential smoothing of the measured ratio
  double hysteresis = 0.05;          // relative change needed before the published ratio moves
  int grid_cols = 4, grid_rows = 3;  // regions of the image with their own ratio
  int min_pixels = 400;              // a region with fewer usable pixels uses the global ratio
  double min_predicted = 1e-4;       // predicted radiance below this is not compared (no room there)
  double max_observed = 0.0;         // observed radiance at or above this is clipped (0 = no limit)
};

class LightingAdapter {
 public:
  explicit LightingAdapter(const LightingAdapterSettings& settings = {});

  // One frame: `observed` is the video's linear radiance (CV_32FC3 or CV_32FC1,
  // undistorted, divided by exposure), `predicted` the map's prediction for the same view
  // and size. `valid` (optional CV_8UC1) excludes pixels (virtual objects, people...).
  // Throws InputError on mismatched sizes or types.
  void update(const cv::Mat& observed, const cv::Mat& predicted, Nanos time, const cv::Mat& valid = cv::Mat());

  // Scale for the map's radiance (1 until the first usable frame).
  double global_ratio() const { return published_global_; }
  // Per-region scales, grid_rows x grid_cols CV_64FC1.
  cv::Mat region_ratios() const { return published_regions_.clone(); }
  // The last frame's raw (unsmoothed) global measurement; 0 when it had no usable pixel.
  double last_measurement() const { return last_measurement_; }
  bool has_estimate() const { return initialised_; }
  void reset();

 private:
  LightingAdapterSettings settings_;
  bool initialised_ = false;
  Nanos last_time_ = 0;
  double last_measurement_ = 0;
  // Log-domain smoothed values and what is published, with whether each is catching up.
  double smooth_global_ = 0, published_global_ = 1;
  bool tracking_global_ = false;
  cv::Mat smooth_regions_, published_regions_, tracking_regions_;
};

}  // namespace lumar::calib
