#pragma once
// Drives a Polhemus ISOTRAK II or Fastrak over any ByteTransport from a reader thread,
// and hands decoded, timestamped poses to the render loop without ever blocking it.
//
// Connect sequence (every wait bounded):
//   open the port -> reset (level 0: "c"; 1: CR then "c"; 2: Ctrl-Y, reinit_wait, "c")
//   -> wait until the line is quiet -> "S" and a status record within status_timeout
//   -> F/f, U/u, the output list (ISOTRAK II: "O2,4,1\r"; Fastrak: "O<st>,2,4,1\r" per
//   station) -> "C" (continuous), or "P" every 1/poll_rate_hz (polled).
// A failed step (no quiet, no status, no record within the watchdog after starting)
// closes the port and retries at the next level; levels cycle 0, 1, 2, 0, ... and drop
// back to 0 once a valid record arrives.
// Watchdog: no valid record for `watchdog` while streaming is a fault: close, reopen,
// reset from level 0. A vanished port (unplugged, pty gone) is reopened every
// reopen_interval.
//
// Time: each record is stamped at its first byte (the parser spreads a chunk's bytes
// back from the read's time at 10 / baud s per byte), then
// sample.time = measurement_time(first_byte_arrival, baud, device_latency)
// (timestamping.h).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lumar/base/time.h"
#include "lumar/tracking/byte_transport.h"
#include "lumar/tracking/pose_sample.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/serial_transport.h"

namespace lumar::tracking {

enum class TrackerState {
  stopped,     // not started, or stopped
  connecting,  // opening the port, resetting, configuring
  connected,   // valid records are arriving
  resetting,   // a fault (watchdog, no status): resetting with rising force
  lost,        // the port is gone or cannot be opened; retrying
};
const char* state_name(TrackerState state);

struct DriverSettings {
  TrackerFormat format;          // device, ASCII/binary, output list, units
  std::vector<int> stations{1};  // Fastrak: one O command each (ISOTRAK II has one list)
  bool continuous = true;        // false: poll with P
  double poll_rate_hz = 30;
  Nanos device_latency = 0;              // measurement to first byte, subtracted from sample times
  Nanos watchdog = 2'000'000'000;        // no valid record this long is a fault
  Nanos read_timeout = 20'000'000;       // longest single wait of the reader thread
  Nanos write_timeout = 200'000'000;     // longest wait for room to send a command
  Nanos command_gap = 20'000'000;        // pause after each configuration command
  Nanos quiet_time = 100'000'000;        // no byte this long after "c": the device stopped
  Nanos quiet_limit = 1'000'000'000;     // give up waiting for quiet after this
  Nanos status_timeout = 1'000'000'000;  // "S" must be answered within this
  Nanos reinit_wait = 8'000'000'000;     // silence after Ctrl-Y before talking again
  Nanos reopen_interval = 250'000'000;   // between attempts to open a vanished port
  std::size_t queue_capacity = 4096;     // samples waiting for take_samples()
};

// Throws InputError for unusable settings (format, stations, non-positive times).
void validate_driver_settings(const DriverSettings& settings);

struct DriverStatus {
  TrackerState state = TrackerState::stopped;
  std::string message;        // what is happening or went wrong last, one line
  int reset_level = 0;        // force of the next or current reset: 0, 1, 2
  std::uint64_t records = 0;  // valid records decoded (all connections)
  std::uint64_t rejected_records = 0;
  std::uint64_t skipped_bytes = 0;
  std::uint64_t bytes_read = 0;
  std::uint64_t samples_dropped = 0;  // the queue was full (take_samples not called)
  std::uint64_t connects = 0;         // times valid records started arriving
  std::uint64_t watchdog_faults = 0;
  std::uint64_t reset_attempts = 0;  // resets that did not end with a status record
  std::uint64_t vanished = 0;        // times the port went away or could not be opened
  Nanos last_record = 0;             // CLOCK_MONOTONIC of the last valid record's arrival (0: none)
};

class TrackerDriver {
 public:
  using TransportFactory = std::function<std::unique_ptr<ByteTransport>()>;
  // Runs on the reader thread for every chunk read from the line (also during resets),
  // e.g. to log the raw stream. Keep it short; exceptions from it stop nothing but are
  // reported in status().message.
  using ByteObserver = std::function<void(const ByteChunk&)>;

  // Throws InputError for bad settings. Nothing is opened before start().
  TrackerDriver(DriverSettings settings, TransportFactory open_transport, ByteObserver on_bytes = {});
  ~TrackerDriver();  // stop()
  TrackerDriver(const TrackerDriver&) = delete;
  TrackerDriver& operator=(const TrackerDriver&) = delete;

  void start();  // starts the reader thread; no-op when running
  // Stops the reader thread and closes the port. Returns within about
  // read_timeout + write_timeout, whatever the thread was doing.
  void stop();

  // Appends the samples decoded since the last call (oldest first) and returns how
  // many. Never blocks; call from one thread (the render loop).
  std::size_t take_samples(std::vector<PoseSample>& out);

  DriverStatus status() const;
  const DriverSettings& settings() const { return settings_; }

 private:
  struct Impl;
  DriverSettings settings_;
  std::unique_ptr<Impl> impl_;
};

// A factory that opens a SerialTransport with these settings.
TrackerDriver::TransportFactory serial_port(SerialSettings settings);

}  // namespace lumar::tracking
