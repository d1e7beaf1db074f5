#pragma once
// Camera calibration from board views (checkerboard or ChArUco) that drops inconsistent views, reports the uncertainty
// of every intrinsic, a cross-validated error and how well the views cover the sensor.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lumar/calib/board_views.h"
#include "lumar/calib/camera_file.h"

namespace lumar::calib {

struct RobustCalibrationOptions {
  bool fix_k3 = false;      // CALIB_FIX_K3: k3 stays 0
  bool fix_aspect = false;  // CALIB_FIX_ASPECT_RATIO: fx = fy
  bool reject_outliers = true;
  // A view is an outlier when its RMS is above median + outlier_z * 1.4826 * MAD of the
  // views' RMS (a robust z-score; 3.5 is Iglewicz and Hoaglin's cut-off) AND above
  // outlier_floor_px, so that a clean set, whose views all sit near the noise level,
  // loses nothing to the spread of small numbers.
  double outlier_z = 3.5;
  double outlier_floor_px = 0.5;
  int min_views = 6;                         // never drop below this many views
  int holdout_splits = 10;                   // random half/half splits for the held-out error
  std::uint32_t seed = 1;                    // of those splits
  int coverage_cols = 8, coverage_rows = 6;  // grid over the sensor for the coverage fraction
  double min_coverage = 0.5;                 // warn below this occupied-cell fraction
  int min_orientations = 3;                  // warn below this many distinct board orientations
  double orientation_separation_deg = 15.0;  // board normals this far apart count as distinct
};

// Standard deviations of fx fy cx cy k1 k2 p1 p2 k3, in this order.
inline constexpr std::array<const char*, 9> kIntrinsicNames = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};

struct RejectedView {
  std::string name;
  double rms_px = 0;        // its RMS in the solve that rejected it
  double threshold_px = 0;  // the threshold it exceeded
  int round = 0;            // 1 = rejected after the first (plain) solve
};

struct RobustCalibrationResult {
  CameraFile camera;       // from the kept views; avg_reprojection_error = their RMS
  double initial_rms = 0;  // plain solve on all views
  std::vector<std::string> used_views;
  std::vector<double> per_view_rms;    // one per used view, final solve
  std::vector<RejectedView> rejected;  // in the order they were dropped
  std::vector<std::string> views_without_board;
  std::array<double, 9> std_dev{};  // kIntrinsicNames; 0 for a fixed parameter
  double holdout_rms = 0;           // mean over splits of the RMS on held-out views (solvePnP + projectPoints)
  double training_rms = 0;          // mean over the same splits of the training halves' RMS
  int holdout_splits = 0;
  double coverage = 0;                // fraction of grid cells holding a corner of a kept view
  int orientations = 0;               // distinct board orientations among kept views
  std::vector<std::string> warnings;  // one line each; poor coverage or diversity
};

// Throws InputError when fewer than 3 views hold the board (what the model needs).
// Rejection stops at options.min_views; the held-out error needs 6 views (else 0 splits).
RobustCalibrationResult calibrate_robust(const BoardViews& views, const RobustCalibrationOptions& options = {});

}  // namespace lumar::calib
