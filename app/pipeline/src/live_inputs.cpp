#include "lumar/pipeline/live_inputs.h"

#include <algorithm>
#include <filesystem>

#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/session.h"
#include "lumar/capture/source_spec.h"
#include "lumar/tracking/serial_transport.h"

namespace lumar::pipeline {

LiveSource open_live_source(const LiveInputOptions& o) {
  capture::SourceOptions so;
  so.timestamps = o.timestamps;
  so.fps = o.images_fps;
  so.v4l2.width = o.width;
  so.v4l2.height = o.height;
  so.v4l2.fps = o.camera_fps;
  if (!o.pixel_format.empty()) so.v4l2.formats = {o.pixel_format};
  so.v4l2.exposure_100us = o.exposure_100us;
  so.v4l2.gain = o.gain;
  so.v4l2.lock_exposure = !o.auto_exposure;
  capture::OpenedSource opened = capture::open_frame_source(o.source, so);
  if (opened.live) return {std::move(opened.source), true};
  return {std::make_unique<capture::RealTimeSource>(std::move(opened.source)), false};
}

std::shared_ptr<const capture::RecordingReplay> recorded_poses_of(const LiveInputOptions& o) {
  const std::string prefix = "recording:";
  if (!o.tracker.empty() || o.source.rfind(prefix, 0) != 0) return nullptr;
  return std::make_shared<const capture::RecordingReplay>(o.source.substr(prefix.size()));
}

std::unique_ptr<tracking::TrackerDriver> make_tracker_driver(const LiveInputOptions& o,
                                                             tracking::TrackerDriver::ByteObserver on_bytes) {
  if (o.tracker.empty()) return nullptr;
  const std::string prefix = "serial:";
  if (o.tracker.rfind(prefix, 0) != 0 || o.tracker.size() == prefix.size())
    throw InputError("--tracker '" + o.tracker + "' is not a serial port; use serial:/dev/ttyUSB0 (see lumar devices)");
  tracking::SerialSettings serial{o.tracker.substr(prefix.size()), o.baud, false};
  if (std::error_code ec; !std::filesystem::exists(serial.path, ec))
    throw InputError(serial.path + ": no such serial port; plug the tracker in or pick a port from `lumar devices`");
  if (!(o.latency_ms >= 0)) throw InputError("--latency-ms must be 0 or more");
  tracking::DriverSettings d;
  try {
    d.format = tracking::TrackerFormat::of(tracking::parse_device(o.tracker_model));
  } catch (const InputError& e) {
    throw InputError(std::string("--tracker-device: ") + e.what());
  }
  d.device_latency = seconds_to_nanos(o.latency_ms * 1e-3);
  tracking::validate_driver_settings(d);
  return std::make_unique<tracking::TrackerDriver>(d, tracking::serial_port(serial), std::move(on_bytes));
}

CameraIntrinsics live_camera(const LiveInputOptions& o, int width, int height) {
  if (!o.camera_file.empty()) {
    CameraIntrinsics c = calib::load_camera_file(o.camera_file).intrinsics;
    if (c.width != width || c.height != height)
      throw InputError(o.camera_file + ": calibrated for " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                       ", the source gives " + std::to_string(width) + "x" + std::to_string(height) +
                       "; calibrate at this size");
    return c;
  }
  CameraIntrinsics c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = width;  // about 53 degrees across: a typical webcam
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  return c;
}

tracking::Rig live_rig(const std::string& session_json, double latency_ms) {
  tracking::Rig rig;
  rig.latency = seconds_to_nanos(latency_ms * 1e-3);
  if (session_json.empty()) return rig;
  return capture::load_session_file(session_json).rig;
}

double source_shutter_s(const capture::FrameSource& source) {
  return std::min(1.0, nanos_to_seconds(source.shutter_time()));
}

nlohmann::json live_session(const LiveInputOptions& o, const CameraIntrinsics& camera,
                            const tracking::TrackerDriver* driver, double shutter_s) {
  capture::Session s;
  s.camera = camera;
  // The overlay blurs the objects' motion over it (docs/ground_truth.md, "Motion blur").
  s.radiometry.shutter_s = shutter_s;
  s.rig.latency = seconds_to_nanos(o.latency_ms * 1e-3);
  if (driver) {
    const auto& f = driver->settings().format;
    s.tracker.device = tracking::device_name(f.device);
    s.tracker.encoding = f.binary ? "binary" : "ascii";
    s.tracker.output_list = f.output.output_list;
    s.tracker.centimetres = f.output.centimetres;
    s.tracker.baud = o.baud;
    s.tracker.rate_hz = f.device == tracking::Device::Fastrak ? 120.0 : 60.0;
    s.tracker.station = driver->settings().stations.front();
  }
  s.source = "lumar record";
  s.capture = capture::CaptureInfo{o.source, o.tracker.empty() ? "none" : o.tracker, !o.camera_file.empty()};
  nlohmann::json j = capture::session_to_json(s);
  if (!driver) j.erase("tracker");  // no tracker settings: the recording has no tracker stream
  return j;
}

}  // namespace lumar::pipeline
