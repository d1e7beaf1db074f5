#pragma once
// What goes wrong with a real camera's video, for testing what must survive it (image-aided
// tracking above all): frames dropped, a textureless wall filling the view, something
// walking through it, motion blur. Applied to a synthetic frame's radiance before the
// sensor model, so the sensor's noise and vignetting stay as in every other frame.
#include <opencv2/core.hpp>

namespace lumar::sim {

struct FrameRange {
  int from = 0, count = 0;  // frames [from, from + count)
  bool contains(int k) const { return k >= from && k < from + count; }
  bool empty() const { return count <= 0; }
};

struct VideoFaults {
  FrameRange dropped;                     // left out of the video, their indices too
  FrameRange textureless;                 // a flat wall fills the view: the frame's mean radiance everywhere
  FrameRange occluder;                    // a textured panel half the frame wide slides across it
  double motion_blur_s = 0.0;             // shutter time: each frame averages renders over it
  static constexpr int kBlurSamples = 5;  // odd: one at the middle of the shutter
};

// Frame k of `frames` (radiance, CV_32FC3) with the textureless wall or the occluder of
// `faults`, if k is in their ranges. `panel`: the occluder's texture (occluder_texture).
void apply_video_faults(const VideoFaults& faults, int k, const cv::Mat& panel, cv::Mat& radiance);

// The occluder's texture: dark cloth with blotches, so that it has corners of its own that
// move with it and not with the room. Deterministic for a size.
cv::Mat occluder_texture(cv::Size frame);

}  // namespace lumar::sim
