#pragma once
// A simulated ISOTRAK II in continuous ASCII mode: turns a true sensor trajectory
// into the exact bytes the device would put on the line, with its measurement
// noise, quantisation (0.01 in or cm, 0.01 deg, 0.0001 for quaternions), device
// latency and serial transmission time. Used for synthetic recordings and to test
// the whole path parser -> timestamping -> conversion -> pose stream.
#include <cstdint>
#include <functional>
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"
#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/isotrak_record.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::tracking {

struct SimulatedTrackerSettings {
  double rate_hz = 60.0;
  int baud = 115200;
  Nanos device_latency = 20'000'000;    // 20 ms from measurement to first byte on the wire
  double orientation_noise_deg = 0.75;  // RMS angle of the rotation error
  double position_noise_m = 0.0025;     // RMS per axis
  OutputFormat format;
  std::uint64_t seed = 1;
  int station = 1;
};

struct SimulatedTrackerOutput {
  std::vector<ByteChunk> chunks;          // one whole record per chunk
  std::vector<PoseSample> noisy_samples;  // what the device measured (before
                                          // quantisation), time = true measurement time
};

// true_pose(t) gives T_transmitter_sensor at time t, for t in [0, duration].
// Record k is measured at t_k = k / rate_hz (rounded to the ns) for every t_k <= duration.
// Noise (MeasurementNoise in measurement_model.h, shared with the emulator): rotation
// error exp(v) with v ~ N(0, sigma^2 I3), sigma = orientation_noise_deg / sqrt(3)
// (so the RMS error angle is the setting), applied in the transmitter frame; position
// error ~ N(0, position_noise_m^2) per axis. Deterministic for a given seed
// (std::mt19937_64, standard normals scaled by sigma).
// Record k's chunk arrives (last byte) at t_k + device_latency + n_bytes * 10 / baud.
// Throws InputError for unusable settings (rate, baud, station, negative noise or
// latency, a line too slow for the record rate, a negative duration) and
// std::invalid_argument when a pose does not fit the ASCII fields (|x| >= 999.995 in/cm).
SimulatedTrackerOutput simulate_tracker(const std::function<Pose(Nanos)>& true_pose, Nanos duration,
                                        const SimulatedTrackerSettings& settings);

}  // namespace lumar::tracking
