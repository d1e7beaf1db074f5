#include "embree_device.h"

#include <cstdlib>
#include <string>

#include "lumar/base/error.h"

namespace lumar {

namespace {

void throw_embree_error(void*, RTCError code, const char* message) {
  if (code != RTC_ERROR_NONE) throw RuntimeError(std::string("Embree: ") + (message ? message : "unknown error"));
}

// The "isa=" part of the device's configuration, from LUMAR_EMBREE_ISA.
std::string isa_setting() {
  const char* value = std::getenv("LUMAR_EMBREE_ISA");
  if (!value || !*value) return {};
  const std::string isa = value;
  // Embree ignores a name it does not know; the CPU check keeps it from picking kernels
  // the processor cannot run.
  struct Known {
    const char* name;
    bool supported;
  };
  __builtin_cpu_init();
  const Known known[] = {{"sse2", bool(__builtin_cpu_supports("sse2"))},
                         {"sse4.2", bool(__builtin_cpu_supports("sse4.2"))},
                         {"avx", bool(__builtin_cpu_supports("avx"))},
                         {"avx2", bool(__builtin_cpu_supports("avx2"))},
                         {"avx512", __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                                        __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
                                        __builtin_cpu_supports("avx512vl")}};
  for (const Known& k : known)
    if (isa == k.name) {
      if (!k.supported) throw RuntimeError("LUMAR_EMBREE_ISA=" + isa + ": this CPU does not have " + isa);
      return ",isa=" + isa;
    }
  throw InputError("LUMAR_EMBREE_ISA=" + isa + ": unknown instruction set; use sse2, sse4.2, avx, avx2 or avx512");
}

}  // namespace

RTCDevice embree_device() {
  static const RTCDevice device = [] {
    const std::string config = "threads=0" + isa_setting();
    RTCDevice d = rtcNewDevice(config.c_str());
    if (!d)
      throw RuntimeError("Embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) +
                         ")");
    rtcSetDeviceErrorFunction(d, throw_embree_error, nullptr);
    return d;
  }();
  return device;
}

}  // namespace lumar
