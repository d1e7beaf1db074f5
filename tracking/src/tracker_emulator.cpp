#include "lumar/tracking/tracker_emulator.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <string_view>
#include <thread>

#include "lumar/base/error.h"
#include "lumar/tracking/measurement_model.h"
#include "lumar/tracking/timestamping.h"
#include "pty_device.h"

namespace lumar::tracking {

namespace {

constexpr std::uint8_t kCtrlY = 0x19;
constexpr Nanos kMaxSleep = 50'000'000;     // re-check requests at least this often
constexpr Nanos kBurst = 1'000'000;         // bytes due within this go out in one write
constexpr Nanos kMaxBacklog = 100'000'000;  // a thread stalled longer than this skips records
constexpr std::size_t kMaxCommandLength = 128;

double default_rate(Device d) { return d == Device::Fastrak ? 120.0 : 60.0; }

// What the device remembers; the power-up state comes back after Ctrl-Y or W.
struct DeviceState {
  bool continuous = false;
  bool binary = false;
  bool centimetres = false;
  std::map<int, std::vector<int>> lists;  // output list per station
  std::vector<bool> active;               // index station - 1
  std::map<int, glm::dquat> boresight;    // reference orientation per station
};

struct OutByte {
  std::uint8_t byte;
  Nanos due;
  std::int64_t record = -1;  // sequence of the record it belongs to (-1: a reply)
  bool last = false;         // the record's last byte
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep)) out.push_back(item);
  return out;
}

std::optional<int> to_int(std::string s) {
  s.erase(0, s.find_first_not_of(' '));
  s.erase(s.find_last_not_of(' ') + 1);
  if (s.empty()) return std::nullopt;
  try {
    std::size_t used = 0;
    const int v = std::stoi(s, &used);
    if (used != s.size()) return std::nullopt;
    return v;
  } catch (...) {
    return std::nullopt;
  }
}

}  // namespace

struct TrackerEmulator::Impl {
  EmulatorSettings settings;
  std::function<void(const SentRecord&)> on_record;
  const int stations;
  const Nanos period;
  const Nanos byte_time;
  const Nanos start;

  // Device thread only.
  std::unique_ptr<PtyDevice> pty;
  DeviceState state;
  MeasurementNoise noise;
  std::mt19937_64 fault_rng;
  std::string command;  // a command waiting for its CR
  std::deque<OutByte> out;
  std::map<std::uint64_t, SentRecord> in_flight;  // queued, not completely written yet
  Nanos line_free_at = 0;
  Nanos next_measure = 0;
  std::size_t station_cursor = 0;
  std::uint64_t sequence = 0;
  Nanos reinit_until = 0, silent_until = 0, reconnect_at = 0;
  Nanos next_silence = 0, next_disconnect = 0;

  // Shared with other threads.
  mutable std::mutex mutex;
  EmulatorCounters counters;
  std::string port_path;
  Nanos requested_disconnect = -1, requested_silence = -1;
  bool stopping = false;
  std::string failure;  // why the device thread ended early ("" = it did not)
  int wake_fd = -1;
  std::thread thread;

  Impl(EmulatorSettings s, std::function<void(const SentRecord&)> cb)
      : settings(std::move(s)),
        on_record(std::move(cb)),
        stations(station_count(settings.device)),
        period(seconds_to_nanos(1.0 / (settings.rate_hz > 0 ? settings.rate_hz : default_rate(settings.device)))),
        byte_time(tracking::byte_time(settings.baud > 0 ? settings.baud : 1)),
        start(monotonic_now()),
        noise(settings.orientation_noise_deg, settings.position_noise_m, settings.seed),
        fault_rng(settings.seed ^ 0x9e3779b97f4a7c15ull) {}

  template <class F>
  void count(F&& f) {
    std::lock_guard lock(mutex);
    f(counters);
  }

  void power_up() {
    state = DeviceState{};
    state.continuous = settings.continuous_at_power_up;
    state.active.assign(std::size_t(stations), false);
    for (int s : settings.stations) state.active[std::size_t(s - 1)] = true;
    for (int s = 1; s <= stations; ++s) state.lists[s] = {kItemPosition, kItemAttitude, kItemCrLf};
    next_measure = monotonic_now();
  }

  TrackerFormat format_for(int station) const {
    OutputFormat output;
    output.output_list = state.lists.at(station);
    output.centimetres = state.centimetres;
    TrackerFormat f = TrackerFormat::of(settings.device, state.binary, output);
    f.euler_full_scale_deg = settings.euler_full_scale_deg;
    return f;
  }

