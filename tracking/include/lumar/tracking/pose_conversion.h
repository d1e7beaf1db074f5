#pragma once
// The edge of tracking/: a device record (inches or cm, Polhemus Euler angles or a
// 4-decimal quaternion) becomes a PoseSample (metres, unit quaternion). Nothing
// past this point sees device units or Euler angles.
#include <optional>

#include "lumar/base/time.h"
#include "lumar/tracking/isotrak_record.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::tracking {

constexpr double kMetresPerInch = 0.0254;
constexpr double kMetresPerCentimetre = 0.01;

// Metres per device position unit for this format.
inline double metres_per_device_unit(const OutputFormat& format) {
  return format.centimetres ? kMetresPerCentimetre : kMetresPerInch;
}

// Position scaled to metres; orientation from the quaternion item when the record
// has one (renormalised: 4 decimals leave its norm up to ~1e-4 off), otherwise from
// the attitude via polhemus_attitude_to_quat (R = Rz(az) Ry(el) Rx(roll)).
// Returns nullopt (a bad record is dropped, not fatal) when the record has no
// position, no orientation, a non-finite value, or a quaternion whose norm is not
// within 0.01 of 1 (a garbled or mis-configured record, not rounding).
std::optional<PoseSample> to_pose_sample(const IsotrakRecord& record, const OutputFormat& format, Nanos time);

}  // namespace lumar::tracking
