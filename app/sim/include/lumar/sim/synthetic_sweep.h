#pragma once
// `lumar synth --sweep`: a recording of a lat-long map alone (at infinity) seen by the
// calibrated camera turning about the map's capture point along a spiral of elevation
// rings (calib/sweep_path.h), through the sensor model (vignetting, noise, 8-bit
// clipping) at several exposures, with the ISOTRAK II byte stream a tracker on the
// camera would send and the true poses. `lumar envmap --recording` reconstructs the map.
//
// Exposures: session.json "frame_exposures" lists them (video linear value per unit
// radiance); frame k was taken with entry k mod n. In "bracket" mode ("exposure_bracket":
// true) the camera stops
// at each station and takes the n exposures there (frames k = m n .. m n + n - 1), then
// moves on while no frame is taken; in "cycle" mode it moves steadily and the exposure
// changes every frame.
#include <filesystem>
#include <string>
#include <vector>

#include "lumar/sim/synthetic_recording.h"

namespace lumar::sim {

struct SweepSynthSettings {
  std::filesystem::path envmap;
  std::vector<double> exposure_stops{0.0, -5.0, -10.0};  // relative to 18 % grey of the map's mean
  std::string exposure_mode = "bracket";                 // bracket | cycle
  double move_seconds = 0.25;                            // bracket: time between stations
  glm::dvec3 capture_position{0.0, 1.5, 0.0};
};

// Parses "0,-5,-10" (stops); InputError on anything else.
std::vector<double> parse_exposure_stops(const std::string& text);

// Writes the recording into shared.out (which must not exist yet). Uses from `shared`:
// out, camera, frames, fps, noise, vignetting, tracker noise and latency, codec, seed.
// Throws InputError / RuntimeError; on failure the partial recording is removed.
void synthesize_sweep(const SynthSettings& shared, const SweepSynthSettings& sweep);

}  // namespace lumar::sim
