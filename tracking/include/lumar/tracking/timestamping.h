#pragma once
// When was a tracker record measured?
//
// The host sees bytes, not measurements. On an 8N1 serial line each byte costs
// 10 bit times (start + 8 data + stop), so byte_time = 10 / baud seconds. A byte is
// "arrived" once its stop bit is in. The device measures the sensor, spends
// `device_latency` computing and queuing the record, then starts sending:
//
//   t_measured + device_latency               first byte starts on the wire
//   t_measured + device_latency + byte_time   first byte has arrived
//
// hence  t_measured = first_byte_arrival - byte_time - device_latency.
// The first byte is used (not the last) because only its delay does not depend on
// the record length, output list or baud. Rounding is to the nearest nanosecond.
#include <cstdint>

#include "lumar/base/time.h"

namespace lumar::tracking {

// Time to send n bytes at `baud` on an 8N1 line: n * 10 / baud seconds, rounded to
// the nearest nanosecond (exact integer arithmetic, no drift over long streams).
// baud must be > 0.
Nanos transmission_time(std::int64_t n_bytes, int baud);

inline Nanos byte_time(int baud) { return transmission_time(1, baud); }

// Measurement time of a record whose first byte arrived at `first_byte_arrival`.
inline Nanos measurement_time(Nanos first_byte_arrival, int baud, Nanos device_latency) {
  return first_byte_arrival - byte_time(baud) - device_latency;
}

}  // namespace lumar::tracking
