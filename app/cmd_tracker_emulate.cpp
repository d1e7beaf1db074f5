// lumar tracker emulate: a Polhemus ISOTRAK II / Fastrak on a pseudo-terminal, for
// driving the real serial code (or any serial program) without the hardware.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"
#include "lumar/tracking/tracker_decode.h"
#include "lumar/tracking/tracker_emulator.h"

namespace lumar::app {

namespace {

struct EmulateOptions {
  std::string model = "isotrak2";
  std::string link;
  int baud = 115200;
  double rate_hz = 0;
  std::string stations = "1";
  bool continuous = false;
  std::string trajectory = "sweep";
  double orientation_noise_deg = 0.75;
  double position_noise_m = 0.0025;
  double latency_ms = 20;
  std::uint64_t seed = 1;
  double reinit_s = 3;
  double garbage = 0, drop = 0;
  double silence_every_s = 0, silence_for_s = 0;
  double disconnect_every_s = 0, disconnect_for_s = 0;
  double duration_s = 0;
  std::string sent_log;
};

tracking::Device model_option(const std::string& name) {
  try {
    return tracking::parse_device(name);
  } catch (const InputError& e) {
    throw InputError(std::string("--device: ") + e.what());
  }
}

std::vector<int> parse_stations(const std::string& text) {
  try {
    return tracking::parse_output_list(text);
  } catch (const InputError&) {
    throw InputError("--stations '" + text + "' is not a comma-separated list of station numbers, e.g. 1,2");
  }
}

// The record as the host decodes it, in `lumar tracker decode`'s CSV form.
std::string decoded_row(const tracking::SentRecord& r) {
  std::ostringstream csv;
  const tracking::ByteChunk chunk{0, r.bytes};
  tracking::decode_to_csv(std::span(&chunk, 1), r.format, csv);
  const std::string text = csv.str();
  const std::size_t first = text.find('\n');
  return first == std::string::npos ? std::string() : text.substr(first + 1);
}

void run_emulate(const EmulateOptions& o) {
  tracking::EmulatorSettings s;
  s.device = model_option(o.model);
  s.baud = o.baud;
  s.rate_hz = o.rate_hz;
  s.stations = parse_stations(o.stations);
  s.continuous_at_power_up = o.continuous;
  s.orientation_noise_deg = o.orientation_noise_deg;
  s.position_noise_m = o.position_noise_m;
  if (!(o.latency_ms >= 0)) throw InputError("--latency-ms must not be negative");
  s.device_latency = seconds_to_nanos(o.latency_ms * 1e-3);
  s.seed = o.seed;
  s.reinit_silence = seconds_to_nanos(std::max(o.reinit_s, 0.0));
  const auto& names = tracking::builtin_trajectory_names();
  s.trajectory = std::find(names.begin(), names.end(), o.trajectory) != names.end()
                     ? tracking::builtin_trajectory(o.trajectory)
                     : tracking::load_trajectory_csv(o.trajectory);
  s.link = o.link;
  s.faults.garbage_rate = o.garbage;
  s.faults.drop_rate = o.drop;
  for (double v : {o.silence_every_s, o.silence_for_s, o.disconnect_every_s, o.disconnect_for_s, o.duration_s})
    if (!(v >= 0)) throw InputError("fault periods and --duration must be 0 or more seconds");
  s.faults.silence_every = seconds_to_nanos(o.silence_every_s);
  s.faults.silence_for = seconds_to_nanos(o.silence_for_s);
  s.faults.disconnect_every = seconds_to_nanos(o.disconnect_every_s);
  s.faults.disconnect_for = seconds_to_nanos(o.disconnect_for_s);

  std::unique_ptr<std::ofstream> log;
  std::mutex log_mutex;
  if (!o.sent_log.empty()) {
    log = std::make_unique<std::ofstream>(o.sent_log, std::ios::trunc);
    if (!*log) throw InputError(o.sent_log + ": cannot be created; check the folder exists and is writable");
    *log << tracking::kDecodeCsvHeader << '\n' << std::flush;
  }
  auto on_record = [&](const tracking::SentRecord& r) {
    if (!log || r.dropped || r.cut_short || r.garbage_bytes > 0) return;
    const std::string row = decoded_row(r);
    std::lock_guard lock(log_mutex);
    *log << row << std::flush;
  };

  catch_stop_signals();
  tracking::TrackerEmulator emulator(s, on_record);
  const auto describe = [&](const std::string& port) {
    std::printf("%s %s on %s", tracking::device_name(s.device).c_str(), port.empty() ? "disconnected" : "ready",
                port.empty() ? "-" : port.c_str());
    if (!o.link.empty()) std::printf(" (link %s)", o.link.c_str());
    std::printf("\n");
    std::fflush(stdout);
  };
  std::string port = emulator.port_path();
  describe(port);
  const Nanos end = o.duration_s > 0 ? monotonic_now() + seconds_to_nanos(o.duration_s) : 0;
  while (!stop_requested() && (end == 0 || monotonic_now() < end)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (const std::string now = emulator.port_path(); now != port) describe(port = now);
    if (const std::string why = emulator.failure(); !why.empty()) throw RuntimeError("emulator stopped: " + why);
  }
  emulator.stop();
  const auto c = emulator.counters();
  spdlog::info(
      "emulate: {} records sent ({} dropped, {} with garbage, {} cut short), {} commands, {} status replies, "
      "{} reinitialisations, {} disconnections",
      c.records_sent, c.records_dropped, c.records_damaged, c.records_cut_short, c.commands, c.status_replies,
      c.reinits, c.disconnects);
}

}  // namespace

void register_tracker_emulate(CLI::App& tracker) {
  auto o = std::make_shared<EmulateOptions>();
  auto* cmd = tracker.add_subcommand(
      "emulate", "Run an emulated ISOTRAK II / Fastrak on a pseudo-terminal (prints its path) until Ctrl-C");
  cmd->add_option("--device", o->model, "Device: isotrak2 or fastrak")->capture_default_str();
  cmd->add_option("--link", o->link, "Also make this symlink to the pty (follows it across reconnections)");
  cmd->add_option("--baud", o->baud, "Line speed the output is paced at")->capture_default_str();
  cmd->add_option("--rate", o->rate_hz, "Records per second over all stations (0: 60 ISOTRAK II, 120 Fastrak)")
      ->capture_default_str();
  cmd->add_option("--stations", o->stations, "Active stations, e.g. 1,2")->capture_default_str();
  cmd->add_flag("--continuous", o->continuous, "Stream from power-up (as if left in continuous mode)");
  cmd->add_option("--trajectory", o->trajectory, "still, sweep, spin, or a CSV of true poses (poses.csv columns)")
      ->capture_default_str();
  cmd->add_option("--orientation-noise-deg", o->orientation_noise_deg, "RMS orientation noise, degrees")
      ->capture_default_str();
  cmd->add_option("--position-noise-m", o->position_noise_m, "RMS position noise per axis, metres")
      ->capture_default_str();
  cmd->add_option("--latency-ms", o->latency_ms, "Measurement to first byte on the wire")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the noise and the faults")->capture_default_str();
  cmd->add_option("--reinit-s", o->reinit_s, "Seconds of silence after Ctrl-Y")->capture_default_str();
  cmd->add_option("--garbage", o->garbage, "Fraction of record bytes replaced by garbage, e.g. 0.01")
      ->capture_default_str();
  cmd->add_option("--drop", o->drop, "Fraction of records never sent")->capture_default_str();
  cmd->add_option("--silence-every", o->silence_every_s, "Hang every this many seconds (0: never)");
  cmd->add_option("--silence-for", o->silence_for_s, "...for this many seconds (Ctrl-Y ends it)");
  cmd->add_option("--disconnect-every", o->disconnect_every_s,
                  "Make the pty vanish every this many seconds (0: never)");
  cmd->add_option("--disconnect-for", o->disconnect_for_s, "...for this many seconds");
  cmd->add_option("--duration", o->duration_s, "Stop after this many seconds (0: at Ctrl-C or SIGTERM)");
  cmd->add_option("--sent-log", o->sent_log,
                  "Write every record put on the line whole as the host decodes it (lumar tracker decode CSV)");
  add_action(cmd, [o] { run_emulate(*o); });
}

}  // namespace lumar::app
