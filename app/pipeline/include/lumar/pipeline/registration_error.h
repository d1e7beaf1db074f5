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
  double pose_ms = 0;  // the pose source's time per frame (decoding not counted)
  // How it moves (NaN where the recording has no such stretch). The offset of a frame is
  // the mean over the points of (projected with the pose - projected with the truth).
  // jitter_px: RMS of the offset about its mean over each stretch where the true camera
  // stands still, leaving out the recording's first second and each stretch's first half
  // second. lag_ms: over the frames where the camera's true motion moves the objects'
  // centre across the image faster than 20 px/s, -sum(offset . v) / sum(|v|^2), v that
  // image velocity: how far behind the poses are. overshoot_px: in the half second after a motion stops, the largest
  // offset along that motion's last direction.
  double jitter_px, lag_ms, overshoot_px;
  // The largest change of the offset from one frame to the next: how far the objects jump
  // against the room at once (a fix taken, the video lost or found again).
  double jump_px = 0;
};

// Every frame of `overlay`'s recording with poses from `source`; the overlay's own source
// is restored afterwards. InputError when the recording has no truth.
RegistrationError registration_error(ReplayOverlay& overlay, PoseSource source);

// The mean distance for one frame.
double projection_error_px(const CameraIntrinsics& camera, const std::vector<glm::dvec3>& points, const Pose& pose,
                           const Pose& truth);

}  // namespace lumar::pipeline
