#pragma once
// The process's one Embree device, shared by every ray scene (private to lighting/).
// Creating a device costs milliseconds and starts a thread pool, so there is one.
//
// LUMAR_EMBREE_ISA=sse2|sse4.2|avx|avx2|avx512 forces Embree's kernels to that
// instruction set (rtcNewDevice's "isa=" setting), so that a test suite can be run
// under every set a CPU has (scripts/test.sh --isa). Unset: Embree picks the best.
#include <embree3/rtcore.h>

namespace lumar {

// Throws InputError for an unknown LUMAR_EMBREE_ISA, RuntimeError when the CPU lacks it
// or Embree cannot make a device. Embree's own errors become RuntimeError.
RTCDevice embree_device();

}  // namespace lumar
