#!/usr/bin/env bash
# Fuzzes one target for real: clang's libFuzzer with ASan + UBSan (docs/fuzzing.md).
# Usage: scripts/fuzz.sh NAME [SECONDS]    (NAME: tests/fuzz/fuzz_NAME.cpp; default 600 s)
# The corpus grows in build/fuzz/corpus/NAME (seeded from tests/fuzz/corpus/NAME, which is
# not touched); a crash stops the run and leaves crash-* / leak-* / timeout-* in
# build/fuzz/findings/NAME. The last line gives the executions and the corpus size.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
name=${1:?usage: scripts/fuzz.sh NAME [SECONDS]}
seconds=${2:-600}
[ -f "$top/tests/fuzz/fuzz_$name.cpp" ] ||
  { echo "fuzz.sh: no target $name; the targets are: $(cd "$top/tests/fuzz" && ls fuzz_*.cpp | sed 's/fuzz_//; s/\.cpp//' | tr '\n' ' ')" >&2; exit 2; }
bash "$top/scripts/install-deps.sh" --fuzz
bash "$top/scripts/build.sh" fuzz "fuzz_$name" >/dev/null
build="$top/build/fuzz"
corpus="$build/corpus/$name" findings="$build/findings/$name"
mkdir -p "$corpus" "$findings"
cp -n "$top/tests/fuzz/corpus/$name"/* "$corpus/"
export ASAN_OPTIONS="detect_odr_violation=0"
export LSAN_OPTIONS="suppressions=$top/scripts/sanitizer/lsan.supp:print_suppressions=0"
cd "$findings"
# -timeout: an input running over 5 s is a hang; -rss_limit_mb: one over 2 GB a leak or bomb.
"$build/tests/fuzz_$name" -max_total_time="$seconds" -timeout=5 -rss_limit_mb=2048 -print_final_stats=1 \
  "$corpus" 2>"$findings/log.txt" || { tail -40 "$findings/log.txt"; echo "fuzz.sh: $name found a problem; see $findings" >&2; exit 1; }
runs=$(grep -m1 '^stat::number_of_executed_units' "$findings/log.txt" | awk '{print $2}')
echo "fuzz.sh: $name ran ${seconds} s: $runs executions, no crash, hang or leak; corpus $(ls "$corpus" | wc -l) inputs"
