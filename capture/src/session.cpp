#include "lumar/capture/session.h"

#include <cmath>
#include <fstream>

#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/base/output_file.h"
#include "lumar/capture/recording_format.h"

namespace lumar::capture {

using nlohmann::json;

namespace {

json vec3_json(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

json rig_json(const tracking::Rig& rig) {
  return {{"T_world_transmitter", tracking::pose_to_json(rig.T_world_transmitter)},
          {"T_sensor_camera", tracking::pose_to_json(rig.T_sensor_camera)},
          {"latency_ns", rig.latency}};
}

template <class T>
T get(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) throw InputError(where + "." + key + ": missing");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    throw InputError(where + "." + key + ": wrong type");
  }
}

// The value of an optional key, or `fallback`; InputError for a wrong type.
template <class T>
T get_or(const json& j, const char* key, T fallback, const std::string& where) {
  return j.contains(key) ? get<T>(j, key, where) : fallback;
}

double finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw InputError(what + ": not a finite number");
  return v;
}

const json& object(const json& j, const char* key, const std::string& where) {
  const json& v = j.at(key);
  if (!v.is_object()) throw InputError(where + "." + key + ": expected an object");
  return v;
}

tracking::Rig parse_rig(const json& r, const std::string& where) {
  tracking::Rig rig;
  if (r.contains("T_world_transmitter"))
    rig.T_world_transmitter = tracking::pose_from_json(r.at("T_world_transmitter"), where + ".T_world_transmitter");
  if (r.contains("T_sensor_camera"))
    rig.T_sensor_camera = tracking::pose_from_json(r.at("T_sensor_camera"), where + ".T_sensor_camera");
  rig.latency = get_or<Nanos>(r, "latency_ns", 0, where);
  return rig;
}

