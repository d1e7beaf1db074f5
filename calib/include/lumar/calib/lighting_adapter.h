#pragma once
// Keeps the environment map's lighting current while the overlay runs: compares what
// the camera sees of the room (live video, linearised) with what the map predicts for
// the same view (the proxy room textured from the map's capture point,
// gl::Renderer::render_room_radiance), and estimates how each part of the map has
// changed, per colour channel: the map's directions are cut into a coarse lat-long grid
// of cells, and each cell's ratio is Σ observed / Σ predicted over the pixels whose light
// comes from it. A sum of light, not a median: a lamp that goes out is a few pixels of a
// cell but most of its power, and the power is what lights the objects.
//
// Estimates are smoothed over time and published with hysteresis: changes smaller than
// a threshold never reach the lighting, so it does not flicker, while a real change is
// followed smoothly until it has been caught up. Cells the camera has never seen follow
// the median change of those it has (a dimmer on every light), and stay at 1 before any.
#include <cstdint>
#include <opencv2/core.hpp>

#include "lumar/base/time.h"

namespace lumar::calib {

struct LightingAdapterSettings {
  double time_constant_s = 0.5;        // exponential smoothing of the measured ratios
  double hysteresis = 0.05;            // relative change needed before a published ratio moves
  int cell_cols = 32, cell_rows = 16;  // cells over the map's directions (lat-long)
  int min_cell_pixels = 8;             // a cell with fewer usable pixels in a frame is not measured in it
  int min_pixels = 200;                // a frame with fewer usable pixels is skipped
  double min_predicted = 1e-4;         // predicted radiance below this is not compared (no room there)
  double max_observed = 0.0;           // observed radiance at or above this is clipped (0 = no limit)
};

class LightingAdapter {
 public:
  explicit LightingAdapter(const LightingAdapterSettings& settings = {});

  // One frame: `observed` is the video's linear radiance (CV_32FC3, undistorted, divided
  // by exposure), `predicted` the map's prediction for the same view and size, and
  // `map_uv` (CV_32FC2) where each pixel's prediction comes from in the map, (u, v) in
  // [0, 1], negative for none. `valid` (optional CV_8UC1) excludes pixels (virtual
  // objects, people...). Throws InputError on mismatched sizes or types.
  void update(const cv::Mat& observed, const cv::Mat& predicted, const cv::Mat& map_uv, Nanos time,
              const cv::Mat& valid = cv::Mat());

  // The published scale of each cell's radiance, per channel in the images' order:
  // cell_rows x cell_cols CV_64FC3, row 0 at the map's top.
  cv::Mat cell_ratios() const;
  // Incremented whenever a published cell ratio moves.
  std::uint64_t version() const { return version_; }
  // How many cells have been measured at least once.
  int measured_cells() const;
  // The room's overall brightness against the map (median of per-pixel ratios, smoothed,
  // with the same hysteresis): what the panel and the summary report. 1 until measured.
  double global_ratio() const { return published_global_; }
  // The last frame's raw (unsmoothed) global measurement; 0 when it had no usable pixel.
  double last_measurement() const { return last_measurement_; }
  bool has_estimate() const { return initialised_; }
  const LightingAdapterSettings& settings() const { return settings_; }
  void reset();

 private:
  cv::Vec3d unseen_log() const;

  LightingAdapterSettings settings_;
  bool initialised_ = false;
  Nanos last_time_ = 0;
  double last_measurement_ = 0;
  std::uint64_t version_ = 0;
  // Log-domain smoothed values and what is published, with whether each is catching up.
  double smooth_global_ = 0, published_global_ = 1;
  bool tracking_global_ = false;
  cv::Mat smooth_cells_, published_cells_;  // CV_64FC3, log ratios
  cv::Mat seen_, tracking_cells_;           // CV_8U per cell
};

}  // namespace lumar::calib
