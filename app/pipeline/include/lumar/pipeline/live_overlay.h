#pragma once
// The live overlay path: a frame source (camera, or a file played as one) and a
// tracker on a serial port -> capture thread (newest frame wins) -> frame-pose
// pairing -> compositor -> a window. Used by `lumar overlay --source ... --tracker ...`.
#include <filesystem>
#include <string>

#include "lumar/pipeline/live_inputs.h"

namespace lumar::pipeline {

struct LiveOverlayOptions {
  LiveInputOptions in;
  std::filesystem::path scene;
  std::filesystem::path rig;  // a session.json whose "rig" to use (default: identity, in.latency_ms)
  double exposure = 1.0;      // video linear value per unit radiance
  double max_wait_ms = 40;    // longest a frame waits for the tracker to cover its time
  int max_frames = 0;         // 0: until the window closes, the source ends or Ctrl-C
};

// Runs until the window is closed, the source ends, Ctrl-C, or max_frames. Throws
// InputError / RuntimeError with one line (e.g. the camera vanished).
void run_live_overlay(const LiveOverlayOptions& options);

}  // namespace lumar::pipeline
