#include "lumar/tracking/pose_fusion.h"

#include <algorithm>
#include <string>

#include "lumar/base/error.h"

namespace lumar::tracking {

PoseFusion::PoseFusion(const PoseFusionSettings& settings) : settings_(settings) {
  if (!(settings.tracker_gain > 0.0 && settings.tracker_gain <= 1.0))
    throw InputError("--tracker-gain: the fused pose's pull towards the tracker must be in (0, 1], not " +
                     std::to_string(settings.tracker_gain));
}

void PoseFusion::restart_mean() {
  tracker_frames_ = std::min(tracker_frames_, 1);
  motion_.reset();
}

void PoseFusion::reset() {
  fused_.reset();
  motion_.reset();
  last_tracker_.reset();
  tracker_frames_ = coasted_ = 0;
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
  if (tracker) {
    // The longer the video has been lost, the more the tracker is trusted, so that the
    // fused pose slides back to it rather than jumping.
    const double coasting = std::min(kMaxCoastGain, settings_.tracker_gain + coasted_ * kCoastGainPerFrame);
    const double gain = std::max({settings_.tracker_gain, coasting, 1.0 / (tracker_frames_ + 1)});
    predicted = interpolate(predicted, *tracker, gain);
    ++tracker_frames_;
    last_tracker_ = tracker;
  }
  fused_ = predicted;
  return fused_;
}

}  // namespace lumar::tracking
