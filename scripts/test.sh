#!/usr/bin/env bash
# Installs what is missing, builds Lumar and runs the whole test suite with CTest.
# Usage: scripts/test.sh [release|asan|tsan]   (asan = AddressSanitizer + UBSan)
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
type=${1:-release}
bash "$top/scripts/install-deps.sh"
bash "$top/scripts/build.sh" "$type"
export LSAN_OPTIONS="suppressions=$top/scripts/sanitizer/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_odr_violation=0"
export TSAN_OPTIONS="suppressions=$top/scripts/sanitizer/tsan.supp"
cd "$top/build/$type"
ctest --output-on-failure -j"$(nproc)" --timeout 900