Session parse_session(const json& j, const std::string& file) {
  if (!j.is_object()) throw InputError(file + ": expected a JSON object");
  Session s;
  if (!j.contains("camera")) throw InputError(file + ": camera: missing");
  const std::string w = file + ": camera";
  const json& cam = object(j, "camera", file + ":");
  s.camera.width = get<int>(cam, "width", w);
  s.camera.height = get<int>(cam, "height", w);
  s.camera.fx = finite(get<double>(cam, "fx", w), w + ".fx");
  s.camera.fy = finite(get<double>(cam, "fy", w), w + ".fy");
  s.camera.cx = finite(get<double>(cam, "cx", w), w + ".cx");
  s.camera.cy = finite(get<double>(cam, "cy", w), w + ".cy");
  const auto d = get<std::vector<double>>(cam, "distortion", w);
  if (d.size() != 4 && d.size() != 5) throw InputError(w + ".distortion: expected 4 or 5 numbers");
  for (std::size_t i = 0; i < d.size(); ++i) s.camera.distortion[i] = finite(d[i], w + ".distortion");
  if (!s.camera.is_valid()) throw InputError(w + ": size and focal lengths must be positive");

  if (j.contains("radiometry")) {
    const std::string wr = file + ": radiometry";
    const json& r = object(j, "radiometry", file + ":");
    s.radiometry.response = get_or<std::string>(r, "response", s.radiometry.response, wr);
    s.radiometry.exposure = finite(get_or<double>(r, "exposure", 1.0, wr), wr + ".exposure");
    if (s.radiometry.exposure <= 0) throw InputError(wr + ".exposure: must be positive");
    if (r.contains("vignetting")) {
      const auto v = get<std::vector<double>>(r, "vignetting", wr);
      if (v.size() != 2) throw InputError(wr + ".vignetting: expected [a, b]");
      s.radiometry.vignetting_a = finite(v[0], wr + ".vignetting");
      s.radiometry.vignetting_b = finite(v[1], wr + ".vignetting");
    }
    s.radiometry.shutter_s = finite(get_or<double>(r, "shutter_s", 0.0, wr), wr + ".shutter_s");
    if (s.radiometry.shutter_s < 0 || s.radiometry.shutter_s > 1)
      throw InputError(wr + ".shutter_s: must be from 0 (not known) to 1 second");
  }
  if (j.contains("tracker")) {
    const std::string wt = file + ": tracker";
    const json& t = object(j, "tracker", file + ":");
    s.tracker.device = get_or<std::string>(t, "device", s.tracker.device, wt);
    s.tracker.encoding = get_or<std::string>(t, "encoding", s.tracker.encoding, wt);
    s.tracker.output_list = get_or<std::vector<int>>(t, "output_list", s.tracker.output_list, wt);
    const std::string units = get_or<std::string>(t, "units", "inches", wt);
    if (units != "inches" && units != "centimetres")
      throw InputError(wt + ".units: expected \"inches\" or \"centimetres\"");
    s.tracker.centimetres = units == "centimetres";
    s.tracker.baud = get_or<int>(t, "baud", s.tracker.baud, wt);
    s.tracker.rate_hz = get_or<double>(t, "rate_hz", s.tracker.rate_hz, wt);
    s.tracker.station = get_or<int>(t, "station", s.tracker.station, wt);
    if (s.tracker.baud <= 0) throw InputError(wt + ".baud: must be positive");
  }
  if (j.contains("rig")) s.rig = parse_rig(object(j, "rig", file + ":"), file + ": rig");
  s.scene = get_or<std::string>(j, "scene", "", file + ":");
  s.source = get_or<std::string>(j, "source", "", file + ":");

  s.frame_exposures = get_or<std::vector<double>>(j, "frame_exposures", {}, file + ":");
  for (double e : s.frame_exposures)
    if (!(e > 0) || !std::isfinite(e)) throw InputError(file + ": frame_exposures: every value must be positive");
  s.exposure_bracket = get_or<bool>(j, "exposure_bracket", false, file + ":");
  if (j.contains("envmap")) {
    const std::string we = file + ": envmap";
    const json& e = object(j, "envmap", file + ":");
    SweepInfo sweep;
    if (e.contains("capture_position")) {
      const auto p = get<std::vector<double>>(e, "capture_position", we);
      if (p.size() != 3) throw InputError(we + ".capture_position: expected 3 numbers");
      sweep.capture_position = glm::dvec3(finite(p[0], we), finite(p[1], we), finite(p[2], we));
    }
    sweep.azimuth_offset_deg = finite(get_or<double>(e, "azimuth_offset_deg", 0.0, we), we + ".azimuth_offset_deg");
    sweep.source_map = get_or<std::string>(e, "source_map", "", we);
    s.envmap = sweep;
  }
  if (j.contains("synth")) {
    const std::string ws = file + ": synth";
    const json& y = object(j, "synth", file + ":");
    SynthInfo synth;
    synth.frames = get_or<int>(y, "frames", 0, ws);
    synth.fps = get_or<double>(y, "fps", 0.0, ws);
    synth.tracker_noise_deg = get_or<double>(y, "tracker_noise_deg", synth.tracker_noise_deg, ws);
    if (!(synth.tracker_noise_deg >= 0)) throw InputError(ws + ".tracker_noise_deg: must be 0 or more");
    synth.position_noise_m = get_or<double>(y, "position_noise_m", 0.0, ws);
    synth.read_noise = get_or<double>(y, "read_noise", 0.0, ws);
    synth.shot_noise_gain = get_or<double>(y, "shot_noise_gain", 0.0, ws);
    synth.arc_deg = get_or<double>(y, "arc_deg", 0.0, ws);
    synth.path = get_or<std::string>(y, "path", "", ws);
    synth.exposure_mode = get_or<std::string>(y, "exposure_mode", "", ws);
    synth.exposure_stops = get_or<std::vector<double>>(y, "exposure_stops", {}, ws);
    synth.seed = get_or<std::uint64_t>(y, "seed", 0, ws);
    s.synth = synth;
  }
  if (j.contains("synth_board")) {
    const std::string wb = file + ": synth_board";
    const json& b = object(j, "synth_board", file + ":");
    BoardSynthInfo board;
    board.board = get_or<std::string>(b, "board", "", wb);
    board.square = get_or<double>(b, "square", 0.0, wb);
    board.seconds = get_or<double>(b, "seconds", 0.0, wb);
    board.fps = get_or<double>(b, "fps", 0.0, wb);
    board.tracker_noise_deg = get_or<double>(b, "tracker_noise_deg", 0.0, wb);
    board.position_noise_m = get_or<double>(b, "position_noise_m", 0.0, wb);
    board.image_noise = get_or<double>(b, "image_noise", 0.0, wb);
    board.seed = get_or<std::uint64_t>(b, "seed", 0, wb);
    if (b.contains("truth")) {
      const json& truth = object(b, "truth", wb);
      board.truth = parse_rig(truth, wb + ".truth");
      if (truth.contains("T_world_board"))
        board.T_world_board = tracking::pose_from_json(truth.at("T_world_board"), wb + ".truth.T_world_board");
    }
    s.synth_board = board;
  }
  if (j.contains("capture")) {
    const std::string wc = file + ": capture";
    const json& c = object(j, "capture", file + ":");
    s.capture = CaptureInfo{get_or<std::string>(c, "source", "", wc), get_or<std::string>(c, "tracker", "", wc),
                            get_or<bool>(c, "camera_calibrated", false, wc)};
  }
  return s;
}

}  // namespace

double Session::frame_exposure(std::int64_t index) const {
  if (frame_exposures.empty()) return radiometry.exposure;
  return frame_exposures[std::size_t(std::max<std::int64_t>(0, index)) % frame_exposures.size()];
}

