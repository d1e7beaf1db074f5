#include "lumar/tracking/pose_conversion.h"

#include <cmath>

namespace lumar::tracking {

namespace {
bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

std::optional<PoseSample> to_pose_sample(const IsotrakRecord& record, const OutputFormat& format, Nanos time) {
  if (!record.position || !finite(*record.position)) return std::nullopt;
  PoseSample s;
  s.time = time;
  s.station = record.station;
  s.T_transmitter_sensor.translation = *record.position * metres_per_device_unit(format);
  if (record.quaternion) {
    const glm::dquat& q = *record.quaternion;
    const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > 0.01) return std::nullopt;
    s.T_transmitter_sensor.rotation = q / norm;
  } else if (record.attitude_deg) {
    const glm::dvec3& a = *record.attitude_deg;
    if (!finite(a)) return std::nullopt;
    s.T_transmitter_sensor.rotation = polhemus_attitude_to_quat(a.x, a.y, a.z);
  } else {
    return std::nullopt;
  }
  return s;
}

}  // namespace lumar::tracking
