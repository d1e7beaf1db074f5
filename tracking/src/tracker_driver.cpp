#include "lumar/tracking/tracker_driver.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string_view>
#include <thread>

#include "lumar/base/error.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_parser.h"
#include "lumar/tracking/spsc_ring.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {

namespace {

constexpr char kCtrlY = 0x19;

// The stop request, seen by every wait of the reader thread.
struct Stopped {};

std::string seconds_text(Nanos t) {
  char s[32];
  std::snprintf(s, sizeof s, "%.2f s", nanos_to_seconds(t));
  return s;
}

int status_length(Device d) { return d == Device::Fastrak ? 55 : 21; }

// A status record: '2', a station digit, 'S', ... CR LF, of the device's length.
bool find_status(const std::string& bytes, Device device) {
  const std::size_t n = std::size_t(status_length(device));
  for (std::size_t i = 0; i + n <= bytes.size(); ++i)
    if (bytes[i] == '2' && bytes[i + 1] >= '1' && bytes[i + 1] <= '9' && bytes[i + 2] == 'S' &&
        bytes[i + n - 2] == '\r' && bytes[i + n - 1] == '\n')
      return true;
  return false;
}

std::string list_text(const std::vector<int>& list) {
  std::string s;
  for (std::size_t i = 0; i < list.size(); ++i) s += (i ? "," : "") + std::to_string(list[i]);
  return s;
}

}  // namespace

const char* state_name(TrackerState state) {
  switch (state) {
    case TrackerState::stopped:
      return "stopped";
    case TrackerState::connecting:
      return "connecting";
    case TrackerState::connected:
      return "connected";
    case TrackerState::resetting:
      return "resetting";
    case TrackerState::lost:
      return "lost";
  }
  return "?";
}

void validate_driver_settings(const DriverSettings& s) {
  validate_tracker_format(s.format);
  const std::string where = "tracker driver: ";
  if (s.stations.empty()) throw InputError(where + "name at least one station");
  for (int st : s.stations)
    if (st < 1 || st > s.format.max_station)
      throw InputError(where + "station " + std::to_string(st) + " does not exist on a " +
                       device_name(s.format.device) + " (1.." + std::to_string(s.format.max_station) + ")");
  if (!s.continuous && !(s.poll_rate_hz > 0 && s.poll_rate_hz <= 1000))
    throw InputError(where + "poll rate " + std::to_string(s.poll_rate_hz) + " Hz must be in (0, 1000]");
  for (Nanos t :
       {s.watchdog, s.read_timeout, s.write_timeout, s.quiet_time, s.quiet_limit, s.status_timeout, s.reopen_interval})
    if (t <= 0) throw InputError(where + "every timeout must be positive");
  if (s.command_gap < 0 || s.reinit_wait < 0 || s.device_latency < 0)
    throw InputError(where + "command gap, reinitialisation wait and latency must not be negative");
  if (s.queue_capacity == 0) throw InputError(where + "the sample queue needs room for at least one sample");
}

struct TrackerDriver::Impl {
  const DriverSettings& settings;
  TransportFactory open_transport;
  ByteObserver on_bytes;
  SpscRing<PoseSample> queue;

  std::thread thread;
  std::atomic<bool> stop_requested{false};
  std::mutex sleep_mutex;
  std::condition_variable sleep_cv;

  mutable std::mutex status_mutex;
  DriverStatus status;

  // Reader thread only.
  std::unique_ptr<ByteTransport> transport;
  int level = 0;

  Impl(const DriverSettings& s, TransportFactory open, ByteObserver observer)
      : settings(s), open_transport(std::move(open)), on_bytes(std::move(observer)), queue(s.queue_capacity) {}

  void check_stop() const {
    if (stop_requested.load(std::memory_order_relaxed)) throw Stopped{};
  }

  // Waits `d` unless stop() is called meanwhile.
  void sleep_for(Nanos d) {
    std::unique_lock lock(sleep_mutex);
    sleep_cv.wait_for(lock, std::chrono::nanoseconds(d), [this] { return stop_requested.load(); });
    check_stop();
  }

  void set_state(TrackerState state, std::string message) {
    std::lock_guard lock(status_mutex);
    status.state = state;
    status.message = std::move(message);
    status.reset_level = level;
  }

  template <class F>
  void update(F&& f) {
    std::lock_guard lock(status_mutex);
    f(status);
  }