  // Queues bytes on the line: the first starts at `earliest` or when the line is free.
  Nanos send(const std::vector<std::uint8_t>& bytes, Nanos earliest, std::int64_t record = -1) {
    const Nanos begin = std::max(earliest, line_free_at);
    for (std::size_t i = 0; i < bytes.size(); ++i)
      out.push_back(
          {bytes[i], begin + transmission_time(std::int64_t(i + 1), settings.baud), record, i + 1 == bytes.size()});
    line_free_at = begin + transmission_time(std::int64_t(bytes.size()), settings.baud);
    return begin + byte_time;
  }

  void send_text(const std::string& text, Nanos now) { send(std::vector<std::uint8_t>(text.begin(), text.end()), now); }

  Pose true_pose(int station, Nanos t) const { return settings.trajectory(station, t - start); }

  // One record of `station`, measured at t; its first byte starts at t + latency.
  void produce_record(int station, Nanos t) {
    SentRecord r;
    r.sequence = sequence++;
    r.measured = t;
    r.format = format_for(station);
    Pose measured = noise.apply(true_pose(station, t));
    if (auto b = state.boresight.find(station); b != state.boresight.end())
      measured.rotation = glm::normalize(glm::inverse(b->second) * measured.rotation);
    r.values = device_record(measured, r.format.output, station);
    try {
      r.bytes = encode_record(r.values, r.format);
    } catch (const std::invalid_argument&) {
      count([](EmulatorCounters& c) { ++c.unencodable; });
      return;
    }
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    if (settings.faults.drop_rate > 0 && uniform(fault_rng) < settings.faults.drop_rate) {
      r.dropped = true;
      count([](EmulatorCounters& c) { ++c.records_dropped; });
    } else {
      std::vector<std::uint8_t> wire = r.bytes;
      if (settings.faults.garbage_rate > 0) {
        std::uniform_int_distribution<int> other(1, 255);
        for (auto& b : wire)
          if (uniform(fault_rng) < settings.faults.garbage_rate) {
            b = std::uint8_t((b + other(fault_rng)) & 0xff);
            ++r.garbage_bytes;
          }
      }
      r.first_byte_due = send(wire, t + settings.device_latency, std::int64_t(r.sequence));
      in_flight.emplace(r.sequence, std::move(r));
      return;  // reported once its last byte is out (write_due) or the line is cut
    }
    finish(std::move(r));
  }

  void finish(SentRecord r) {
    count([&](EmulatorCounters& c) {
      if (r.dropped) return;
      ++c.records_sent;
      c.garbage_bytes += std::uint64_t(r.garbage_bytes);
      if (r.garbage_bytes > 0) ++c.records_damaged;
      if (r.cut_short) ++c.records_cut_short;
    });
    if (!on_record) return;
    try {
      on_record(r);
    } catch (...) {
      // The observer's problem must not stop the device.
    }
  }

  int next_active_station() {
    for (int tries = 0; tries < stations; ++tries) {
      const int s = int(station_cursor++ % std::size_t(stations)) + 1;
      if (state.active[std::size_t(s - 1)]) return s;
    }
    return 0;
  }

  // Continuous mode: every record whose first byte is due by `now`.
  void produce_due_records(Nanos now) {
    if (!state.continuous || now < silent_until || reinit_until) return;
    if (now - (next_measure + settings.device_latency) > kMaxBacklog) next_measure = now - settings.device_latency;
    for (;;) {
      Nanos begin = std::max(next_measure + settings.device_latency, line_free_at);
      if (begin > now) return;
      const Nanos t = begin - settings.device_latency;  // a busy line delays the measurement
      const int station = next_active_station();
      if (station == 0) return;
      produce_record(station, t);
      next_measure = t + period;
    }
  }

  std::string status_record() const {
    char flags[8];
    std::snprintf(flags, sizeof flags, "%03X",
                  (state.binary ? 1 : 0) | (state.centimetres ? 2 : 0) | (state.continuous ? 8 : 0));
    std::string s = std::string("21S") + flags + "  0";
    if (settings.device == Device::Fastrak) {
      std::string id = "LUMAR EMULATED FASTRAK";
      id.resize(32, ' ');
      s += "      " + std::string("  3.00") + id;
    } else {
      s += "  2.00    ";
    }
    return s + "\r\n";  // 21 bytes (ISOTRAK II) or 55 (Fastrak)
  }

