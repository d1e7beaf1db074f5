#pragma once
// Synthetic checkerboard recordings (`lumar synth --board`) shared by the rig tests.
// CTest runs every test in its own process, so each recording is made once and cached
// under the temporary directory, keyed by its arguments and the lumar binary's
// modification time; it is made under a temporary name and renamed, so concurrent
// tests never see half a recording.
#include <filesystem>
#include <string>

#include "lumar/calib/rig_recording.h"
#include "lumar/tracking/rig.h"

namespace lumar::test {

// `extra_args` are appended to: lumar synth --board 9x6 --square 0.025 --camera <webcam>.
std::filesystem::path board_recording(const std::string& extra_args);

// The truth stored by the generator in session.json ("synth_board").
tracking::Rig board_recording_truth(const std::filesystem::path& recording);

// Loaded once per process and recording.
const calib::RigRecording& loaded_board_recording(const std::string& extra_args);

struct RigErrors {
  double offset_mm = 0, offset_deg = 0;  // T_sensor_camera
  double world_mm = 0, world_deg = 0;    // T_world_transmitter
  double latency_ms = 0;                 // signed, estimate - truth
};
RigErrors rig_errors(const tracking::Rig& estimate, const tracking::Rig& truth);

}  // namespace lumar::test
