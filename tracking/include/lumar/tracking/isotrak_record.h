#pragma once
// One Polhemus data record as the device sent it, before any conversion: device
// units (inches or centimetres, degrees) and Polhemus Euler angles. Shared by the
// ASCII codec and the (later) binary codec; nothing outside tracking/ sees it.
#include <optional>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "lumar/base/time.h"

namespace lumar::tracking {

// Output list items (the `O` command) this code understands.
enum OutputItem : int {
  kItemSpace = 0,       // ' '
  kItemCrLf = 1,        // "\r\n"
  kItemPosition = 2,    // x, y, z
  kItemAttitude = 4,    // azimuth, elevation, roll in degrees
  kItemQuaternion = 11  // w, x, y, z
};

struct IsotrakRecord {
  int station = 1;                         // 1-based station number
  char status = ' ';                       // ' ', or an error letter; '@' / '*' for a stylus button
  std::optional<glm::dvec3> position;      // device units: inches, or cm after `u`
  std::optional<glm::dvec3> attitude_deg;  // azimuth, elevation, roll
  std::optional<glm::dquat> quaternion;    // as sent (4 decimals), w first on the wire
};

// What the device was told to send: the output list and the position unit.
struct OutputFormat {
  std::vector<int> output_list{kItemPosition, kItemAttitude, kItemCrLf};
  bool centimetres = false;  // `u` command; inches otherwise
};

// Throws InputError unless every item is supported (0, 1, 2, 4, 11), the list holds
// at least one of 2, 4, 11 and none of those three twice (a record has one slot each).
void validate_output_format(const OutputFormat& format);

// A record together with when its first byte reached the host (CLOCK_MONOTONIC,
// or time since the recording's start). See timestamping.h for the measurement time.
struct TimedIsotrakRecord {
  IsotrakRecord record;
  Nanos first_byte_arrival = 0;
};

}  // namespace lumar::tracking
