#include "lumar/tracking/pose_fusion.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "lumar/base/error.h"

namespace lumar::tracking {

PoseFusion::PoseFusion(const PoseFusionSettings& settings) : settings_(settings) {
  if (!(settings.tracker_gain > 0.0 && settings.tracker_gain <= 1.0))
    throw InputError("--tracker-gain: the fused pose's pull towards the tracker must be in (0, 1], not " +
                     std::to_string(settings.tracker_gain));
  if (!(settings.fix_worth >= 0.0 && std::isfinite(settings.fix_worth)))
    throw InputError("--fix-worth: an absolute fix's worth in tracker samples must be a number >= 0, not " +
                     std::to_string(settings.fix_worth));
}

double PoseFusion::drift_gain() const {
  // More and more trust in the tracker while the video is lost.
  return std::max(settings_.tracker_gain,
                  std::min(kMaxCoastGain, settings_.tracker_gain + coasted_ * kCoastGainPerFrame));
}

double PoseFusion::tracker_worth() const {
  // The running mean at the start, the drift's floor after it.
  return 1.0 / std::max(drift_gain(), 1.0 / (tracker_frames_ + 1));
}

const std::optional<Pose>& PoseFusion::fix(const Pose& absolute) {
  if (fused_ && settings_.fix_worth > 0) {
    const double worth = tracker_worth() + fixes_worth_;
    fused_ = interpolate(*fused_, absolute, settings_.fix_worth / (worth + settings_.fix_worth));
    fixes_worth_ += settings_.fix_worth;
  }
  return fused_;
}

void PoseFusion::restart_mean() {
  tracker_frames_ = std::min(tracker_frames_, 1);
  fixes_worth_ = 0;
  motion_.reset();
}

void PoseFusion::reset() {
  fused_.reset();
  motion_.reset();
  last_tracker_.reset();
  tracker_frames_ = coasted_ = 0;
  fixes_worth_ = 0;
}

std::optional<Pose> PoseFusion::update(const std::optional<Pose>& visual, const std::optional<Pose>& tracker) {
  if (!fused_) {
    if (tracker) fused_ = tracker, last_tracker_ = tracker, tracker_frames_ = 1;
    return fused_;
  }
  Pose predicted = *fused_;
  if (visual) {
    motion_ = fused_->inverse() * *visual;
    predicted = *visual;
    coasted_ = 0;
  } else if (motion_) {
    predicted = *fused_ * *motion_;  // on at the video's last motion, which the tracker's noise does not shake
    ++coasted_;
  } else if (tracker && last_tracker_) {
    predicted = *fused_ * (last_tracker_->inverse() * *tracker);  // the tracker's motion, in the camera's frame
  }
  // The fixes fade as the video drifts; the longer the video has been lost, the faster,
  // so that the fused pose slides back to the tracker rather than jumping.
  // The video's drift adds to the fused pose's variance each frame what keeps the
  // tracker's settled gain at g: g^2 / (1 - g) tracker variances (a Kalman filter's process
  // noise), so an old fix is soon worth little more than the tracker's running mean.
  if (fixes_worth_ > 0) {
    const double drift = drift_gain();
    fixes_worth_ = 1.0 / (1.0 / fixes_worth_ + drift * drift / (1.0 - drift));
  }
  if (tracker) {
    predicted = interpolate(predicted, *tracker, 1.0 / (tracker_worth() + fixes_worth_));
    ++tracker_frames_;
    last_tracker_ = tracker;
  }
  fused_ = predicted;
  return fused_;
}

}  // namespace lumar::tracking
