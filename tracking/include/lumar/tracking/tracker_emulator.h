#pragma once
// A Polhemus ISOTRAK II or Fastrak on a pseudo-terminal: any serial program that opens
// port_path() (or the symlink) talks to it as to the device. It answers the commands
// of TRACKER.md, sends records at the device's rate and no faster than the baud rate
// allows, plays a trajectory through the shared measurement model (noise, latency),
// and injects faults on demand or on a schedule.
//
// Commands (single letters act at once, the others end with CR):
//   P poll one record per active station      C / c  continuous on / off
//   F / f ASCII / binary                       U / u  inches / centimetres
//   O p1,p2,...\r (ISOTRAK II, every station)  O<st>,p1,...\r (Fastrak, one station)
//   S status record: ISOTRAK II 21 bytes, Fastrak 55 bytes, both "2<st>S<flags>..."
//   l[<st>][,<0|1>]\r  query ("2<st>l" + one flag per station + CR LF) or set an
//                      active station
//   B<st>\r / b<st>\r  boresight to the current orientation / undo it
//   H<st>,x,y,z\r, R<st>\r, A<st>,...\r, x...\r, v...\r  accepted, no effect on output
//   Ctrl-Y  reinitialise: silent (input ignored) for reinit_silence, then power-up state
//   W       factory defaults (power-up state) at once
//   CR alone and unknown commands are ignored, as the device does.
// Status flags (3 hex digits, unverified layout): bit 0 binary, bit 1 centimetres,
// bit 3 continuous.
//
// Timing: record k is measured at t_k = t_0 + k / rate (stations take turns); its
// first byte starts on the wire at t_k + device_latency and byte i is written to the
// pty when it would have fully arrived, t_k + device_latency + (i + 1) * 10 / baud
// (bytes go out in bursts of at most ~1 ms). A line too slow for the rate delays the
// next measurement, as a device whose output buffer is full would.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lumar/base/time.h"
#include "lumar/tracking/isotrak_record.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/trajectory.h"

namespace lumar::tracking {

struct EmulatorFaults {
  double garbage_rate = 0;  // fraction of record bytes replaced by a different random byte
  double drop_rate = 0;     // fraction of records never sent (the line stays idle)
  Nanos silence_every = 0;  // > 0: hang (see silence_for()) for silence_for, every silence_every
  Nanos silence_for = 0;
  Nanos disconnect_every = 0;  // > 0: the pty vanishes for disconnect_for, every disconnect_every
  Nanos disconnect_for = 0;
};

struct EmulatorSettings {
  Device device = Device::Isotrak2;
  int baud = 115200;             // only paces the output; a pty has no real baud
  double rate_hz = 0;            // records/s over all active stations; 0 = 60 (ISOTRAK II), 120 (Fastrak)
  std::vector<int> stations{1};  // active at power-up
  bool continuous_at_power_up = false;
  Nanos device_latency = 20'000'000;     // measurement to first byte on the wire
  double orientation_noise_deg = 0.75;   // RMS
  double position_noise_m = 0.0025;      // RMS per axis
  std::uint64_t seed = 1;                // noise and faults
  double euler_full_scale_deg = 180.0;   // ISOTRAK II binary Euler scale (unverified)
  Nanos reinit_silence = 3'000'000'000;  // how long Ctrl-Y keeps the device silent
  Trajectory trajectory;                 // empty: builtin_trajectory("sweep")
  std::filesystem::path link;            // also make this symlink to the pty ("" = none)
  EmulatorFaults faults;
};

// One record the device produced, reported once its last byte was written to the pty
// (or it was dropped, or the line was cut before it was out).
struct SentRecord {
  std::uint64_t sequence = 0;       // 0, 1, 2, ... over all records produced
  Nanos measured = 0;               // CLOCK_MONOTONIC of the measurement
  Nanos first_byte_due = 0;         // when its first byte was written to the pty
  TrackerFormat format;             // what the record was encoded as
  IsotrakRecord values;             // the values handed to the encoder (before quantisation)
  std::vector<std::uint8_t> bytes;  // the encoded record, before any garbage
  bool dropped = false;             // never sent
  bool cut_short = false;           // not all of its bytes reached the pty (Ctrl-Y, disconnection,
                                    // a full pty, the emulator stopped)
  int garbage_bytes = 0;            // how many of its bytes were replaced by garbage
};

struct EmulatorCounters {
  std::uint64_t records_sent = 0;  // including damaged and cut-short ones
  std::uint64_t records_cut_short = 0;
  std::uint64_t records_dropped = 0;
  std::uint64_t records_damaged = 0;  // sent with at least one garbage byte
  std::uint64_t garbage_bytes = 0;
  std::uint64_t bytes_written = 0;  // to the pty
  std::uint64_t bytes_lost = 0;     // the pty was full (nobody reading)
  std::uint64_t commands = 0;       // commands recognised
  std::uint64_t status_replies = 0;
  std::uint64_t reinits = 0;  // Ctrl-Y
  std::uint64_t disconnects = 0;
  std::uint64_t unencodable = 0;  // poses outside the format's range (not sent)
};

class TrackerEmulator {
 public:
  // Creates the pty (and the link) and starts the device thread. `on_record` runs on
  // that thread for every record produced; keep it short. Throws InputError for bad
  // settings, RuntimeError when no pty can be created or the link cannot be made.
  explicit TrackerEmulator(EmulatorSettings settings, std::function<void(const SentRecord&)> on_record = {});
  ~TrackerEmulator();  // stop()
  TrackerEmulator(const TrackerEmulator&) = delete;
  TrackerEmulator& operator=(const TrackerEmulator&) = delete;

  // The pty's slave path ("/dev/pts/N"); a new one after each disconnection, "" while
  // disconnected.
  std::string port_path() const;
  bool connected() const;
  EmulatorCounters counters() const;
  // Why the device thread stopped on its own (an unexpected error); "" while it runs.
  std::string failure() const;

  // Fault injection on demand. disconnect_for: the pty (and link) vanish now, queued
  // bytes are lost, and a new pty appears after `duration`. silence_for: the device hangs
  // for `duration`: no new records, commands ignored except Ctrl-Y (which reinitialises
  // it); bytes already queued on the line still go out.
  void disconnect_for(Nanos duration);
  void silence_for(Nanos duration);

  // Stops the device thread, closes the pty, removes the link. Idempotent.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lumar::tracking
