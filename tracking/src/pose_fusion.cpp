#include "lumar/tracking/pose_fusion.h"

#include <algorithm>

#include "lumar/base/error.h"

namespace lumar::tracking {

PoseFusion::PoseFusion(const PoseFusionSettings& settings) : settings_(settings) {
  if (!(settings.tracker_gain > 0.0 && settings.tracker_gain <= 1.0))
    throw InputError("pose fusion: the tracker's gain must be in (0, 1]");
}

void PoseFusion::reset() {
  fused_.reset();
  last_tracker_.reset();
  tracker_frames_ = 0;
}

std::optional<Pose> PoseFusion::update(const std::optional<Pose>& visual, const std::optional<Pose>& tracker) {
  if (!fused_) {
    if (tracker) fused_ = tracker, last_tracker_ = tracker, tracker_frames_ = 1;
    return fused_;
  }
  Pose predicted = *fused_;
  if (visual)
    predicted = *visual;
  else if (tracker && last_tracker_)
    predicted = *fused_ * (last_tracker_->inverse() * *tracker);  // the tracker's motion, in the camera's frame
  if (tracker) {
    const double gain = std::max(settings_.tracker_gain, 1.0 / (tracker_frames_ + 1));
    predicted = interpolate(predicted, *tracker, gain);
    ++tracker_frames_;
    last_tracker_ = tracker;
  }
  fused_ = predicted;
  return fused_;
}

}  // namespace lumar::tracking
