// lumar tracker record: drive a tracker on a serial port and record what it says: the
// raw bytes with their arrival times (tracker.raw, crash-safe chunks) and the decoded
// poses (poses.csv), in a tracker-only recording directory.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/tracking/tracker_driver.h"

namespace lumar::app {

namespace {

struct RecordOptions {
  std::string device;
  std::string out;
  std::string model = "isotrak2";
  int baud = 115200;
  bool rts_cts = false;
  bool binary = false;
  std::string units = "in";
  std::string list = "2,4,1";
  std::string stations = "1";
  double poll_hz = 0;
  double latency_ms = 0;
  double watchdog_s = 2;
  double reinit_wait_s = 8;
  double duration_s = 0;
};

std::string port_from_device(const std::string& device) {
  const std::string prefix = "serial:";
  std::string path = device.rfind(prefix, 0) == 0 ? device.substr(prefix.size()) : device;
  if (path.empty() || path[0] != '/')
    throw InputError("--port '" + device + "' is not a serial port; use serial:/dev/ttyUSB0 (see lumar devices)");
  return path;
}

void run_record(const RecordOptions& o) {
  tracking::DriverSettings d;
  tracking::OutputFormat output;
  tracking::Device device;
  // Name the option in the message: the parsers only know the value.
  try {
    output.output_list = tracking::parse_output_list(o.list);
    tracking::validate_output_format(output);
  } catch (const InputError& e) {
    throw InputError(std::string("--list: ") + e.what());
  }
  try {
    device = tracking::parse_device(o.model);
  } catch (const InputError& e) {
    throw InputError(std::string("--device: ") + e.what());
  }
  if (o.units != "in" && o.units != "cm") throw InputError("--units '" + o.units + "' is unknown; use in or cm");
  output.centimetres = o.units == "cm";
  d.format = tracking::TrackerFormat::of(device, o.binary, output);
  try {
    d.stations = tracking::parse_output_list(o.stations);
  } catch (const InputError&) {
    throw InputError("--stations '" + o.stations + "' is not a comma-separated list of station numbers, e.g. 1,2");
  }
  d.continuous = o.poll_hz <= 0;
  if (!d.continuous) d.poll_rate_hz = o.poll_hz;
  for (double v : {o.latency_ms, o.reinit_wait_s, o.duration_s})
    if (!(v >= 0)) throw InputError("--latency-ms, --reinit-wait and --duration must be 0 or more");
  if (!(o.watchdog_s > 0)) throw InputError("--watchdog must be more than 0 seconds");
  d.device_latency = seconds_to_nanos(o.latency_ms * 1e-3);
  d.watchdog = seconds_to_nanos(o.watchdog_s);
  d.reinit_wait = seconds_to_nanos(o.reinit_wait_s);
  tracking::validate_driver_settings(d);
  tracking::SerialSettings serial{port_from_device(o.device), o.baud, o.rts_cts};
  // Missing at the start is a typo or an unplugged device, and a file that is not a
  // serial port is a wrong path: say so now. Later the driver waits for a vanished port.
  if (std::error_code ec; !std::filesystem::exists(serial.path, ec))
    throw InputError(serial.path + ": no such serial port; plug the tracker in or pick a port from `lumar devices`");
  try {
    tracking::SerialTransport probe(serial);
  } catch (const tracking::DeviceVanished&) {
  } catch (const RuntimeError& e) {
    throw InputError(e.what());
  }
  const auto& bauds = tracking::supported_bauds();
  if (std::find(bauds.begin(), bauds.end(), serial.baud) == bauds.end())
    throw InputError("--baud " + std::to_string(serial.baud) +
                     " is not supported; use 9600, 19200, 38400, 57600 or 115200");

  // The tracker part of session.json uses the keys of capture/session.h, so replay
  // tools decode tracker.raw with the settings the device was given.
  nlohmann::json session = {
      {"tracker_only", true},
      {"tracker",
       {{"device", tracking::device_name(d.format.device)},
        {"encoding", d.format.binary ? "binary" : "ascii"},
        {"output_list", output.output_list},
        {"units", output.centimetres ? "centimetres" : "inches"},
        {"baud", serial.baud},
        {"rate_hz", d.continuous ? (d.format.device == tracking::Device::Fastrak ? 120.0 : 60.0) : d.poll_rate_hz},
        {"station", d.stations.front()},
        {"stations", d.stations},
        {"port", serial.path},
        {"mode", d.continuous ? "continuous" : "polled"}}},
      {"rig", {{"latency_ns", d.device_latency}}}};
  capture::RecordingSettings video;  // no frames are written; the writer wants a nominal size
  video.size = {1, 1};
  capture::RecordingWriter writer(o.out, session, video);

  catch_stop_signals();
  const Nanos start = monotonic_now();
  tracking::TrackerDriver driver(d, tracking::serial_port(serial), [&](const tracking::ByteChunk& chunk) {
    tracking::ByteChunk since_start{chunk.arrival - start, chunk.bytes};
    writer.add_tracker_bytes(since_start);
  });
  driver.start();
  std::printf("recording %s from %s into %s; Ctrl-C to stop\n", tracking::device_name(d.format.device).c_str(),
              serial.path.c_str(), o.out.c_str());
  std::fflush(stdout);

  std::vector<tracking::PoseSample> samples;
  std::uint64_t poses = 0;
  tracking::TrackerState last_state = tracking::TrackerState::stopped;
  std::string last_message;
  auto drain = [&] {
    samples.clear();
    driver.take_samples(samples);
    for (auto s : samples) {
      s.time -= start;
      writer.add_pose(s);
      ++poses;
    }
  };
  const Nanos end = o.duration_s > 0 ? start + seconds_to_nanos(o.duration_s) : 0;
  while (!stop_requested() && (end == 0 || monotonic_now() < end)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    drain();
    const auto st = driver.status();
    if (st.state != last_state || (st.state != tracking::TrackerState::connected && st.message != last_message)) {
      spdlog::info("tracker: {} ({})", tracking::state_name(st.state), st.message);
      last_state = st.state;
      last_message = st.message;
    }
  }
  driver.stop();
  drain();
  writer.close();
  const auto st = driver.status();
  spdlog::info(
      "record: {} poses; {} records, {} rejected, {} skipped bytes, {} bytes read; {} connections, {} "
      "watchdog faults, {} failed resets",
      poses, st.records, st.rejected_records, st.skipped_bytes, st.bytes_read, st.connects, st.watchdog_faults,
      st.reset_attempts);
}

}  // namespace

void register_tracker_record(CLI::App& tracker) {
  auto o = std::make_shared<RecordOptions>();
  auto* cmd = tracker.add_subcommand("record", "Record a tracker's raw bytes and decoded poses until Ctrl-C");
  cmd->add_option("--port", o->device, "Serial port, e.g. serial:/dev/ttyUSB0")->required();
  cmd->add_option("--out", o->out, "Recording directory to create (must not exist)")->required();
  cmd->add_option("--device", o->model, "Tracker: isotrak2 or fastrak")->capture_default_str();
  cmd->add_option("--baud", o->baud, "Line speed (the device's DIP switches)")->capture_default_str();
  cmd->add_flag("--rts-cts", o->rts_cts, "Hardware flow control");
  cmd->add_flag("--binary", o->binary, "Ask for binary records (`f`) instead of ASCII");
  cmd->add_option("--units", o->units, "Ask for in (inches) or cm")->capture_default_str();
  cmd->add_option("--list", o->list, "Output list to set (`O` command), e.g. 2,4,1 or 2,11,1")->capture_default_str();
  cmd->add_option("--stations", o->stations, "Stations to configure, e.g. 1,2")->capture_default_str();
  cmd->add_option("--poll", o->poll_hz, "Poll with P at this rate instead of continuous mode (0: continuous)")
      ->capture_default_str();
  cmd->add_option("--latency-ms", o->latency_ms, "Device latency subtracted from pose times")->capture_default_str();
  cmd->add_option("--watchdog", o->watchdog_s, "Seconds without a valid record before resetting")
      ->capture_default_str();
  cmd->add_option("--reinit-wait", o->reinit_wait_s, "Seconds to wait after Ctrl-Y")->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Stop after this many seconds (0: at Ctrl-C or SIGTERM)")
      ->capture_default_str();
  add_action(cmd, [o] { run_record(*o); });
}

}  // namespace lumar::app
