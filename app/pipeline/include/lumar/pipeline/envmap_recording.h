#pragma once
// A sweep given as a recording (`lumar envmap --recording`): its frames, the tracker's
// rotation at each frame's time (through the real parser, as a replay sees it), the
// exposures of the session (frame_exposures, cycled, or its one exposure), brackets as
// groups, and for a synthetic sweep its truth and source map.
#include <string>

#include "lumar/pipeline/envmap_sweep.h"

namespace lumar::pipeline {

// `camera_file` replaces the session's calibration (empty: keep it). InputError naming
// the recording or the file when it has no frames or tracker poses, when the poses do
// not cover a frame, or when the calibration's size is not the frames'.
SweepInput recording_sweep_input(const std::string& recording, const std::string& camera_file, int width);

}  // namespace lumar::pipeline
