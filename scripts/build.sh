#!/usr/bin/env bash
# Configures and builds Lumar. Usage: scripts/build.sh [release|asan|tsan|fuzz] [TARGET ...]
# fuzz: clang with libFuzzer, ASan and UBSan, for the fuzz targets (scripts/fuzz.sh).
# The build goes to build/<type>/ inside the checkout; with targets, only those (and
# what they need) are built, e.g. `scripts/build.sh release lumar` for the command alone.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
type=${1:-release}
shift || true
case "$type" in
  release) cmake_type=Release ;;
  asan) cmake_type=Asan ;;
  tsan) cmake_type=Tsan ;;
  fuzz) cmake_type=Fuzz ;;
  *) echo "build.sh: unknown build type '$type' (release, asan, tsan or fuzz)" >&2; exit 2 ;;
esac
build="$top/build/$type"
extra=()
[ "$type" != fuzz ] || extra=(-DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 -DLUMAR_BUILD_BENCH=OFF)
cmake -S "$top" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$cmake_type" -DLUMAR_SHARED_DIR="$top/../shared" \
  "${extra[@]}" >/dev/null
if [ $# -gt 0 ]; then
  cmake --build "$build" -j"$(nproc)" --target "$@"
else
  cmake --build "$build" -j"$(nproc)"
fi
echo "build.sh: built $build${*:+ ($*)}"
