# Helpers for the command-line tests. Each test script defines functions named
# case_<name>; CTest runs one case per test: bash script.sh LUMAR SOURCE SHARED CASE.
set -uo pipefail
LUMAR=$1
SRC=$2
SHARED=$3
CASE=$4
TMP=$(mktemp -d "${TMPDIR:-/tmp}/lumar-cli-XXXXXX")
# Background processes a case starts go into PIDS: killed by process id at exit.
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill -9 "$pid" 2>/dev/null; done
  rm -rf "$TMP"
}
trap cleanup EXIT
unset DISPLAY  # headless unless a case asks for a display

fail() { echo "FAIL: $*" >&2; exit 1; }

# expect_bad_input WHAT_STDERR_MUST_NAME OUTPUT_THAT_MUST_NOT_EXIST -- command...
# The command must exit 2 with exactly one line on stderr that names the file, and
# leave no output (nor a partial one) behind.
expect_bad_input() {
  local must_name=$1 output=$2
  shift 3
  "$@" >"$TMP/stdout" 2>"$TMP/stderr"
  local status=$?
  [ $status -eq 2 ] || { cat "$TMP/stderr" >&2; fail "exit status $status, expected 2: $*"; }
  local lines
  lines=$(grep -c . "$TMP/stderr")
  [ "$lines" -eq 1 ] || { cat "$TMP/stderr" >&2; fail "expected one line on stderr, got $lines"; }
  grep -qF -- "$must_name" "$TMP/stderr" || { cat "$TMP/stderr" >&2; fail "stderr does not name $must_name"; }
  if [ -n "$output" ]; then
    [ ! -e "$output" ] || fail "output $output was left behind"
    local partials
    partials=$(find "$(dirname "$output")" -maxdepth 1 -name '.*partial*' | wc -l)
    [ "$partials" -eq 0 ] || fail "a partial output was left behind in $(dirname "$output")"
  fi
  echo "ok: $(head -1 "$TMP/stderr")"
}

# no_temporaries DIR: nothing an output's writer leaves while it works (".NAME.partial-*",
# or an old-style "NAME.tmp") is left in DIR.
no_temporaries() {
  local left
  left=$(find "$1" -maxdepth 1 \( -name '.*partial*' -o -name '*.tmp' \) | head -3)
  [ -z "$left" ] || fail "temporary files left behind: $left"
}

# png_size FILE: "WIDTH HEIGHT" of a PNG (from its header).
png_size() {
  python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); assert d[:8]==b'\x89PNG\r\n\x1a\n'; print(*struct.unpack('>II', d[16:24]))" "$1"
}

# wait_for SECONDS COMMAND...: true once COMMAND succeeds, false at the deadline.
wait_for() {
  local deadline=$((SECONDS + $1))
  shift
  until "$@"; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.05
  done
}

# Complete lines of a file (a line cut short by a crash has no '\n' and does not count).
complete_lines() { [ -f "$1" ] && tr -cd '\n' <"$1" | wc -c || echo 0; }
at_least_lines() { [ "$(complete_lines "$1")" -ge "$2" ]; }

# The tracker emulator on a pty at $TMP/tty, logging what it sent to $TMP/sent.csv.
start_emulator() {  # extra emulator options...
  "$LUMAR" tracker emulate --link "$TMP/tty" --sent-log "$TMP/sent.csv" "$@" >"$TMP/emulator.log" 2>&1 &
  EMULATOR=$!
  PIDS+=("$EMULATOR")
  wait_for 5 test -L "$TMP/tty" || { cat "$TMP/emulator.log"; fail "the emulator made no link"; }
}

run_case() {
  declare -F "case_$CASE" >/dev/null || fail "no case '$CASE' in $0"
  "case_$CASE"
}

