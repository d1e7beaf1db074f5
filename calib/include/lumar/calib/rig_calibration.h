#pragma once
// Tracker-to-camera calibration of a tracked camera filmed looking at a checkerboard:
// the time offset between tracker and video, the sensor-to-camera offset and the
// transmitter-to-world alignment (docs/rig_calibration.md).
//
//  1. board poses per frame (board_pose.h); views whose PnP reprojection error is far
//     above the others' are dropped;
//  2. time offset from the cross-correlation of angular speeds (latency_estimation.h);
//  3. every tracker sample paired with the camera pose interpolated (slerp) between the
//     board views around its time - offset; cv::calibrateHandEye on pairs spread in
//     orientation (hand_eye_calibration.h). The precise board poses are interpolated,
//     never the noisy tracker: interpolating noisy samples averages their noise more
//     at some offsets than at others, which biases the offset by several milliseconds;
//  4. a joint least-squares refinement (Levenberg-Marquardt) of T_sensor_camera,
//     T_transmitter_board and the offset, each sample's residual being the difference
//     between the sensor pose the tracker reported and the one the board implies,
//     weighted by the tracker's noise; samples with inconsistent residuals are dropped
//     and the fit repeated once.
//
// World frame: the board's frame turned by T_world_board (default Rx(+90 deg): a board
// lying face up on a level table gives world +Y up, world X along the board's rows, world
// Z down its columns, origin at the first inner corner).
#include <cstdint>
#include <string>
#include <vector>

#include "lumar/calib/hand_eye_calibration.h"
#include "lumar/calib/latency_estimation.h"
#include "lumar/tracking/pose_stream.h"
#include "lumar/tracking/rig.h"

namespace lumar::calib {

// One video frame where the board was found.
struct BoardView {
  std::int64_t index = 0;
  Nanos time = 0;  // recording time of the frame
  Pose T_camera_board;
  double reprojection_rms_px = 0;
};

struct RigCalibrationOptions {
  Pose T_world_board{axis_angle_deg({1, 0, 0}, 90.0), {0, 0, 0}};
  bool estimate_time_offset = true;  // false: trust the recording's latency as it is
  bool refine = true;                // false: stop after cv::calibrateHandEye
  TimeOffsetOptions time_offset;
  HandEyeOptions hand_eye;
  // A view is dropped when its PnP RMS is above max(floor, median + 5 * 1.4826 * MAD).
  double view_rms_floor_px = 0.5;
  // Tracker noise that weighs rotation against position in the refinement
  // (ISOTRAK II: 0.75 deg and 0.1 in RMS).
  double tracker_rotation_sigma_deg = 0.75;
  double tracker_position_sigma_m = 0.00254;
  // After the first refinement, a view is dropped when its squared normalised residual
  // (6 degrees of freedom) exceeds this chi-square value once the residuals are scaled
  // so that their median is chi-square-6's (5.35): 30 is p = 4e-5 for Gaussian noise.
  double residual_outlier_chi2 = 30.0;
  int min_views = 12;
  double min_rotation_deg = 15.0;  // the camera must turn at least this much overall
};

struct RigCalibrationResult {
  tracking::Rig rig;  // latency = assumed latency + time offset
  Nanos assumed_latency = 0;
  Nanos time_offset = 0;         // final (refined) offset added to the assumed latency
  Nanos correlation_offset = 0;  // from the angular-speed cross-correlation alone
  double peak_correlation = 0, correlation_at_zero = 0;
  HandEyeSolution hand_eye;           // cv::calibrateHandEye on latency-corrected poses
  int views_given = 0;                // board views passed in
  int views_rejected_pnp = 0;         // dropped for their reprojection error
  int views_used = 0;                 // the rest
  int samples_used = 0;               // tracker samples in the final fit
  int samples_rejected_residual = 0;  // dropped by the refinement
  double rotation_range_deg = 0;      // largest rotation between the first view and another
  double view_rms_threshold_px = 0;
  double median_view_rms_px = 0;
  // Residuals of the final fit (tracker pose against board-implied pose), RMS over samples.
  double rotation_rms_deg = 0, translation_rms_m = 0;
  // One-sigma uncertainties from the fit's covariance (scaled by the residual).
  double sigma_rotation_deg = 0, sigma_translation_m = 0, sigma_time_offset_s = 0;
  std::vector<std::string> warnings;
};

// `tracker` holds T_transmitter_sensor samples timestamped with `assumed_latency`.
// Throws InputError for unusable input: fewer than min_views usable views, too little
// rotation, no overlap between tracker and video (fewer than min_views samples between
// two board views), constant angular speed.
RigCalibrationResult calibrate_rig(const std::vector<BoardView>& views, const tracking::PoseStream& tracker,
                                   int station, Nanos assumed_latency, const RigCalibrationOptions& options = {});

}  // namespace lumar::calib
