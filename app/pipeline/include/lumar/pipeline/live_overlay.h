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

  Overlay& overlay() { return *overlay_; }
  const LiveLoop& loop() const { return *loop_; }
  double fps() const { return fps_; }  // the source's nominal rate

 private:
  std::unique_ptr<Overlay> overlay_;
  std::unique_ptr<LiveLoop> loop_;
  std::unique_ptr<ImageAidedPose> fused_;
  double fps_ = 30;
};

}  // namespace lumar::pipeline
