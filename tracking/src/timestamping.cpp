#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {

Nanos transmission_time(std::int64_t n_bytes, int baud) {
  if (n_bytes < 0) return -transmission_time(-n_bytes, baud);
  // Whole seconds first so that n * 1e10 cannot overflow for long streams.
  const std::int64_t bits = n_bytes * 10;
  const std::int64_t seconds = bits / baud;
  const std::int64_t rest = bits % baud;  // < baud, so rest * 1e9 fits easily
  return seconds * kNanosPerSecond + (rest * kNanosPerSecond + baud / 2) / baud;
}

}  // namespace lumar::tracking