  void execute_letter(std::uint8_t c, Nanos now) {
    switch (c) {
      case 'P':
        if (!state.continuous)
          for (int s = 1; s <= stations; ++s)
            if (state.active[std::size_t(s - 1)])
              produce_record(s, std::max(now, line_free_at - settings.device_latency));
        break;
      case 'C':
        if (!state.continuous) next_measure = now;
        state.continuous = true;
        break;
      case 'c':
        state.continuous = false;
        break;
      case 'F':
        state.binary = false;
        break;
      case 'f':
        state.binary = true;
        break;
      case 'U':
        state.centimetres = false;
        break;
      case 'u':
        state.centimetres = true;
        break;
      case 'S':
        send_text(status_record(), now);
        count([](EmulatorCounters& k) { ++k.status_replies; });
        break;
      case 'W':
        power_up();
        break;
      default:
        return;
    }
    count([](EmulatorCounters& k) { ++k.commands; });
  }

  // A command that ended with CR; `text` is without the CR.
  void execute_line(const std::string& text, Nanos now) {
    const char letter = text[0];
    const std::string args = text.substr(1);
    const auto fields = split(args, ',');
    auto station_arg = [&]() -> int {
      const auto s = fields.empty() ? std::nullopt : to_int(fields[0]);
      return s && *s >= 1 && *s <= stations ? *s : (fields.empty() || fields[0].empty() ? 1 : 0);
    };
    switch (letter) {
      case 'O': {
        std::vector<int> items;
        for (const auto& f : fields) {
          const auto v = to_int(f);
          if (!v) return;
          items.push_back(*v);
        }
        int station = 0;  // ISOTRAK II: every station
        if (settings.device == Device::Fastrak) {
          if (items.size() < 2 || items[0] < 1 || items[0] > stations) return;
          station = items[0];
          items.erase(items.begin());
        }
        try {
          OutputFormat f;
          f.output_list = items;
          validate_output_format(f);
        } catch (const InputError&) {
          return;  // the device ignores a list it cannot send
        }
        for (int s = 1; s <= stations; ++s)
          if (station == 0 || s == station) state.lists[s] = items;
        break;
      }
      case 'l': {
        const int station = station_arg();
        if (station == 0) return;
        if (fields.size() >= 2) {
          const auto on = to_int(fields[1]);
          if (!on || (*on != 0 && *on != 1)) return;
          state.active[std::size_t(station - 1)] = *on == 1;
        } else {
          std::string reply{'2', char('0' + station), 'l'};
          for (bool a : state.active) reply += a ? '1' : '0';
          send_text(reply + "\r\n", now);
        }
        break;
      }
      case 'B': {
        const int station = station_arg();
        if (station == 0) return;
        state.boresight[station] = true_pose(station, now).rotation;
        break;
      }
      case 'b': {
        const int station = station_arg();
        if (station == 0) return;
        state.boresight.erase(station);
        break;
      }
      default:
        break;  // H, R, A, x, v: accepted; no effect on the records
    }
    count([](EmulatorCounters& k) { ++k.commands; });
  }

  void feed(std::uint8_t c, Nanos now) {
    if (c == kCtrlY) {
      drop_line(now);
      silent_until = 0;  // reinitialising also ends a hang
      reinit_until = now + std::max<Nanos>(settings.reinit_silence, 1);
      count([](EmulatorCounters& k) {
        ++k.reinits;
        ++k.commands;
      });
      return;
    }
    if (reinit_until || now < silent_until) return;  // a busy or hung device hears nothing
    if (!command.empty()) {
      if (c == '\r') {
        execute_line(command, now);
        command.clear();
      } else if (command.size() < kMaxCommandLength) {
        command.push_back(char(c));
      } else {
        command.clear();
      }
      return;
    }
    switch (c) {
      case 'P':
      case 'C':
      case 'c':
      case 'F':
      case 'f':
      case 'U':
      case 'u':
      case 'S':
      case 'W':
        execute_letter(c, now);
        return;
      case '\r':
      case '\n':
      case ' ':
        return;
    }
    // Letters of commands that take arguments start a line; other bytes are ignored.
    if (std::string_view("OlBbHRAxv").find(char(c)) != std::string_view::npos) command.push_back(char(c));
  }

  void read_input(Nanos now) {
    std::uint8_t buf[512];
    for (;;) {
      const ssize_t n = ::read(pty->master_fd(), buf, sizeof buf);
      if (n <= 0) return;
      for (ssize_t i = 0; i < n; ++i) feed(buf[i], now);
    }
  }

