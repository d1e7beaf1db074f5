#include "lumar/tracking/simulated_tracker.h"

#include <cmath>
#include <string>

#include "lumar/base/error.h"
#include "lumar/tracking/isotrak_ascii.h"
#include "lumar/tracking/measurement_model.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {

namespace {

void validate(const SimulatedTrackerSettings& s, Nanos duration, int record_length) {
  const std::string where = "simulated tracker: ";
  if (!(std::isfinite(s.rate_hz) && s.rate_hz > 0))
    throw InputError(where + "rate " + std::to_string(s.rate_hz) + " Hz is not positive; use e.g. 60");
  if (s.baud <= 0) throw InputError(where + "baud " + std::to_string(s.baud) + " is not positive; use e.g. 115200");
  if (s.station < 1 || s.station > 9)
    throw InputError(where + "station " + std::to_string(s.station) + " is outside 1..9");
  if (!(std::isfinite(s.orientation_noise_deg) && s.orientation_noise_deg >= 0) ||
      !(std::isfinite(s.position_noise_m) && s.position_noise_m >= 0))
    throw InputError(where + "noise levels must be finite and not negative");
  if (s.device_latency < 0) throw InputError(where + "device latency is negative; use 0 or more");
  if (duration < 0) throw InputError(where + "duration is negative");
  // A record must be on the wire before the next one is due.
  if (nanos_to_seconds(transmission_time(record_length, s.baud)) * s.rate_hz > 1.0)
    throw InputError(where + std::to_string(record_length) + "-byte records at " + std::to_string(s.rate_hz) +
                     " Hz do not fit a " + std::to_string(s.baud) + " baud line; raise the baud or lower the rate");
}

}  // namespace

SimulatedTrackerOutput simulate_tracker(const std::function<Pose(Nanos)>& true_pose, Nanos duration,
                                        const SimulatedTrackerSettings& settings) {
  const int record_length = ascii_record_length(settings.format);
  validate(settings, duration, record_length);

  MeasurementNoise noise(settings.orientation_noise_deg, settings.position_noise_m, settings.seed);
  const Nanos send_time = transmission_time(record_length, settings.baud);

  SimulatedTrackerOutput out;
  for (std::int64_t k = 0;; ++k) {
    const Nanos t = seconds_to_nanos(double(k) / settings.rate_hz);
    if (t > duration) break;
    PoseSample measured;
    measured.time = t;
    measured.station = settings.station;
    measured.T_transmitter_sensor = noise.apply(true_pose(t));
    out.noisy_samples.push_back(measured);

    const IsotrakRecord record = device_record(measured.T_transmitter_sensor, settings.format, settings.station);
    const std::string bytes = encode_ascii_record(record, settings.format);

    ByteChunk chunk;
    chunk.arrival = t + settings.device_latency + send_time;
    chunk.bytes.assign(bytes.begin(), bytes.end());
    out.chunks.push_back(std::move(chunk));
  }
  return out;
}

}  // namespace lumar::tracking
