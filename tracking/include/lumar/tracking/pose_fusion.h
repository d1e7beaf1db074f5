#pragma once
// Fusing two estimates of the camera's pose: one precise from frame to frame but drifting
// (the video's), one absolute but noisy (the tracker's). A complementary filter on
// SO(3) x R^3: each frame the pose the video predicts is pulled towards the tracker's by
// a small gain, so the fused pose takes its high frequencies from the video and its low
// frequencies, and its absolute placement, from the tracker.
//
// With white tracker noise sigma_t per frame and a drift-free video, the settled error is
// sigma_t * sqrt(g / (2 - g)) (g = the gain); a video drifting by d per frame adds about
// d / g. Until 1/g frames have passed the gain is 1/(n + 1), the running mean of the
// tracker's offset from the video's path, so that the start needs no settling.
//
// An absolute fix (the frame aligned with the room the proxy predicts) may come too. It
// is weighed as `fix_worth` tracker samples against what the fused pose is worth then
// (1/gain tracker samples, plus the fixes before it); a fix's worth fades as the video
// drifts (its variance grows each frame by the process noise g^2/(1-g) that gives the
// tracker's settled gain g; faster while the video is lost), and while it lasts the
// tracker pulls that much less.
#include <algorithm>
#include <optional>

#include "lumar/base/pose.h"

namespace lumar::tracking {

struct PoseFusionSettings {
  double tracker_gain = 0.035;  // (0, 1]; 1 = the tracker alone
  // How many tracker samples one absolute fix is worth (the ratio of their variances;
  // >= 0, 0 = fixes are ignored).
  double fix_worth = 400;
};

class PoseFusion {
 public:
  // While the video is lost the tracker's gain grows by this per frame, up to the most.
  static constexpr double kCoastGainPerFrame = 1.0 / 240, kMaxCoastGain = 0.25;

  explicit PoseFusion(const PoseFusionSettings& settings = {});

  // One frame. `visual`: the camera's pose as the video continues it from the last fused
  // pose (nullopt: the video could not tell; its last motion goes on, pulled towards the
  // tracker ever harder; before any, or after a gap, the tracker's own motion since its
  // last sample stands in). `tracker`: the tracker's pose for the same frame (nullopt: none).
  // Returns the fused pose; nullopt until the tracker has given one.
  std::optional<Pose> update(const std::optional<Pose>& visual, const std::optional<Pose>& tracker);
  // An absolute fix for the frame just updated, pulled towards as its worth says.
  const std::optional<Pose>& fix(const Pose& absolute);

  // Forget everything (a seek): the next tracker pose starts again.
  void reset();
  // Keep the pose but weigh the next tracker poses as at the start (1/2, 1/3, ...): after
  // a gap in the frames, bridged by the tracker's noisy motion, the fused pose is worth
  // about one tracker sample.
  void restart_mean();
  // Keep everything but the video's last motion (frames were skipped: it spans several).
  void forget_motion() { motion_.reset(); }
  const std::optional<Pose>& pose() const { return fused_; }

 private:
  double drift_gain() const;     // the tracker's gain once its mean has settled
  double tracker_worth() const;  // the fused pose's worth from the tracker alone, in its samples

  PoseFusionSettings settings_;
  std::optional<Pose> fused_, last_tracker_;
  std::optional<Pose> motion_;  // the video's last motion per frame, in the camera's frame
  int tracker_frames_ = 0, coasted_ = 0;
  double fixes_worth_ = 0;  // what the fixes so far are still worth, in tracker samples
};

}  // namespace lumar::tracking
