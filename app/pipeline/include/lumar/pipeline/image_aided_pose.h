#pragma once
// Image-aided tracking: the camera's pose from the tracker, steadied by the video. Corners
// are tracked from frame to frame (Shi-Tomasi corners, pyramidal Lucas-Kanade, checked
// forwards and backwards); each carries the 3-D point where the last fused pose's ray
// through it meets the proxy, so the new frame's pose follows from PnP with RANSAC (the
// room's planes make the essential matrix degenerate; the proxy's depth does not). That
// pose, continuing the last fused one, is fused with the tracker's by
// tracking::PoseFusion. Where the video cannot tell (too few corners or inliers, a jump
// the tracker does not share), its last motion goes on while the fused pose slides back
// to the tracker's, without a jump; over dropped frames (up to 30) the tracker's motion
// bridges the gap (over a few, as a live source skips them, the corners still track).
// Frames must come in order; a seek starts again from the tracker.
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/capture/frame_source.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/pipeline/proxy_alignment.h"
#include "lumar/scene/mesh.h"
#include "lumar/tracking/pose_fusion.h"

namespace lumar::pipeline {

struct ImageAidedSettings {
  tracking::PoseFusionSettings fusion;
  int max_corners = 300;
  int min_inliers = 30;         // fewer: the video cannot tell
  double ransac_px = 0.5;       // PnP inlier threshold
  double max_disagree_deg = 3;  // the video's turn against the tracker's, beyond which the video is not trusted
  // Lucas-Kanade's least eigenvalue per window pixel below which a corner is not tracked:
  // above the sensor noise of a flat wall, whose "corners" would stay where they were put.
  double min_eigen = 1e-4;
  ProxyAlignmentSettings alignment;
  int align_every = 24;  // frames between absolute fixes (0: only at the start and after a gap)
  // A fix further than this from the fused pose is not trusted (a wrong match).
  double max_fix_offset_deg = 3, max_fix_offset_m = 0.1;
};

class ImageAidedPose {
 public:
  // `camera`: the video's intrinsics, with its distortion. `proxy`: the room in world
  // metres (the scene's proxy); InputError when it is empty. `predict`: the room's
  // radiance from a pose, for absolute fixes (empty: none; called from update()).
  ImageAidedPose(const CameraIntrinsics& camera, const Mesh& proxy, const ImageAidedSettings& settings = {},
                 RoomPrediction predict = {});

  // The fused pose for `frame`, given the tracker's for it. The same frame again (a paused
  // window) returns the same pose.
  std::optional<Pose> update(const capture::Frame& frame, const std::optional<Pose>& tracker);

  struct Stats {
    int frames = 0, visual_frames = 0;  // frames fused, and of them those the video could tell
    double inliers = 0;                 // mean PnP inliers over the visual frames
    int fix_attempts = 0, fixes = 0;    // absolute fixes tried, and taken
  };
  const Stats& stats() const { return stats_; }

 private:
  std::optional<Pose> pose_from_video(const cv::Mat& grey, const Pose& last, const std::optional<Pose>& tracker);
  void anchor(const cv::Mat& grey, const Pose& fused);
  void try_fix(const cv::Mat& image);

  CameraIntrinsics camera_;
  RayScene proxy_;
  ImageAidedSettings settings_;
  tracking::PoseFusion fusion_;
  std::optional<ProxyAlignment> alignment_;
  int frames_since_fix_try_ = 0;
  bool fix_due_ = true;  // at the start and after a gap
  std::optional<Pose> last_tracker_, last_fused_;
  std::int64_t last_index_ = -2;
  cv::Mat last_grey_;
  std::vector<cv::Point2f> corners_;  // in the last frame, each with its point on the proxy
  std::vector<cv::Point3f> points_;
  std::vector<cv::Point2f> tracked_;  // the inliers' corners in the frame just fused
  Stats stats_;
};

}  // namespace lumar::pipeline
