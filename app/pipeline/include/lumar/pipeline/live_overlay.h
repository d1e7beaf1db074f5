#pragma once
// The live overlay: a frame source (a camera, or a file played as one) and a tracker ->
// the live loop (newest frame wins, paired with the tracker's pose through the rig and
// the pose filter) -> the same Overlay the replay uses (radiometry, lighting adaptation,
// compositor). Used by `lumar overlay --source ... --tracker ...`.
//
// What the camera is and how it made its video, in this order: the flags (--camera,
// --response, --vignetting, --exposure, --latency-ms); the session.json of --rig (its
// rig, camera, radiometry and latency); a `recording:` source's own session; the
// defaults (a nominal pinhole, sRGB, no vignetting, exposure 1, no latency).
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "lumar/pipeline/image_aided_pose.h"
#include "lumar/pipeline/live_inputs.h"
#include "lumar/pipeline/live_loop.h"
#include "lumar/pipeline/overlay.h"
#include "lumar/pipeline/quality_choice.h"
#include "lumar/tracking/one_euro_filter.h"

namespace lumar::pipeline {

struct LiveOverlayOptions {
  LiveInputOptions in;
  std::filesystem::path scene;
  std::filesystem::path rig;            // a session.json (see above); empty: none
  std::optional<std::string> response;  // camera response JSON, or "srgb"
  std::optional<double> vignetting_a, vignetting_b, exposure;
  std::optional<tracking::PoseFilterSettings> filter;
  bool steady_with_video = true;  // the tracker's poses steadied by the video (image_aided_pose.h)
  ImageAidedSettings image_aided;
  double max_wait_ms = 40;  // longest a frame waits for the tracker to cover its time
  int max_frames = 0;       // 0: until the source ends, Ctrl-C or the sink says stop
  // Set: the quality knobs chosen on the first frames with a pose (choose_quality below),
  // from overlay.quality as full quality.
  std::optional<QualityBudget> auto_quality;
  OverlaySettings overlay = [] {
    OverlaySettings s;
    s.window = true;
    s.window_title = "lumar overlay (live)";
    return s;
  }();
};

class LiveOverlay {
 public:
  // Opens the source, the tracker, the scene and the GL context. InputError /
  // RuntimeError with one line.
  explicit LiveOverlay(const LiveOverlayOptions& options);

  // Runs until the source ends, Ctrl-C, max_frames, or `sink` returns false (e.g. the
  // window was closed); then InputError / RuntimeError if the source failed.
  void run(const std::function<bool(const OverlayFrame&)>& sink);

  // Chooses the quality knobs (quality_choice.h) on the camera's next budget.frames + 1
  // frames that have a pose, each at least kProbeSpacing after the last so that they see
  // more than one view; until then the frames are composited at the current quality. The
  // choice itself runs between two frames, from the current quality as full quality; the
  // camera's frames meanwhile are dropped as stale, and the stage times start again.
  static constexpr double kProbeSpacingS = 0.2;
  void choose_quality(const QualityBudget& budget);
  // Frames collected for a choice asked for, and how many it needs (0, 0: none asked for).
  std::pair<int, int> quality_probes() const;
  // The last choice (nullopt: none made yet).
  const std::optional<QualityChoice>& quality_choice() const { return quality_choice_; }

  Overlay& overlay() { return *overlay_; }
  const LiveLoop& loop() const { return *loop_; }
  double fps() const { return fps_; }  // the source's nominal rate

 private:
  // Keeps `frame` as a probe if a choice is asked for, and makes the choice once there
  // are enough; true when it did.
  bool probe(const capture::Frame& frame, const std::optional<Pose>& pose,
             const std::vector<std::optional<Pose>>& shutter_cameras);

  std::optional<QualityBudget> probe_budget_;
  std::vector<ProbeFrame> probes_;
  std::optional<QualityChoice> quality_choice_;
  std::unique_ptr<Overlay> overlay_;
  std::unique_ptr<LiveLoop> loop_;
  std::unique_ptr<ImageAidedPose> fused_;
  double fps_ = 30;
};

}  // namespace lumar::pipeline
