#include "lumar/tracking/measurement_model.h"

#include <cmath>
#include <string>

#include "lumar/base/error.h"
#include "lumar/tracking/pose_conversion.h"

namespace lumar::tracking {

namespace {

// exp of a rotation vector (radians).
glm::dquat rotation_from_vector(const glm::dvec3& v) {
  const double angle = glm::length(v);
  if (angle == 0.0) return glm::dquat(1, 0, 0, 0);
  return glm::angleAxis(angle, v / angle);
}

}  // namespace

MeasurementNoise::MeasurementNoise(double orientation_noise_deg, double position_noise_m, std::uint64_t seed)
    : sigma_rotation_rad_(glm::radians(orientation_noise_deg) / std::sqrt(3.0)),
      sigma_position_m_(position_noise_m),
      rng_(seed) {
  if (!(std::isfinite(orientation_noise_deg) && orientation_noise_deg >= 0) ||
      !(std::isfinite(position_noise_m) && position_noise_m >= 0))
    throw InputError("tracker noise: orientation " + std::to_string(orientation_noise_deg) + " deg and position " +
                     std::to_string(position_noise_m) + " m must be finite and not negative");
}

Pose MeasurementNoise::apply(const Pose& truth) {
  glm::dvec3 rot_err, pos_err;
  for (int i = 0; i < 3; ++i) rot_err[i] = sigma_rotation_rad_ * unit_normal_(rng_);
  for (int i = 0; i < 3; ++i) pos_err[i] = sigma_position_m_ * unit_normal_(rng_);
  Pose measured;
  measured.rotation = glm::normalize(rotation_from_vector(rot_err) * glm::normalize(truth.rotation));
  measured.translation = truth.translation + pos_err;
  return measured;
}

IsotrakRecord device_record(const Pose& T_transmitter_sensor, const OutputFormat& format, int station, char status) {
  IsotrakRecord record;
  record.station = station;
  record.status = status;
  glm::dquat q = glm::normalize(T_transmitter_sensor.rotation);
  if (q.w < 0) q = -q;  // one sign on the wire, like the device
  record.position = T_transmitter_sensor.translation / metres_per_device_unit(format);
  record.attitude_deg = quat_to_polhemus_attitude(q);
  record.quaternion = q;
  return record;
}

}  // namespace lumar::tracking
