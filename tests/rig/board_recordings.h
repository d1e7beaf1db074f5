#pragma once
// Synthetic checkerboard recordings (sim/synthetic_board.h, what `lumar synth --board`
// makes) shared by the rig tests. CTest runs every test in its own process, so each
// recording is made once and cached under the temporary directory, keyed by its settings
// and the test program's modification time; it is made under a temporary name and
// renamed, so concurrent tests never see half a recording.
#include <filesystem>
#include <string>

#include "lumar/calib/rig_recording.h"
#include "lumar/sim/synthetic_board.h"
#include "lumar/tracking/rig.h"

namespace lumar::test {

// 12 s at 30 fps, the ISOTRAK II's noise (0.75 deg, 0.1 in RMS), 20 ms latency, the
// session assuming 0 ms; the 9x6 board of 25 mm squares, the calibrated webcam.
sim::BoardSynthSettings noisy_board();
// The same motion with a perfect tracker (only its 0.01 deg / 0.01 in quantisation) and
// 35 ms of latency.
sim::BoardSynthSettings clean_board();

std::filesystem::path board_recording(const sim::BoardSynthSettings& settings);

// The truth stored by the generator in session.json ("synth_board").
tracking::Rig board_recording_truth(const std::filesystem::path& recording);

// Loaded once per process and recording.
const calib::RigRecording& loaded_board_recording(const sim::BoardSynthSettings& settings);

struct RigErrors {
  double offset_mm = 0, offset_deg = 0;  // T_sensor_camera
  double world_mm = 0, world_deg = 0;    // T_world_transmitter
  double latency_ms = 0;                 // signed, estimate - truth
};
RigErrors rig_errors(const tracking::Rig& estimate, const tracking::Rig& truth);

}  // namespace lumar::test
