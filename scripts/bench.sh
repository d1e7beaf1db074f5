#!/usr/bin/env bash
# Builds (Release) and runs every benchmark; results land in bench/results/*.json and *.png.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
bash "$top/scripts/build.sh" release
for b in "$top"/build/release/bench/bench_*; do
  [ -x "$b" ] || continue
  echo "== $(basename "$b")"
  "$b" "$@"
done
