#pragma once
// What a recording's session.json says about how it was made: the camera, its
// radiometry, the tracker's settings and the rig. Format in docs/formats.md.
#include <filesystem>
#include <nlohmann/json.hpp>
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

struct Session {
  CameraIntrinsics camera;
  Radiometry radiometry;
  TrackerSettings tracker;
  tracking::Rig rig;
  std::string scene;  // path of the scene manifest, relative to the recording (may be empty)
  nlohmann::json extra = nlohmann::json::object();  // anything else the writer added
};

// The record format the tracker settings name. InputError naming `file` for an unknown
// device or encoding, or an output list the device cannot send.
tracking::TrackerFormat tracker_format_of(const TrackerSettings& settings, const std::string& file);

nlohmann::json session_to_json(const Session& session);
// Throws InputError naming `file` and the key on missing or bad values.
Session session_from_json(const nlohmann::json& j, const std::string& file);

}  // namespace lumar::capture