  void write_due(Nanos now) {
    std::vector<OutByte> burst;
    while (!out.empty() && out.front().due <= now) {
      burst.push_back(out.front());
      out.pop_front();
    }
    if (burst.empty()) return;
    std::vector<std::uint8_t> bytes(burst.size());
    for (std::size_t i = 0; i < burst.size(); ++i) bytes[i] = burst[i].byte;
    const ssize_t n = ::write(pty->master_fd(), bytes.data(), bytes.size());
    const std::size_t written = n > 0 ? std::size_t(n) : 0;
    // A full pty means nobody reads: the bytes fall off the line, as on a real wire.
    count([&](EmulatorCounters& c) {
      c.bytes_written += written;
      c.bytes_lost += burst.size() - written;
    });
    for (std::size_t i = 0; i < burst.size(); ++i) {
      const auto it = burst[i].record < 0 ? in_flight.end() : in_flight.find(std::uint64_t(burst[i].record));
      if (it == in_flight.end()) continue;
      if (i >= written) it->second.cut_short = true;
      if (burst[i].last) {
        SentRecord r = std::move(it->second);
        in_flight.erase(it);
        finish(std::move(r));
      }
    }
  }

  // The line stops mid-stream (reinitialisation, disconnection): queued bytes never go out.
  void drop_line(Nanos now) {
    out.clear();
    line_free_at = now;
    command.clear();
    auto cut = std::move(in_flight);
    in_flight.clear();
    for (auto& [sequence, r] : cut) {
      r.cut_short = true;
      finish(std::move(r));
    }
  }

  void vanish(Nanos now, Nanos duration) {
    if (pty) pty->close();
    pty.reset();
    drop_line(now);
    reconnect_at = now + std::max<Nanos>(duration, 0);
    std::lock_guard lock(mutex);
    port_path.clear();
    ++counters.disconnects;
  }

  void appear() {
    pty = std::make_unique<PtyDevice>(settings.link);
    line_free_at = monotonic_now();
    std::lock_guard lock(mutex);
    port_path = pty->slave_path();
  }

  void apply_faults(Nanos now) {
    Nanos disconnect = -1, silence = -1;
    {
      std::lock_guard lock(mutex);
      std::swap(disconnect, requested_disconnect);
      std::swap(silence, requested_silence);
    }
    const EmulatorFaults& f = settings.faults;
    if (f.disconnect_every > 0 && now >= next_disconnect) {
      next_disconnect = now + f.disconnect_every;
      if (disconnect < 0) disconnect = f.disconnect_for;
    }
    if (f.silence_every > 0 && now >= next_silence) {
      next_silence = now + f.silence_every;
      if (silence < 0) silence = f.silence_for;
    }
    if (disconnect >= 0 && pty) vanish(now, disconnect);
    // A hung device stops producing, but the bytes already queued still go out.
    if (silence >= 0) silent_until = std::max(silent_until, now + silence);
  }

  Nanos next_wake(Nanos now) const {
    Nanos wake = now + kMaxSleep;
    if (!pty) return std::min(wake, reconnect_at);
    if (!out.empty()) {
      // Write when the last byte of a ~1 ms burst is due.
      const Nanos first = out.front().due;
      Nanos last = first;
      for (const auto& b : out) {
        if (b.due > first + kBurst) break;
        last = b.due;
      }
      wake = std::min(wake, last);
    }
    if (reinit_until) wake = std::min(wake, reinit_until);
    if (silent_until > now) wake = std::min(wake, silent_until);
    if (state.continuous && !reinit_until)
      wake = std::min(wake, std::max({next_measure + settings.device_latency, line_free_at, silent_until}));
    if (settings.faults.disconnect_every > 0) wake = std::min(wake, next_disconnect);
    if (settings.faults.silence_every > 0) wake = std::min(wake, next_silence);
    return std::max(wake, now);
  }

  void wait_until(Nanos wake, Nanos now) {
    pollfd fds[2] = {{wake_fd, POLLIN, 0}, {pty ? pty->master_fd() : -1, POLLIN, 0}};
    const Nanos d = std::max<Nanos>(wake - now, 0);
    timespec ts{time_t(d / kNanosPerSecond), long(d % kNanosPerSecond)};
    ::ppoll(fds, pty ? 2 : 1, &ts, nullptr);
    if (fds[0].revents & POLLIN) {
      std::uint64_t v;
      [[maybe_unused]] auto r = ::read(wake_fd, &v, sizeof v);
    }
  }

