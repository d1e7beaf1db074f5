#pragma once
// Calibration views sampled from any frame source: a video file, an image sequence, a
// recording or a live camera (`lumar calibrate --source SPEC --every N`).
#include <vector>

#include "lumar/calib/board_views.h"
#include "lumar/capture/frame_source.h"

namespace lumar::calib {

// Every `every`-th frame the source delivers (frame 0 first), at most max_frames; named
// "<source>#<frame index>". Throws InputError when `every` < 1 or no frame arrives.
std::vector<NamedImage> sample_frames(capture::FrameSource& source, int every, int max_frames = 500);

}  // namespace lumar::calib
