#!/usr/bin/env bash
# Installs what is missing, builds Lumar and runs the whole test suite with CTest.
# Usage: scripts/test.sh [release|asan|tsan] [--isa sse2|sse4.2|avx|avx2|avx512]
#   asan = AddressSanitizer + UBSan, tsan = ThreadSanitizer.
#   --isa forces Embree's kernels to that instruction set (LUMAR_EMBREE_ISA), so that the
#   suite can be run under each set this CPU has; without it Embree picks the best.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
type=release
isa=
while [ $# -gt 0 ]; do
  case "$1" in
    release|asan|tsan) type=$1 ;;
    --isa) [ $# -ge 2 ] || { echo "test.sh: --isa needs a value (sse2, sse4.2, avx, avx2 or avx512)" >&2; exit 2; }
      isa=$2; shift ;;
    *) echo "test.sh: unknown argument '$1'; usage: scripts/test.sh [release|asan|tsan] [--isa NAME]" >&2; exit 2 ;;
  esac
  shift
done
if [ -n "$isa" ]; then
  case "$isa" in
    sse2) flags="sse2" ;;
    sse4.2) flags="sse4_2" ;;
    avx) flags="avx" ;;
    avx2) flags="avx2" ;;
    avx512) flags="avx512f avx512dq avx512cd avx512bw avx512vl" ;;
    *) echo "test.sh: --isa $isa: unknown instruction set; use sse2, sse4.2, avx, avx2 or avx512" >&2; exit 2 ;;
  esac
  cpu_flags=" $(grep -m1 '^flags' /proc/cpuinfo | cut -d: -f2) "
  for f in $flags; do
    case "$cpu_flags" in *" $f "*) ;; *) echo "test.sh: --isa $isa: this CPU has no $f" >&2; exit 2 ;; esac
  done
  export LUMAR_EMBREE_ISA=$isa
  echo "test.sh: Embree forced to $isa"
fi
bash "$top/scripts/install-deps.sh"
bash "$top/scripts/build.sh" "$type"
export LSAN_OPTIONS="suppressions=$top/scripts/sanitizer/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_odr_violation=0"
export TSAN_OPTIONS="suppressions=$top/scripts/sanitizer/tsan.supp"
cd "$top/build/$type"
# The tests' caches (irradiance volumes, shadow lines) are not keyed by instruction set:
# under --isa they would hand back what other kernels computed, so they start empty.
if [ -n "$isa" ]; then rm -rf test-cache test-cache-sse2; fi
ctest --output-on-failure -j"$(nproc)" --timeout 900