  ByteChunk read_chunk(Nanos timeout) {
    check_stop();
    ByteChunk chunk = transport->read(std::min(timeout, settings.read_timeout));
    if (!chunk.bytes.empty()) {
      update([&](DriverStatus& s) { s.bytes_read += chunk.bytes.size(); });
      if (on_bytes) {
        try {
          on_bytes(chunk);
        } catch (const std::exception& e) {
          update([&](DriverStatus& s) { s.message = std::string("byte observer failed: ") + e.what(); });
        }
      }
    }
    return chunk;
  }

  void send(std::string_view bytes) {
    check_stop();
    transport->write(bytes, settings.write_timeout);
  }

  // Reads (and keeps nothing) for `d`.
  void drain_for(Nanos d) {
    const Nanos end = monotonic_now() + d;
    for (Nanos now = monotonic_now(); now < end; now = monotonic_now()) read_chunk(end - now);
  }

  // Reads until no byte came for quiet_time; false if that does not happen within quiet_limit.
  bool wait_for_quiet() {
    const Nanos give_up = monotonic_now() + settings.quiet_limit;
    Nanos last_byte = monotonic_now();
    for (;;) {
      const Nanos now = monotonic_now();
      if (now - last_byte >= settings.quiet_time) return true;
      if (now >= give_up) return false;
      if (!read_chunk(std::min(settings.quiet_time - (now - last_byte), give_up - now)).bytes.empty())
        last_byte = monotonic_now();
    }
  }

  bool request_status() {
    transport->discard_input();
    send("S");
    std::string reply;
    const Nanos give_up = monotonic_now() + settings.status_timeout;
    for (Nanos now = monotonic_now(); now < give_up; now = monotonic_now()) {
      const ByteChunk c = read_chunk(give_up - now);
      reply.append(c.bytes.begin(), c.bytes.end());
      if (find_status(reply, settings.format.device)) return true;
    }
    return false;
  }

  // Reset at the current level, then S. True when the device answered.
  bool reset() {
    const std::string& port = transport->name();
    set_state(level == 0 && status.connects == 0 ? TrackerState::connecting : TrackerState::resetting,
              port + ": reset level " + std::to_string(level) +
                  (level == 0   ? " (c)"
                   : level == 1 ? " (CR + c)"
                                : " (Ctrl-Y, waiting " + seconds_text(settings.reinit_wait) + ")"));
    if (level == 1) send("\r");
    if (level == 2) {
      send(std::string(1, kCtrlY));
      drain_for(settings.reinit_wait);
    }
    send("c");
    if (!wait_for_quiet()) {
      set_state(TrackerState::resetting, port + ": the device keeps sending after 'c'");
      return false;
    }
    if (!request_status()) {
      set_state(TrackerState::resetting, port + ": no status record within " + seconds_text(settings.status_timeout));
      return false;
    }
    return true;
  }

  void configure() {
    const TrackerFormat& f = settings.format;
    const std::string list = list_text(f.output.output_list);
    std::vector<std::string> commands{f.binary ? "f" : "F", f.output.centimetres ? "u" : "U"};
    if (f.device == Device::Fastrak)
      for (int st : settings.stations) commands.push_back("O" + std::to_string(st) + "," + list + "\r");
    else
      commands.push_back("O" + list + "\r");
    for (const auto& c : commands) {
      send(c);
      sleep_for(settings.command_gap);
    }
    transport->discard_input();
    if (settings.continuous) send("C");
  }

