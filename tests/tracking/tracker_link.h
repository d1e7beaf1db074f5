#pragma once
// Test harness: the emulator on a fresh pty, the real SerialTransport (LibSerial) and
// the real driver on top, plus what it takes to compare what was sent with what came
// out. Every wait has a deadline.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/tracker_driver.h"
#include "lumar/tracking/tracker_emulator.h"

namespace lumar::tracking::test {

// Emulator and driver settings for short, fast tests.
inline EmulatorSettings quick_emulator(Device device) {
  EmulatorSettings e;
  e.device = device;
  e.rate_hz = 120;  // twice the ISOTRAK II rate: more records per second of test
  e.reinit_silence = 300'000'000;
  return e;
}

inline DriverSettings quick_driver(const TrackerFormat& format) {
  DriverSettings d;
  d.format = format;
  d.device_latency = 20'000'000;  // the emulator's default
  d.watchdog = 500'000'000;
  d.read_timeout = 10'000'000;
  d.write_timeout = 100'000'000;
  d.command_gap = 2'000'000;
  d.quiet_time = 40'000'000;
  d.quiet_limit = 300'000'000;
  d.status_timeout = 200'000'000;
  d.reinit_wait = 300'000'000;
  d.reopen_interval = 30'000'000;
  return d;
}

// Largest error quantisation can cause, per format.
struct Tolerance {
  double position_m;
  double angle_deg;
};

inline Tolerance quantisation(const TrackerFormat& f) {
  const double unit_m = metres_per_device_unit(f.output);
  if (!f.binary) return {0.005 * unit_m + 1e-9, 0.016};  // 2 decimals; 3 angles of +-0.005 deg or 4 decimals
  if (f.device == Device::Isotrak2)
    return {0.5 * 1.6632 / 32767 + 1e-9, 0.01};  // half a count of 166.32 cm / 32767; int16 angles
  return {1e-6, 0.001};                          // float32
}

inline bool has_item(const TrackerFormat& f, int item) {
  const auto& l = f.output.output_list;
  return std::find(l.begin(), l.end(), item) != l.end();
}

// The pose the host should decode from a sent record, before quantisation.
inline Pose expected_pose(const SentRecord& r) {
  Pose p;
  p.translation = *r.values.position * metres_per_device_unit(r.format.output);
  if (has_item(r.format, kItemQuaternion))
    p.rotation = *r.values.quaternion;
  else
    p.rotation =
        polhemus_attitude_to_quat(r.values.attitude_deg->x, r.values.attitude_deg->y, r.values.attitude_deg->z);
  return p;
}

struct Mismatch {
  double position_m = 0, angle_deg = 0;
};

inline Mismatch mismatch(const SentRecord& r, const PoseSample& s) {
  const Pose e = expected_pose(r);
  const glm::dvec3 d = glm::abs(s.T_transmitter_sensor.translation - e.translation);
  return {std::max({d.x, d.y, d.z}), rotation_angle_deg(s.T_transmitter_sensor.rotation, e.rotation)};
}

inline bool within(const SentRecord& r, const PoseSample& s) {
  const Tolerance t = quantisation(r.format);
  const Mismatch m = mismatch(r, s);
  return r.values.station == s.station && m.position_m <= t.position_m && m.angle_deg <= t.angle_deg;
}

// The emulator, LibSerial and the driver, wired together.
class Link {
 public:
  // The driver starts `driver_delay` after the emulator.
  Link(EmulatorSettings es, DriverSettings ds, SerialSettings serial = {}, Nanos driver_delay = 0)
      : emulator_(std::move(es), [this](const SentRecord& r) {
          std::lock_guard lock(mutex_);
          sent_.push_back(r);
        }) {
    if (serial.path.empty()) serial.path = emulator_.port_path();
    std::this_thread::sleep_for(std::chrono::nanoseconds(driver_delay));
    driver_ = std::make_unique<TrackerDriver>(std::move(ds), serial_port(serial));
    driver_->start();
  }
  ~Link() { shut_down(); }

  TrackerEmulator& emulator() { return emulator_; }
  TrackerDriver& driver() { return *driver_; }

  // Takes samples (timing the call) until pred() or the deadline; true if pred() held.
  bool run_until(const std::function<bool()>& pred, Nanos deadline) {
    const Nanos end = monotonic_now() + deadline;
    for (;;) {
      pump();
      if (pred()) return true;
      if (monotonic_now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  // One render-loop step: take the new samples and read the status, timing both.
  void pump() {
    const Nanos t0 = monotonic_now();
    const std::size_t n = driver_->take_samples(samples_);
    const Nanos t1 = monotonic_now();
    status_ = driver_->status();
    const Nanos t2 = monotonic_now();
    max_take_ = std::max(max_take_, t1 - t0);
    max_status_ = std::max(max_status_, t2 - t1);
    max_level_ = std::max(max_level_, status_.reset_level);
    if (n > 0) last_sample_seen_ = t1;
  }

  // Lets the bytes on the line drain, then stops both ends: every record that went
  // out was given a chance to arrive.
  void finish() {
    emulator_.silence_for(3'600'000'000'000);
    run_until([] { return false; }, 150'000'000);
    shut_down();
  }

  void shut_down() {
    if (!driver_) return;
    const Nanos t0 = monotonic_now();
    driver_->stop();
    stop_time_ = monotonic_now() - t0;
    pump();
    emulator_.stop();
  }

  std::vector<SentRecord> sent() {
    std::lock_guard lock(mutex_);
    return sent_;
  }
  const std::vector<PoseSample>& samples() const { return samples_; }
  const DriverStatus& status() const { return status_; }
  Nanos max_take_time() const { return max_take_; }
  Nanos max_status_time() const { return max_status_; }
  Nanos stop_time() const { return stop_time_; }
  Nanos last_sample_seen() const { return last_sample_seen_; }
  int max_reset_level() const { return max_level_; }

 private:
  std::mutex mutex_;
  std::vector<SentRecord> sent_;
  TrackerEmulator emulator_;
  std::unique_ptr<TrackerDriver> driver_;
  std::vector<PoseSample> samples_;
  DriverStatus status_;
  Nanos max_take_ = 0, max_status_ = 0, stop_time_ = 0, last_sample_seen_ = 0;
  int max_level_ = 0;
};

// Records that reached the host whole and untouched.
inline std::vector<SentRecord> intact(const std::vector<SentRecord>& sent) {
  std::vector<SentRecord> out;
  for (const auto& r : sent)
    if (!r.dropped && !r.cut_short && r.garbage_bytes == 0) out.push_back(r);
  return out;
}

}  // namespace lumar::tracking::test
