#pragma once
// The time offset between tracker and video, from motion alone: the angular speed of a
// rigid body is the same whichever frame measures it, so the camera's (from board
// poses) and the sensor's (from the tracker) can be compared before any hand-eye
// calibration. Their normalised cross-correlation peaks at the offset (as PLUS does);
// a parabola through the peak and its neighbours refines it below the search step.
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"

namespace lumar::calib {

struct AngularSpeedSample {
  Nanos time = 0;  // middle of the two poses compared
  double speed_deg_s = 0.0;
};

// Angular speed over a symmetric window: for each pose i, the angle between the first
// pose at or after t_i - span/2 and the last at or before t_i + span/2, over their time
// difference (skipped when that difference is under span/2, e.g. across a gap). A
// window of several tracker samples keeps noise down; being symmetric, it adds no lag.
// `times` must be increasing and the same size as `rotations`.
std::vector<AngularSpeedSample> angular_speed(const std::vector<Nanos>& times, const std::vector<glm::dquat>& rotations,
                                              Nanos span);

struct TimeOffsetOptions {
  Nanos max_offset = 1'000'000'000;  // search +-1 s
  Nanos step = 1'000'000;            // 1 ms
  Nanos video_span = 70'000'000;     // angular-speed window over video poses (about 2 frames at 30 Hz;
                                     // calibrate_rig widens it to 2.1 view spacings when frames are skipped)
  Nanos tracker_span = 100'000'000;  // over tracker poses (6 samples at 60 Hz)
};

struct TimeOffsetEstimate {
  // Use tracker data at t + offset for the video at t (PoseLookupSettings::time_offset):
  // offset > 0 means the tracker's timestamps are too late, i.e. its latency is
  // larger than assumed by `offset`.
  Nanos offset = 0;
  double peak_correlation = 0;  // Pearson correlation at the peak (1 = identical shapes)
  double correlation_at_zero = 0;
  int samples = 0;            // tracker speed samples compared at the peak
  std::vector<double> curve;  // correlation at -max_offset + k * step
};

// Each tracker speed sample is compared with the video's speed interpolated at its time
// (the video's series is the precise one: interpolating the noisy one would average its
// noise more at some offsets than at others and pull the peak towards those).
// Throws InputError when fewer than 10 tracker speed samples overlap the video at every
// offset, or when either speed is constant (nothing to correlate: the camera must turn
// at varying speed).
TimeOffsetEstimate estimate_time_offset(const std::vector<AngularSpeedSample>& video,
                                        const std::vector<AngularSpeedSample>& tracker,
                                        const TimeOffsetOptions& options = {});

}  // namespace lumar::calib
