#include "lumar/sim/synthetic_sweep.h"

#include <spdlog/spdlog.h>
#include <cmath>
#include <memory>
#include <sstream>

#include "lumar/base/error.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/capture/session.h"
#include "lumar/envmap/sweep_path.h"
#include "lumar/scene/envmap.h"
#include "lumar/sim/envmap_view.h"
#include "lumar/tracking/simulated_tracker.h"

namespace lumar::sim {

namespace {

// Exposure that puts the map's mean luminance (solid-angle weighted) at 18 % grey.
double automatic_exposure(const EnvironmentMap& map, const std::string& name) {
  const double mean = mean_luminance(map);
  if (!(mean > 0) || !std::isfinite(mean)) throw InputError(name + ": the map is black or not finite; nothing to see");
  return 0.18 / mean;
}

// When each frame is taken and where the camera points at any moment.
struct SweepTiming {
  int frames = 0, per_station = 1, stations = 0;
  bool bracket = true;
  double period = 0, move = 0, margin = 0, station_length = 0;
  Nanos start = 0;

  Nanos frame_time(int k) const {
    if (!bracket) return start + seconds_to_nanos(k * period);
    const int m = k / per_station, j = k % per_station;
    return start + seconds_to_nanos(m * station_length + j * period);
  }
  double path_s(Nanos t) const {
    const double x = nanos_to_seconds(t - start);
    if (!bracket) return std::clamp((x / period + 0.5) / frames, 0.0, 1.0);
    const int m = std::max(0, int(std::floor(x / station_length)));
    const double local = x - m * station_length;
    const double still = (per_station - 1) * period + margin;  // the bracket and a margin
    double q = std::clamp((local - still) / move, 0.0, 1.0);
    q = q * q * (3.0 - 2.0 * q);  // start and stop smoothly
    return std::clamp((m + 0.5 + q) / stations, 0.0, 1.0);
  }
};

}  // namespace

std::vector<double> parse_exposure_stops(const std::string& text) {
  std::vector<double> stops;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v) || std::abs(v) > 24)
      throw InputError("--exposures " + text + ": expected stops relative to 18 % grey, e.g. 0,-5,-10");
    stops.push_back(v);
  }
  if (stops.empty()) throw InputError("--exposures: give at least one exposure, e.g. 0,-5,-10");
  return stops;
}

void synthesize_sweep(const SynthSettings& s, const SweepSynthSettings& sw) {
  if (s.frames < 2) throw InputError("--frames: need at least 2 frames");
  if (s.fps <= 0) throw InputError("--fps: must be positive");
  if (sw.exposure_mode != "bracket" && sw.exposure_mode != "cycle")
    throw InputError("--exposure-mode " + sw.exposure_mode + ": expected bracket or cycle");
  if (sw.exposure_stops.empty()) throw InputError("--exposures: give at least one exposure");
  if (std::filesystem::exists(s.out))
    throw InputError(s.out.string() + ": already exists; choose a new recording directory");
  const EnvironmentMap map = load_environment_map(sw.envmap);
  const double base = automatic_exposure(map, sw.envmap.string());
  std::vector<double> exposures;
  for (double stop : sw.exposure_stops) exposures.push_back(base * std::exp2(stop));

  SweepTiming timing;
  timing.frames = s.frames;
  timing.bracket = sw.exposure_mode == "bracket";
  timing.per_station = timing.bracket ? int(exposures.size()) : 1;
  timing.stations = (s.frames + timing.per_station - 1) / timing.per_station;
  timing.period = 1.0 / s.fps;
  // The camera holds still a little longer than one tracker interval around each
  // bracket, so that the poses interpolated for its frames are not pulled by the move.
  timing.margin = 0.025;
  timing.move = sw.move_seconds;
  timing.station_length = (timing.per_station - 1) * timing.period + timing.move + 2 * timing.margin;
  timing.start = seconds_to_nanos(0.1);  // the tracker runs before the first frame
  const Nanos duration = timing.frame_time(s.frames - 1) + seconds_to_nanos(0.2);
  auto true_camera = [&](Nanos t) { return Pose{calib::sweep_rotation(timing.path_s(t)), sw.capture_position}; };

  capture::Session session;
  session.camera = s.camera;
  session.rig.T_world_transmitter = Pose{axis_angle_deg({1, 0, 0}, 90), {0.45, 0.9, -0.55}};
  session.rig.T_sensor_camera = Pose{axis_angle_deg({0, 0, 1}, 90), {0.03, 0.05, -0.02}};
  session.rig.latency = seconds_to_nanos(s.latency_ms * 1e-3);
  session.radiometry.exposure = base;
  session.radiometry.vignetting_a = s.vignetting_a;
  session.radiometry.vignetting_b = s.vignetting_b;
  session.source = "lumar synth --sweep";
  session.frame_exposures = exposures;
  // Frames k = m n .. m n + n - 1 were taken standing still (one rotation).
  session.exposure_bracket = timing.bracket;
  session.envmap =
      capture::SweepInfo{sw.capture_position, map.azimuth_offset_deg, std::filesystem::absolute(sw.envmap).string()};
  session.synth = synth_info(s);
  session.synth->exposure_mode = sw.exposure_mode;
  session.synth->exposure_stops = sw.exposure_stops;

  const auto tracker = simulate_session_tracker(
      session, session.rig.latency, s.tracker_noise_deg, s.position_noise_m, s.seed,
      [&](Nanos t) { return session.rig.sensor_pose(true_camera(t)); }, duration);

  SensorModel sensor;
  sensor.read_noise = s.read_noise;
  sensor.shot_noise_gain = s.shot_noise_gain;
  sensor.vignetting_a = s.vignetting_a;
  sensor.vignetting_b = s.vignetting_b;
  const EnvmapViewRenderer view(s.camera, s.supersample);

  const capture::RecordingSettings video{
      .codec = s.codec, .quality = s.quality, .fps = s.fps, .size = cv::Size(s.camera.width, s.camera.height)};
  write_synthetic_recording(
      s.out, session, tracker, video, s.frames, s.seed, [&](int k) { return timing.frame_time(k); }, true_camera,
      [&](int k, Nanos, const Pose& T_world_camera, cv::RNG& rng) {
        const double exposure = exposures[std::size_t(k) % exposures.size()];
        return expose_8bit(view.render(map, T_world_camera.rotation), s.camera, sensor, exposure, rng);
      });
  spdlog::info("synth: wrote {} ({} frames, {} exposures, {} mode)", s.out.string(), s.frames, exposures.size(),
               sw.exposure_mode);
}

}  // namespace lumar::sim
