#include "lumar/capture/session.h"

#include <cmath>

#include "lumar/base/error.h"

namespace lumar::capture {

using nlohmann::json;

json session_to_json(const Session& s) {
  const CameraIntrinsics& c = s.camera;
  json j = s.extra;
  j["camera"] = {{"width", c.width}, {"height", c.height},        {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx},
                 {"cy", c.cy},       {"distortion", c.distortion}};
  j["radiometry"] = {{"response", s.radiometry.response},
                     {"exposure", s.radiometry.exposure},
                     {"vignetting", {s.radiometry.vignetting_a, s.radiometry.vignetting_b}}};
  j["tracker"] = {{"device", s.tracker.device},
                  {"encoding", s.tracker.encoding},
                  {"output_list", s.tracker.output_list},
                  {"units", s.tracker.centimetres ? "centimetres" : "inches"},
                  {"baud", s.tracker.baud},
                  {"rate_hz", s.tracker.rate_hz},
                  {"station", s.tracker.station}};
  j["rig"] = {{"T_world_transmitter", tracking::pose_to_json(s.rig.T_world_transmitter)},
              {"T_sensor_camera", tracking::pose_to_json(s.rig.T_sensor_camera)},
              {"latency_ns", s.rig.latency}};
  j["scene"] = s.scene;
  return j;
}

namespace {

template <class T>
T get(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) throw InputError(where + "." + key + ": missing");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    throw InputError(where + "." + key + ": wrong type");
  }
}

double finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw InputError(what + ": not a finite number");
  return v;
}

Session parse_session(const json& j, const std::string& file) {
  if (!j.is_object()) throw InputError(file + ": expected a JSON object");
  Session s;
  const json& cam = j.contains("camera") ? j["camera"] : throw InputError(file + ": camera: missing");
  const std::string w = file + ": camera";
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
    const json& r = j["radiometry"];
    const std::string wr = file + ": radiometry";
    s.radiometry.response = r.value("response", s.radiometry.response);
    s.radiometry.exposure = finite(r.value("exposure", 1.0), wr + ".exposure");
    if (s.radiometry.exposure <= 0) throw InputError(wr + ".exposure: must be positive");
    if (r.contains("vignetting")) {
      const auto v = get<std::vector<double>>(r, "vignetting", wr);
      if (v.size() != 2) throw InputError(wr + ".vignetting: expected [a, b]");
      s.radiometry.vignetting_a = finite(v[0], wr + ".vignetting");
      s.radiometry.vignetting_b = finite(v[1], wr + ".vignetting");
    }
  }
  if (j.contains("tracker")) {
    const json& t = j["tracker"];
    const std::string wt = file + ": tracker";
    s.tracker.device = t.value("device", s.tracker.device);
    s.tracker.encoding = t.value("encoding", s.tracker.encoding);
    if (t.contains("output_list")) s.tracker.output_list = get<std::vector<int>>(t, "output_list", wt);
    const std::string units = t.value("units", std::string("inches"));
    if (units != "inches" && units != "centimetres")
      throw InputError(wt + ".units: expected \"inches\" or \"centimetres\"");
    s.tracker.centimetres = units == "centimetres";
    s.tracker.baud = t.value("baud", s.tracker.baud);
    s.tracker.rate_hz = t.value("rate_hz", s.tracker.rate_hz);
    s.tracker.station = t.value("station", s.tracker.station);
    if (s.tracker.baud <= 0) throw InputError(wt + ".baud: must be positive");
  }
  if (j.contains("rig")) {
    const json& r = j["rig"];
    const std::string wr = file + ": rig";
    if (r.contains("T_world_transmitter"))
      s.rig.T_world_transmitter = tracking::pose_from_json(r["T_world_transmitter"], wr + ".T_world_transmitter");
    if (r.contains("T_sensor_camera"))
      s.rig.T_sensor_camera = tracking::pose_from_json(r["T_sensor_camera"], wr + ".T_sensor_camera");
    s.rig.latency = r.value("latency_ns", Nanos(0));
  }
  s.scene = j.value("scene", std::string());
  s.extra = j;
  for (const char* k : {"camera", "radiometry", "tracker", "rig", "scene"}) s.extra.erase(k);
  return s;
}

}  // namespace

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
    throw InputError(file + ": unexpected value (" + e.what() + ")");
  }
}

}  // namespace lumar::capture