# expect_environment_error WHAT_STDERR_MUST_SAY DIR -- command...: a failure of the
# environment (a full disk, a read-only folder): exit 1, one error line on stderr saying it,
# nothing final and no temporary left in DIR besides what was there before (DIR "-":
# not checked).
expect_environment_error() {
  local must_say=$1 dir=$2
  shift 3
  local before status=0
  [ "$dir" = - ] || before=$(ls -A "$dir" | sort)
  "$@" >"$TMP/stdout" 2>"$TMP/stderr" || status=$?
  [ $status -eq 1 ] || { cat "$TMP/stderr" >&2; fail "exit status $status, expected 1: $*"; }
  # One error line, last; warnings the work gave before the failure may precede it.
  [ "$(grep -c '^lumar: ' "$TMP/stderr")" -eq 1 ] || { cat "$TMP/stderr" >&2; fail "expected one error line on stderr"; }
  tail -1 "$TMP/stderr" | grep -qF -- "$must_say" || { cat "$TMP/stderr" >&2; fail "the last line does not say '$must_say'"; }
  [ "$dir" = - ] || [ "$(ls -A "$dir" | sort)" = "$before" ] || fail "left in $dir: $(comm -13 <(echo "$before") <(ls -A "$dir" | sort) | tr '\n' ' ')"
  echo "ok: $(tail -1 "$TMP/stderr")"
}

# with_file_size_limit KB command...: runs the command as if the disk filled up after KB
# kilobytes per file (RLIMIT_FSIZE; writes past it fail with EFBIG, SIGXFSZ ignored).
with_file_size_limit() {
  local kb=$1
  shift
  (trap '' XFSZ; ulimit -f "$kb"; exec "$@")  # bash counts -f in 1024-byte blocks
}

# handles_sigint PID: the process has installed its own SIGINT handler. Until then a
# background job of a script ignores SIGINT (POSIX, without job control), so a signal
# sent earlier would be lost, not handled.
handles_sigint() {
  local caught
  caught=$(awk '/^SigCgt:/ { print $2 }' "/proc/$1/status" 2>/dev/null) || return 1
  [ -n "$caught" ] && [ $((0x$caught & 0x2)) -ne 0 ]
}

# stop_midway SIGNAL WAIT_FOR -- command...: starts the command, waits until the work is
# under way (WAIT_FOR: a glob a file must match, "stderr:TEXT" the command must have
# printed, or "after:SECONDS" of running) and handles SIGINT, sends the signal, and
# expects exit 130 within 2 s with a "stopped" line.
stop_midway() {
  local signal=$1 glob=$2
  shift 3
  "$@" >"$TMP/stdout" 2>"$TMP/stderr" &
  local pid=$! waited=0
  PIDS+=("$pid")
  local started=$SECONDS
  until handles_sigint "$pid" && if [ "${glob#stderr:}" != "$glob" ]; then grep -q "${glob#stderr:}" "$TMP/stderr";
        elif [ "${glob#after:}" != "$glob" ]; then [ $((SECONDS - started)) -ge "${glob#after:}" ];
        else compgen -G "$glob" >/dev/null; fi; do
    kill -0 "$pid" 2>/dev/null || { cat "$TMP/stderr"; fail "the command ended before $glob appeared"; }
    sleep 0.05
    waited=$((waited + 1))
    [ $waited -lt 2400 ] || fail "$glob did not appear within 120 s"
  done
  sleep 0.3
  kill -"$signal" "$pid"
  local start=$(date +%s%N) status=0
  wait "$pid" || status=$?
  local ms=$((($(date +%s%N) - start) / 1000000))
  [ $status -eq 130 ] || { cat "$TMP/stderr"; fail "exit status $status after SIG$signal, expected 130"; }
  # 2 s, times the sanitizer build's slowdown (LUMAR_TEST_TIME_SCALE, tests/CMakeLists.txt):
  # the command stops between frames, and under ThreadSanitizer one frame takes seconds.
  local limit=$((2000 * ${LUMAR_TEST_TIME_SCALE:-1}))
  [ $ms -lt $limit ] || fail "took $ms ms to stop after SIG$signal (limit $limit ms)"
  grep -q "^lumar: stopped:" "$TMP/stderr" || { cat "$TMP/stderr"; fail "no 'stopped' line"; }
  echo "ok: SIG$signal stopped it in $ms ms: $(grep '^lumar: stopped' "$TMP/stderr")"
}
