#pragma once
// One decoded tracker reading, already converted at the edge of tracking/:
// metres and a unit quaternion, in the transmitter frame (Polhemus +Z down).
#include "lumar/base/pose.h"
#include "lumar/base/time.h"

namespace lumar::tracking {

struct PoseSample {
  Nanos time = 0;   // when the sensor was at this pose (device latency already removed)
  int station = 1;  // Polhemus station number, 1-based
  Pose T_transmitter_sensor;
};

}  // namespace lumar::tracking
