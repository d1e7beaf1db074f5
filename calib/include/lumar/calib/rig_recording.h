#pragma once
// The recording side of `lumar calibrate-rig`: board views found in a recording's
// frames, its tracker stream decoded from the raw bytes exactly as a replay does
// (timestamped with the session's latency), and the result written back into its
// session.json.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "lumar/calib/rig_calibration.h"
#include "lumar/capture/session.h"
#include "lumar/tracking/pose_stream.h"

namespace lumar::calib {

struct RigRecording {
  capture::Session session;
  CameraIntrinsics camera;       // the one used for the board poses
  std::vector<BoardView> views;  // frames where the whole board was found
  int frames = 0;                // frames read
  tracking::PoseStream tracker;  // T_transmitter_sensor, times with session.rig.latency
  std::size_t tracker_records = 0;
};

// Reads `dir` (InputError naming the file when it is missing or unusable), finds the
// board in every `every`-th frame, decodes the tracker stream. `camera` overrides the
// session's intrinsics (its size must match the video's). Throws InputError when the
// board is found in no frame or the tracker stream is empty.
RigRecording load_rig_recording(const std::filesystem::path& dir, cv::Size inner_corners, double square_size_m,
                                const std::optional<CameraIntrinsics>& camera = std::nullopt, int every = 1);

// Machine-readable summary of a calibration (also stored in session.json as
// "rig_calibration").
nlohmann::json rig_calibration_json(const RigCalibrationResult& result);

// Replaces the session's rig with result.rig and stores the summary, atomically
// (session.json.tmp, then rename); every other key is kept as it was.
void save_rig_to_session(const std::filesystem::path& dir, const RigCalibrationResult& result);

}  // namespace lumar::calib
