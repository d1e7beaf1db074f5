#include "lumar/base/time.h"

#include <ctime>

namespace lumar {

Nanos monotonic_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return Nanos(ts.tv_sec) * kNanosPerSecond + ts.tv_nsec;
}

}  // namespace lumar