  // Reads records until the watchdog fires (returns) or the port fails (throws).
  void stream() {
    const int baud = transport->baud();
    RecordParser parser(settings.format, baud);
    const Nanos poll_period = settings.continuous ? 0 : seconds_to_nanos(1.0 / settings.poll_rate_hz);
    Nanos last_valid = monotonic_now();
    Nanos next_poll = last_valid;
    bool receiving = false;
    std::size_t counted_records = 0, counted_rejected = 0, counted_skipped = 0;
    for (;;) {
      Nanos now = monotonic_now();
      if (!settings.continuous && now >= next_poll) {
        send("P");
        next_poll = std::max(next_poll + poll_period, now);
      }
      const Nanos wait = settings.continuous ? settings.read_timeout : std::max<Nanos>(next_poll - now, 0);
      const ByteChunk chunk = read_chunk(std::min(wait, settings.read_timeout));
      std::size_t valid = 0, dropped = 0;
      if (!chunk.bytes.empty()) {
        parser.push(chunk);
        for (const TimedIsotrakRecord& r : parser.take_all()) {
          const auto sample = to_pose_sample(r.record, settings.format.output,
                                             measurement_time(r.first_byte_arrival, baud, settings.device_latency));
          if (!sample) continue;  // decodable but not a pose (e.g. a quaternion far from unit)
          ++valid;
          if (!queue.push(*sample)) ++dropped;
        }
      }
      now = monotonic_now();
      if (valid > 0) {
        last_valid = now;
        if (!receiving) {
          receiving = true;
          level = 0;
          set_state(TrackerState::connected, transport->name() + ": receiving records");
          update([](DriverStatus& s) { ++s.connects; });
        }
      }
      update([&](DriverStatus& s) {
        // Add what this parser counted since the last update (it lives one connection).
        s.records += parser.accepted_records() - counted_records;
        s.rejected_records += parser.rejected_records() - counted_rejected;
        s.skipped_bytes += parser.skipped_bytes() - counted_skipped;
        s.samples_dropped += dropped;
        if (valid > 0) s.last_record = last_valid;
      });
      counted_records = parser.accepted_records();
      counted_rejected = parser.rejected_records();
      counted_skipped = parser.skipped_bytes();
      if (now - last_valid > settings.watchdog) {
        // Streaming for a while and then silence: start gently. Never receiving after
        // a good status: the next reset needs more force.
        level = receiving ? 0 : (level + 1) % 3;
        update([](DriverStatus& s) { ++s.watchdog_faults; });
        set_state(TrackerState::resetting,
                  transport->name() + ": no valid record for " + seconds_text(settings.watchdog) + "; resetting");
        return;
      }
    }
  }

  void close_transport() {
    if (transport) transport->close();
    transport.reset();
  }

  void run() {
    try {
      while (!stop_requested) {
        try {
          transport = open_transport();
        } catch (const std::exception& e) {
          // Missing, unplugged, busy or refused: report it and keep trying.
          update([](DriverStatus& s) { ++s.vanished; });
          set_state(TrackerState::lost, e.what());
          sleep_for(settings.reopen_interval);
          continue;
        }
        try {
          if (reset()) {
            configure();
            stream();
          } else {
            update([](DriverStatus& s) { ++s.reset_attempts; });
            level = (level + 1) % 3;
          }
          close_transport();
        } catch (const std::exception& e) {
          // DeviceVanished or a failed write: the port is unusable; reopen it.
          close_transport();
          update([](DriverStatus& s) { ++s.vanished; });
          set_state(TrackerState::lost, e.what());
          sleep_for(settings.reopen_interval);
        }
      }
    } catch (const Stopped&) {
    }
    close_transport();
    set_state(TrackerState::stopped, "stopped");
  }
};

TrackerDriver::TrackerDriver(DriverSettings settings, TransportFactory open_transport, ByteObserver on_bytes)
    : settings_(std::move(settings)) {
  validate_driver_settings(settings_);
  if (!open_transport) throw InputError("tracker driver: no way to open the port was given");
  impl_ = std::make_unique<Impl>(settings_, std::move(open_transport), std::move(on_bytes));
}

TrackerDriver::~TrackerDriver() { stop(); }

void TrackerDriver::start() {
  if (impl_->thread.joinable()) return;
  impl_->stop_requested = false;
  impl_->set_state(TrackerState::connecting, "starting");
  impl_->thread = std::thread([this] { impl_->run(); });
}

void TrackerDriver::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  {
    std::lock_guard lock(impl_->sleep_mutex);
    impl_->stop_requested = true;
  }
  impl_->sleep_cv.notify_all();
  impl_->thread.join();
}

std::size_t TrackerDriver::take_samples(std::vector<PoseSample>& out) {
  std::size_t n = 0;
  while (auto s = impl_->queue.pop()) {
    out.push_back(*s);
    ++n;
  }
  return n;
}

DriverStatus TrackerDriver::status() const {
  std::lock_guard lock(impl_->status_mutex);
  return impl_->status;
}

TrackerDriver::TransportFactory serial_port(SerialSettings settings) {
  return [settings] { return std::make_unique<SerialTransport>(settings); };
}

}  // namespace lumar::tracking