  void run() {
    try {
      loop();
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      failure = e.what();
    }
    if (pty) pty->close();
    std::lock_guard lock(mutex);
    port_path.clear();
  }

  void loop() {
    for (;;) {
      {
        std::lock_guard lock(mutex);
        if (stopping) return;
      }
      Nanos now = monotonic_now();
      apply_faults(now);
      if (!pty) {
        if (now >= reconnect_at) {
          try {
            appear();
          } catch (const RuntimeError&) {
            reconnect_at = now + 100'000'000;  // try again shortly
          }
        }
        if (!pty) {
          wait_until(next_wake(now), now);
          continue;
        }
      }
      read_input(now);
      if (reinit_until && now >= reinit_until) {
        reinit_until = 0;
        power_up();
      }
      produce_due_records(now);
      write_due(now);
      now = monotonic_now();
      wait_until(next_wake(now), now);
    }
  }

  void wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] auto r = ::write(wake_fd, &one, sizeof one);
  }
};

TrackerEmulator::TrackerEmulator(EmulatorSettings settings, std::function<void(const SentRecord&)> on_record) {
  const int stations = station_count(settings.device);
  const std::string where = "emulator: ";
  if (!(settings.rate_hz >= 0 && std::isfinite(settings.rate_hz)))
    throw InputError(where + "rate " + std::to_string(settings.rate_hz) +
                     " Hz must be positive (or 0 for the device's)");
  if (settings.baud <= 0) throw InputError(where + "baud " + std::to_string(settings.baud) + " must be positive");
  if (settings.stations.empty()) throw InputError(where + "at least one station must be active");
  for (int s : settings.stations)
    if (s < 1 || s > stations)
      throw InputError(where + "station " + std::to_string(s) + " does not exist on a " + device_name(settings.device) +
                       " (1.." + std::to_string(stations) + ")");
  if (settings.device_latency < 0 || settings.reinit_silence < 0)
    throw InputError(where + "latency and reinitialisation time must not be negative");
  const EmulatorFaults& f = settings.faults;
  if (!(f.garbage_rate >= 0 && f.garbage_rate <= 1) || !(f.drop_rate >= 0 && f.drop_rate <= 1))
    throw InputError(where + "garbage and drop rates must be fractions in 0..1");
  if (f.silence_every < 0 || f.silence_for < 0 || f.disconnect_every < 0 || f.disconnect_for < 0)
    throw InputError(where + "fault periods must not be negative");
  if (!(settings.euler_full_scale_deg > 0)) throw InputError(where + "the Euler full scale must be positive");
  if (!settings.trajectory) settings.trajectory = builtin_trajectory("sweep");

  impl_ = std::make_unique<Impl>(std::move(settings), std::move(on_record));
  Impl& m = *impl_;
  m.power_up();
  m.next_silence = m.start + m.settings.faults.silence_every;
  m.next_disconnect = m.start + m.settings.faults.disconnect_every;
  m.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m.wake_fd < 0) throw RuntimeError("emulator: cannot create an eventfd");
  try {
    m.appear();
  } catch (...) {
    ::close(m.wake_fd);
    throw;
  }
  m.thread = std::thread([&m] { m.run(); });
}

TrackerEmulator::~TrackerEmulator() { stop(); }

void TrackerEmulator::stop() {
  if (!impl_) return;
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->wake();
  if (impl_->thread.joinable()) impl_->thread.join();
  impl_->drop_line(monotonic_now());
  if (impl_->pty) impl_->pty->close();
  impl_->pty.reset();
  if (impl_->wake_fd >= 0) ::close(impl_->wake_fd);
  impl_->wake_fd = -1;
  std::lock_guard lock(impl_->mutex);
  impl_->port_path.clear();
}

std::string TrackerEmulator::port_path() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->port_path;
}

bool TrackerEmulator::connected() const { return !port_path().empty(); }

std::string TrackerEmulator::failure() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->failure;
}

EmulatorCounters TrackerEmulator::counters() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->counters;
}

void TrackerEmulator::disconnect_for(Nanos duration) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->requested_disconnect = std::max<Nanos>(duration, 0);
  }
  impl_->wake();
}

void TrackerEmulator::silence_for(Nanos duration) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->requested_silence = std::max<Nanos>(duration, 0);
  }
  impl_->wake();
}

}  // namespace lumar::tracking
