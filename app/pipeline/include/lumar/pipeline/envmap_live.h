#pragma once
// `lumar envmap --source SPEC --tracker serial:PORT`: a live sweep, stitched as it goes.
// A capture thread reads the camera (or a file played in real time); each frame is
// paired with the tracker's pose at its time (capture::FramePosePairing, the rig of
// --rig) and added to an incremental calib::EnvmapStitcher at once. Rotations are the
// tracker's as they are: no refinement live (the stitcher cannot retract a frame).
// The outputs are rewritten atomically every --update-every seconds and at the end
// (Ctrl-C / SIGTERM, --duration, or the end of the source). With --refine-at-end the
// frames are also kept (up to --keep-frames) and, once the sweep is over, go through the
// offline pipeline (refinement, then a fresh stitch), whose outputs replace the live ones.
//
// `--source recording:DIR` without --tracker replays the recording's own tracker stream
// (and takes its camera, radiometry and per-frame exposures): a sweep recorded earlier,
// played through the live path.
#include <string>
#include <vector>

#include "lumar/pipeline/envmap_sweep.h"
#include "lumar/pipeline/live_inputs.h"

namespace lumar::pipeline {

struct LiveEnvmapOptions {
  LiveInputOptions in;      // source, tracker, camera calibration (in.camera_file)
  EnvmapOutputOptions out;  // out, width, coverage, preview, no_fill, azimuth offset
  std::string rig;          // a session.json whose "rig" to use (default: identity, in.latency_ms)
  std::string response;     // camera response JSON (default: sRGB; a recording: its own)
  double vignetting_a = 0, vignetting_b = 0;
  // Video linear value per unit radiance; a list is cycled over the frames (frame k, by
  // its source index, uses entry k mod n), e.g. a camera bracketing. A recording: its own.
  std::vector<double> exposures{1.0};
  double update_every_s = 5;  // rewrite the outputs this often
  double duration_s = 0;      // stop after this long (0: at the end of the source or Ctrl-C)
  double max_wait_ms = 100;   // longest a frame waits for the tracker to cover its time
  bool refine_at_end = false;
  int keep_frames = 600;            // --refine-at-end: frames kept in memory (~0.9 MB each at 640x480)
  double tracker_noise_deg = 0.75;  // --refine-at-end: the refinement's prior
  double tracker_timeout_s = 10;    // the tracker's first pose must come within this (capture starts then)
};

// Throws InputError / RuntimeError with one line; the outputs written so far stay valid.
void run_live_envmap(const LiveEnvmapOptions& options);

}  // namespace lumar::pipeline