json session_to_json(const Session& s) {
  const CameraIntrinsics& c = s.camera;
  json j = json::object();
  j["camera"] = {{"width", c.width}, {"height", c.height},        {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx},
                 {"cy", c.cy},       {"distortion", c.distortion}};
  j["radiometry"] = {{"response", s.radiometry.response},
                     {"exposure", s.radiometry.exposure},
                     {"vignetting", {s.radiometry.vignetting_a, s.radiometry.vignetting_b}}};
  if (s.radiometry.shutter_s > 0) j["radiometry"]["shutter_s"] = s.radiometry.shutter_s;
  j["tracker"] = {{"device", s.tracker.device},
                  {"encoding", s.tracker.encoding},
                  {"output_list", s.tracker.output_list},
                  {"units", s.tracker.centimetres ? "centimetres" : "inches"},
                  {"baud", s.tracker.baud},
                  {"rate_hz", s.tracker.rate_hz},
                  {"station", s.tracker.station}};
  j["rig"] = rig_json(s.rig);
  j["scene"] = s.scene;
  if (!s.source.empty()) j["source"] = s.source;
  if (!s.frame_exposures.empty()) j["frame_exposures"] = s.frame_exposures;
  if (s.exposure_bracket) j["exposure_bracket"] = true;
  if (s.envmap) {
    json e = {{"azimuth_offset_deg", s.envmap->azimuth_offset_deg}};
    if (s.envmap->capture_position) e["capture_position"] = vec3_json(*s.envmap->capture_position);
    if (!s.envmap->source_map.empty()) e["source_map"] = s.envmap->source_map;
    j["envmap"] = e;
  }
  if (s.synth) {
    const SynthInfo& y = *s.synth;
    json o = {{"frames", y.frames},
              {"fps", y.fps},
              {"tracker_noise_deg", y.tracker_noise_deg},
              {"position_noise_m", y.position_noise_m},
              {"read_noise", y.read_noise},
              {"shot_noise_gain", y.shot_noise_gain},
              {"seed", y.seed}};
    if (y.arc_deg != 0) o["arc_deg"] = y.arc_deg;
    if (!y.path.empty()) o["path"] = y.path;
    if (!y.exposure_mode.empty()) o["exposure_mode"] = y.exposure_mode;
    if (!y.exposure_stops.empty()) o["exposure_stops"] = y.exposure_stops;
    j["synth"] = o;
  }
  if (s.synth_board) {
    const BoardSynthInfo& b = *s.synth_board;
    json truth = rig_json(b.truth);
    truth["T_world_board"] = tracking::pose_to_json(b.T_world_board);
    j["synth_board"] = {{"board", b.board},
                        {"square", b.square},
                        {"seconds", b.seconds},
                        {"fps", b.fps},
                        {"tracker_noise_deg", b.tracker_noise_deg},
                        {"position_noise_m", b.position_noise_m},
                        {"image_noise", b.image_noise},
                        {"seed", b.seed},
                        {"truth", truth}};
  }
  if (s.capture)
    j["capture"] = {{"source", s.capture->source},
                    {"tracker", s.capture->tracker},
                    {"camera_calibrated", s.capture->camera_calibrated}};
  return j;
}

tracking::TrackerFormat tracker_format_of(const TrackerSettings& t, const std::string& file) {
  if (t.encoding != "ascii" && t.encoding != "binary")
    throw InputError(file + ": tracker encoding '" + t.encoding + "' is unknown; use ascii or binary");
  try {
    const auto format = tracking::TrackerFormat::of(tracking::parse_device(t.device), t.encoding == "binary",
                                                    {t.output_list, t.centimetres});
    tracking::validate_tracker_format(format);
    return format;
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
}

Session session_from_json(const json& j, const std::string& file) {
  try {
    return parse_session(j, file);
  } catch (const json::exception& e) {
    throw InputError(file + ": unexpected value (" + json_error_text(e) + ")");
  }
}

Session load_session_file(const std::filesystem::path& file) {
  return session_from_json(read_json_file(file, "session file"), file.string());
}

void update_session_file(const std::filesystem::path& dir, const std::function<void(Session&)>& change,
                         const json& set_keys) {
  const std::filesystem::path file = dir / kSessionFile;
  json j = read_json_file(file, "session file");
  Session session = session_from_json(j, file.string());
  change(session);
  const json updated = session_to_json(session);
  session_from_json(updated, file.string());  // the edit must still read as a session
  for (const auto& [key, value] : updated.items()) j[key] = value;
  for (const auto& [key, value] : set_keys.items()) j[key] = value;
  write_file_atomically(file, j.dump(2) + "\n");
}

}  // namespace lumar::capture
