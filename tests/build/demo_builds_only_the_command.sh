#!/usr/bin/env bash
# scripts/demo.sh must build the lumar command alone, not the tests and benchmarks (which
# took a fresh machine 7 minutes before the demo's first frame).
# Usage: demo_builds_only_the_command.sh SOURCE_DIR BUILD_DIR
set -uo pipefail
top=$1 build=$2
fail() { echo "FAIL: $*" >&2; exit 1; }
line=$(grep -E 'scripts/build.sh" release' "$top/scripts/demo.sh") || fail "demo.sh does not run scripts/build.sh release"
targets=$(echo "$line" | sed -E 's/.*build\.sh" release *([^#]*).*/\1/' | xargs)
[ -n "$targets" ] || fail "demo.sh builds every target: $line"
# shellcheck disable=SC2086
commands=$(ninja -C "$build" -t commands $targets) || fail "ninja knows no target '$targets'"
total=$(ninja -C "$build" -t commands | wc -l)
count=$(echo "$commands" | wc -l)
if echo "$commands" | grep -qE "$top/(tests|bench)/"; then
  fail "demo.sh's targets ($targets) compile tests or benchmarks"
fi
[ "$count" -lt "$total" ] || fail "demo.sh's targets need all $total build commands"
echo "ok: demo.sh builds '$targets': $count of the $total build commands"
