#pragma once
// How a tracker turns the true sensor pose into what it reports: its measurement
// noise and the values of its record. Shared by the offline simulated tracker
// (simulated_tracker.h) and the pty emulator (tracker_emulator.h), so both produce
// the same statistics.
#include <cstdint>
#include <random>

#include "lumar/base/pose.h"
#include "lumar/tracking/isotrak_record.h"

namespace lumar::tracking {

class MeasurementNoise {
 public:
  // Throws InputError for a negative or non-finite level.
  MeasurementNoise(double orientation_noise_deg, double position_noise_m, std::uint64_t seed);

  // `truth` as the device measures it. Rotation error exp(v) with v ~ N(0, sigma^2 I3),
  // sigma = orientation_noise_deg / sqrt(3) (so the RMS error angle is the setting),
  // applied in the transmitter frame; position error ~ N(0, position_noise_m^2) per
  // axis. Deterministic for a seed: std::mt19937_64 and standard normals, three for
  // the rotation, then three for the position, per call.
  Pose apply(const Pose& truth);

 private:
  double sigma_rotation_rad_;
  double sigma_position_m_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
};

// The values a device reports for a measured pose T_transmitter_sensor: position in
// device units (inches, or cm when format.centimetres), attitude (azimuth, elevation,
// roll in degrees) and the quaternion with w >= 0 (the device sends one sign). Every
// value is filled whatever the output list, so any list can be encoded from it.
IsotrakRecord device_record(const Pose& T_transmitter_sensor, const OutputFormat& format, int station,
                            char status = ' ');

}  // namespace lumar::tracking
