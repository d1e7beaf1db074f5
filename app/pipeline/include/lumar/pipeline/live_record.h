#pragma once
// `lumar record`: frames from any source (a camera, a video file, an image sequence, a
// recording) and the raw stream of a tracker, through the live loop, into a recording
// that a crash cannot tear (capture/recording_writer.h). A camera that vanishes or a
// disk that fills ends the recording early with one clear line, and what was written
// stays readable.
#include <string>

#include "lumar/pipeline/live_inputs.h"

namespace lumar::pipeline {

struct RecordOptions {
  LiveInputOptions in;
  std::string out;
  std::string codec = "mjpeg";
  int quality = 95;
  double segment_seconds = 1.0;
  double duration_s = 0;
  int max_frames = 0;
  double min_free_mb = 256;
};

// Throws InputError / RuntimeError with one line (naming what was kept) when the
// recording ended early for a reason other than the end of the source or Ctrl-C.
void record_live(const RecordOptions& options);

}  // namespace lumar::pipeline
