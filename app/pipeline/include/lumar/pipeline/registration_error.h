#pragma once
// How far the objects land from where they belong: per frame, the mean distance in pixels
// between where the objects' points project with a pose source's camera pose and with the
// recording's true one (the compositor's undistorted output camera). Registration alone:
// nothing is rendered.
#include <vector>

#include "lumar/pipeline/replay_overlay.h"

namespace lumar::pipeline {

struct RegistrationError {
  std::vector<double> px;  // per frame that had a pose (and a true one)
  int frames = 0;          // frames read
  double mean = 0, p95 = 0, worst = 0;
};

// Every frame of `overlay`'s recording with poses from `source`; the overlay's own source
// is restored afterwards. InputError when the recording has no truth.
RegistrationError registration_error(ReplayOverlay& overlay, PoseSource source);

// The mean distance for one frame.
double projection_error_px(const CameraIntrinsics& camera, const std::vector<glm::dvec3>& points, const Pose& pose,
                           const Pose& truth);

}  // namespace lumar::pipeline
