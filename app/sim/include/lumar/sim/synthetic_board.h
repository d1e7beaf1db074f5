#pragma once
// `lumar synth --board`: a recording of the tracked camera filming a planar checkerboard,
// for tracker-to-camera (hand-eye) and latency calibration with known truth. The board
// is rendered exactly: every pixel's footprint is mapped through the lens (undistorted
// with the calibrated Brown-Conrady model) and the board-plane homography, and the
// checker pattern is box-filtered over it analytically. The tracker stream is what an
// ISOTRAK II would send about the same motion (noise, quantisation, latency).
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"

namespace lumar::sim {

struct BoardSynthSettings {
  std::filesystem::path out;
  CameraIntrinsics camera;  // calibrated, with distortion
  cv::Size board{9, 6};     // inner corners
  double square = 0.025;    // metres
  double seconds = 10.0;    // of video
  double fps = 30.0;
  double tracker_noise_deg = 0.75;    // RMS rotation error
  double position_noise_m = 0.00254;  // RMS per axis (ISOTRAK II: 0.1 in)
  double latency_ms = 20.0;           // the simulated device's true latency
  double assumed_latency_ms = 0.0;    // the latency session.json claims (what calibration corrects)
  double image_noise = 1.5;           // 8-bit levels, standard deviation
  std::string codec = "ffv1";
  std::uint64_t seed = 1;
};

// The truth the recording is made with (also stored in session.json "synth_board").
// World = the board's frame turned by Rx(+90 deg): the board lies face up at the origin.
Pose board_synth_T_world_board();
Pose board_synth_T_sensor_camera();
Pose board_synth_T_world_transmitter();
// T_world_camera at time t (seconds): orbits, tilts and rolls over the board with
// angular speed that keeps changing (incommensurate sinusoids).
Pose board_synth_camera_pose(double t_s, cv::Size board, double square);

// Renders the 8-bit image of the board seen from T_world_camera (no noise).
cv::Mat render_board_image(const CameraIntrinsics& camera, cv::Size board, double square, const Pose& T_camera_board);

// Writes the recording into settings.out (which must not exist yet). Throws
// InputError / RuntimeError; on failure the partial recording directory is removed.
void synthesize_board_recording(const BoardSynthSettings& settings);

}  // namespace lumar::sim
