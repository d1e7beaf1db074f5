#pragma once
// What a recording's session.json says about how it was made: the camera, its
// radiometry, the tracker's settings and the rig. Format in docs/formats.md.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/rig.h"

namespace lumar::capture {

struct Radiometry {
  std::string response = "srgb";  // the default camera response until one is calibrated
  double exposure = 1.0;          // video linear value per unit of scene radiance
  // Vignetting gain 1 + a r^2 + b r^4, r = distance from the principal point over the
  // half-diagonal. {0, 0} = none.
  double vignetting_a = 0.0, vignetting_b = 0.0;
  // How long each frame's shutter was open, seconds: what the camera's motion and the
  // objects' blur over (the overlay's motion blur). 0: not known, no motion blur.
  double shutter_s = 0.0;
};

struct TrackerSettings {
  std::string device = "isotrak2";  // isotrak2 | fastrak
  std::string encoding = "ascii";   // ascii | binary
  std::vector<int> output_list{2, 4, 1};
  bool centimetres = false;
  int baud = 115200;
  double rate_hz = 60.0;
  int station = 1;
};

// "envmap": a sweep recorded to stitch an environment map.
struct SweepInfo {
  std::optional<glm::dvec3> capture_position;  // where the camera turned (else the tracker's mean position)
  double azimuth_offset_deg = 0.0;
  std::string source_map;  // the map a synthetic sweep was rendered from, to compare with ("" if none)
};

// "synth": how `lumar synth` made the recording; its tracker noise is read back as the
// prior of orientation refinement.
struct SynthInfo {
  int frames = 0;
  double fps = 0.0;
  double tracker_noise_deg = 0.75, position_noise_m = 0.0, read_noise = 0.0, shot_noise_gain = 0.0;
  double arc_deg = 0.0;                // an orbit's arc
  std::string path;                    // the camera's path: orbit | still
  std::string exposure_mode;           // a sweep's: bracket | cycle
  std::vector<double> exposure_stops;  // a sweep's
  std::uint64_t seed = 0;
};

// "synth_board": a synthetic board recording and the truth rig calibration should find.
struct BoardSynthInfo {
  std::string board;  // inner corners, "9x6"
  double square = 0.0, seconds = 0.0, fps = 0.0, tracker_noise_deg = 0.0, position_noise_m = 0.0, image_noise = 0.0;
  std::uint64_t seed = 0;
  tracking::Rig truth;  // T_world_transmitter, T_sensor_camera, latency
  Pose T_world_board;
};

// "capture": what `lumar record` recorded from.
struct CaptureInfo {
  std::string source, tracker;  // as given on the command line ("none": no tracker)
  bool camera_calibrated = false;
};

struct Session {
  CameraIntrinsics camera;
  Radiometry radiometry;
  TrackerSettings tracker;
  tracking::Rig rig;
  std::string scene;   // path of the scene manifest, relative to the recording (may be empty)
  std::string source;  // what made the recording: "lumar record", "lumar synth", ...
  // Video linear value per unit radiance per frame: frame k has entry k mod n (a camera
  // bracketing exposures). Empty: radiometry.exposure for every frame.
  std::vector<double> frame_exposures;
  bool exposure_bracket = false;  // the frames of one cycle of frame_exposures were taken standing still
  std::optional<SweepInfo> envmap;
  std::optional<SynthInfo> synth;
  std::optional<BoardSynthInfo> synth_board;
  std::optional<CaptureInfo> capture;

  // The exposure of frame `index`.
  double frame_exposure(std::int64_t index) const;
};

// The record format the tracker settings name. InputError naming `file` for an unknown
// device or encoding, or an output list the device cannot send.
tracking::TrackerFormat tracker_format_of(const TrackerSettings& settings, const std::string& file);

// The session's keys. Keys it does not know are left to whoever writes the file around it.
nlohmann::json session_to_json(const Session& session);
// Throws InputError naming `file` and the key on missing or bad values.
Session session_from_json(const nlohmann::json& j, const std::string& file);

// Reads a session.json file (a recording's, or one that only describes a rig). InputError
// naming the file when it is missing, malformed or not a session.
Session load_session_file(const std::filesystem::path& file);

// Reads DIR/session.json, lets `change` edit the session, and writes it back atomically
// with every key it does not know kept as it was, and `set_keys` set (for example a
// calibration's summary). InputError naming the file when it is missing or invalid, or
// when the edited session is.
void update_session_file(const std::filesystem::path& dir, const std::function<void(Session&)>& change,
                         const nlohmann::json& set_keys = nlohmann::json::object());

}  // namespace lumar::capture
