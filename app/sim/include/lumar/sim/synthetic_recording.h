#pragma once
// `lumar synth`: renders a recording whose truth is known. The proxy room is textured
// by projecting the HDR map from its capture point, seen by the calibrated camera
// (lens distortion, vignetting, sensor noise, 8-bit clipping) along a trajectory, with
// the byte stream a Polhemus ISOTRAK II would send about the same motion.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/capture/session.h"
#include "lumar/sim/light_change.h"
#include "lumar/sim/video_faults.h"
#include "lumar/tracking/simulated_tracker.h"

namespace lumar::sim {

struct SynthSettings {
  std::filesystem::path scene;
  std::filesystem::path out;
  CameraIntrinsics camera;  // calibrated, with distortion
  int frames = 48;
  double fps = 24.0;
  int supersample = 2;
  double exposure = 0.0;            // video linear value per unit radiance; 0 = automatic
  double read_noise = 0.002;        // linear units, standard deviation
  double shot_noise_gain = 0.0004;  // variance per unit of linear signal
  double vignetting_a = -0.30, vignetting_b = 0.05;
  double tracker_noise_deg = 0.75;   // RMS rotation error
  double position_noise_m = 0.0025;  // RMS per axis
  double latency_ms = 20.0;          // device latency
  double arc_deg = 60.0;             // how far the camera orbits
  std::string path = "orbit";        // orbit | still | room | rest-turn (synth_camera_pose)
  std::string codec = "mjpeg";
  int quality = 95;
  std::uint64_t seed = 1;
  // truth/ beside the video: the same frames with the objects physically present
  // (docs/ground_truth.md), with the video's noise and with another seed's.
  bool truth = false;
  // The frames that get truth (indices from 0); empty: every frame. A shipped recording
  // keeps a few, as its truth is four images a frame.
  std::vector<int> truth_frames;
  std::uint64_t truth_seed = 0;  // the other seed; 0: seed + 1
  int truth_ratio_stride = 4;    // TruthSettings::ratio_stride, in rendered (supersampled) pixels
  // Rays per object pixel of the truth: strata² (CompositeReferenceSettings::object_strata).
  // Their noise is the truth's own, which no seed changes; more rays, less of it.
  int truth_strata = 16;
  // The room's light changes during the recording (light_change.h); not with truth.
  std::optional<LightChange> light_change;
  // The video shows a room that differs from the scene's proxy (furnished_room.h), which
  // the session still names: an honest test of anything that aligns video with the proxy.
  bool room_differs = false;
  // Dropped frames, a textureless view, an occluder, motion blur (video_faults.h).
  VideoFaults faults;
};

// The session's record of the settings every synthetic recording shares ("synth").
capture::SynthInfo synth_info(const SynthSettings& settings);

// OpenCV camera axes (x right, y down, z forward) looking from `eye` at `target`, world +Y up.
Pose look_at(const glm::dvec3& eye, const glm::dvec3& target);

// The tracker of a synthetic recording: the session's protocol (rate, baud, station),
// the simulated device's own latency, its noise and seed, measuring `true_sensor_pose`.
tracking::SimulatedTrackerOutput simulate_session_tracker(const capture::Session& session, Nanos device_latency,
                                                          double orientation_noise_deg, double position_noise_m,
                                                          std::uint64_t seed,
                                                          const std::function<Pose(Nanos)>& true_sensor_pose,
                                                          Nanos duration);

// The tracker's bytes as they arrived (into tracker.raw), and the poses the real ASCII
// parser decodes from them (into poses.csv), timestamped with `assumed_latency`: the
// latency the recorder believed in, which need not be the simulated device's.
void write_tracker_stream(capture::RecordingWriter& writer, const tracking::SimulatedTrackerOutput& tracker,
                          const capture::TrackerSettings& settings, Nanos assumed_latency);

// One synthetic frame: the image the camera makes of the truth at frame k, time t.
using SyntheticFrameRenderer = std::function<cv::Mat(int k, Nanos t, const Pose& T_world_camera, cv::RNG& rng)>;

// Writes a synthetic recording into `out` (which must not exist yet): session.json, the
// simulated tracker's stream, and `frames` frames at `frame_time(k)` seen from
// `true_camera(t)`, drawn by `render` with one noise generator seeded by `seed`. On any
// failure the partial directory is removed and the error rethrown.
// `dropped(k)`: frame k is left out of the video (not rendered, its index skipped).
void write_synthetic_recording(const std::filesystem::path& out, const capture::Session& session,
                               const tracking::SimulatedTrackerOutput& tracker, const capture::RecordingSettings& video,
                               int frames, std::uint64_t seed, const std::function<Nanos(int)>& frame_time,
                               const std::function<Pose(Nanos)>& true_camera, const SyntheticFrameRenderer& render,
                               const std::function<bool(int)>& dropped = {});

// The camera's true pose at s in [0, 1] along the orbit around `target`.
Pose orbit_camera_pose(const glm::dvec3& target, double s, double arc_deg);
// The camera's true pose along the named path at s in [0, 1] of the recording, t_s
// seconds into it: "orbit"; "still" (held where the orbit ends); "room" (standing back,
// turning slowly); "rest-turn" (held halfway along the orbit for 2 s, then turning about
// the vertical at 30 degrees/s for 1 s, then held). InputError for another name.
Pose synth_camera_pose(const std::string& path, const glm::dvec3& target, double s, double t_s, double arc_deg);
// rest-turn: when the turn starts and ends, seconds, and its rate, degrees per second.
constexpr double kRestTurnStartS = 2.0, kRestTurnEndS = 3.0, kRestTurnDegPerS = 30.0;

// The sample room's two light changes (data/scenes/room; the tests and
// bench_lighting_change): "lamp-off", the ceiling lamp at (-1.2, 3, 0.3) going out at
// 2.5 s (13 % of the map's power), 120 frames; "warmer-window", the window's light
// ×(1.5, 1, 0.5) over 0.5 s from 1.5 s (16 % of the power), 96 frames at a third of the
// automatic exposure so that the window does not clip. Both on the "room" path at 24
// frames/s, one sample per pixel. `camera`: the calibrated camera.
std::vector<SynthSettings> sample_room_light_changes(const std::filesystem::path& scene, const CameraIntrinsics& camera,
                                                     const std::filesystem::path& out_dir);

// Writes the recording into settings.out (which must not exist yet). Throws
// InputError / RuntimeError; on failure the partial recording directory is removed.
void synthesize_recording(const SynthSettings& settings);

}  // namespace lumar::sim
