#pragma once
// Time is int64 nanoseconds of CLOCK_MONOTONIC; recordings store time since their start.
#include <cstdint>

namespace lumar {

using Nanos = std::int64_t;

constexpr Nanos kNanosPerSecond = 1'000'000'000;
constexpr double nanos_to_seconds(Nanos t) { return double(t) * 1e-9; }
constexpr Nanos seconds_to_nanos(double s) { return Nanos(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }

// CLOCK_MONOTONIC now.
Nanos monotonic_now();

}  // namespace lumar
