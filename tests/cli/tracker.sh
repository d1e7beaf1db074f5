# lumar devices, lumar tracker emulate and lumar tracker record, against the emulator
# on a pty. Background processes are stopped by their process id; every wait has a
# deadline.
source "$(dirname "$0")/lib.sh"

stop_emulator() {
  kill -TERM "$EMULATOR"
  wait "$EMULATOR" || fail "the emulator did not exit cleanly on SIGTERM"
  grep -q "records sent" "$TMP/emulator.log" || fail "the emulator printed no summary"
}

case_devices_lists_or_says_none() {
  "$LUMAR" devices >"$TMP/out" 2>&1 || { cat "$TMP/out"; fail "lumar devices failed"; }
  cat "$TMP/out"
  grep -q "^Serial ports:" "$TMP/out" || fail "no serial port section"
  grep -q "^Polhemus USB devices" "$TMP/out" || fail "no Polhemus section"
  grep -q "^USB-serial adapters" "$TMP/out" || fail "no USB-serial section"
  grep -q "^V4L2 cameras:" "$TMP/out" || fail "no V4L2 camera section"
  if ! ls /dev/video* >/dev/null 2>&1; then
    grep -q "none (no /dev/video\*)" "$TMP/out" || fail "no camera here, but the list does not say none"
  fi
  if ! grep -q "^  [0-9a-f]\{4\}:[0-9a-f]\{4\}" "$TMP/out"; then
    grep -q "No tracker hardware found" "$TMP/out" || fail "no USB device listed and no plain 'none found'"
  fi
}

case_record_survives_kill_9() {
  start_emulator --rate 60
  "$LUMAR" tracker record --port "serial:$TMP/tty" --out "$TMP/rec" >"$TMP/record.log" 2>&1 &
  local recorder=$!
  PIDS+=("$recorder")
  wait_for 15 at_least_lines "$TMP/rec/poses.csv" 61 || { cat "$TMP/record.log"; fail "no poses recorded"; }
  kill -9 "$recorder"
  wait "$recorder" 2>/dev/null
  stop_emulator

  grep -q '"complete": false' "$TMP/rec/session.json" || fail "session.json should say the recording is incomplete"
  "$LUMAR" tracker decode "$TMP/rec/tracker.raw" >"$TMP/raw.csv" 2>"$TMP/decode.err" || {
    cat "$TMP/decode.err"
    fail "tracker.raw does not reopen"
  }
  local records poses first start
  records=$(($(complete_lines "$TMP/raw.csv") - 1))
  poses=$(($(complete_lines "$TMP/rec/poses.csv") - 1))
  echo "after kill -9: tracker.raw holds $records records, poses.csv $poses poses ($(cat "$TMP/decode.err"))"
  [ "$poses" -ge 60 ] || fail "poses.csv lost rows it had before the kill"
  # Raw bytes are logged before the poses decoded from them, and flushed first.
  [ "$records" -ge "$poses" ] || fail "poses.csv holds poses whose raw bytes are not in tracker.raw"
  # The records form one unbroken run of what the emulator sent: none lost in between.
  first=$(sed -n 2p "$TMP/raw.csv")
  start=$(grep -n -x -F -- "$first" "$TMP/sent.csv" | head -1 | cut -d: -f1)
  [ -n "$start" ] || fail "the first recorded record was never sent"
  # sed rather than tail | head: under pipefail, head closing early can kill tail with SIGPIPE.
  sed -n "${start},$((start + records - 1))p" "$TMP/sent.csv" | diff - <(tail -n +2 "$TMP/raw.csv") >"$TMP/run.diff" || {
    head -n 20 "$TMP/run.diff"
    cat "$TMP/emulator.log" "$TMP/record.log"
    fail "tracker.raw is not the unbroken run of records the emulator sent"
  }
  # poses.csv holds the same poses (full precision there, 6 decimals in the decode).
  paste -d, <(head -n $((poses + 1)) "$TMP/rec/poses.csv" | tail -n +2 | cut -d, -f2-) \
    <(tail -n +2 "$TMP/raw.csv" | head -n "$poses") |
    awk -F, '{ for (i = 1; i <= 8; i++) { d = $i - $(i + 8); if (d * d > 1e-12) bad++ } } END { exit bad > 0 }' ||
    fail "poses.csv differs from the poses decoded from tracker.raw"
}

case_record_rides_through_disconnections() {
  # Outages every 2 s after the emulator started (the recorder must find the port at its
  # start, so the first outage leaves it time to start even on a loaded machine). Seven
  # seconds of recording span at least two outages and the reconnection after them, even
  # when a loaded machine starts the recorder a second late and reconnects slowly.
  start_emulator --rate 60 --disconnect-every 2 --disconnect-for 0.3
  "$LUMAR" tracker record --port "serial:$TMP/tty" --out "$TMP/rec" --watchdog 0.5 --duration 7 \
    >"$TMP/record.log" 2>&1 || { cat "$TMP/record.log"; fail "record failed"; }
  stop_emulator
  cat "$TMP/record.log"
  grep -q "tracker: lost" "$TMP/record.log" || fail "the outages were not reported"
  local connects
  connects=$(sed -n 's/.* \([0-9]*\) connections.*/\1/p' "$TMP/record.log")
  [ "${connects:-0}" -ge 3 ] || fail "expected at least 3 connections (2 outages), got ${connects:-none}"
  grep -q '"complete": true' "$TMP/rec/session.json" || fail "a clean stop must mark the recording complete"
}

case_record_stops_cleanly_on_sigint() {
  start_emulator --rate 60
  "$LUMAR" tracker record --port "serial:$TMP/tty" --out "$TMP/rec" >"$TMP/record.log" 2>&1 &
  local recorder=$!
  PIDS+=("$recorder")
  wait_for 15 at_least_lines "$TMP/rec/poses.csv" 11 || { cat "$TMP/record.log"; fail "no poses recorded"; }
  kill -INT "$recorder"
  wait_for 5 eval '! kill -0 '"$recorder"' 2>/dev/null' || fail "record did not stop within 5 s of SIGINT"
  wait "$recorder" || { cat "$TMP/record.log"; fail "record exited with an error after SIGINT"; }
  stop_emulator
  grep -q '"complete": true' "$TMP/rec/session.json" || fail "SIGINT must close the recording"
}

case_bad_tracker_input() {
  expect_bad_input "--device" "" -- "$LUMAR" tracker emulate --device polaris
  expect_bad_input "/dev/lumar-no-such-port" "$TMP/rec" -- "$LUMAR" tracker record \
    --port serial:/dev/lumar-no-such-port --out "$TMP/rec"
  expect_bad_input "--list" "$TMP/rec" -- "$LUMAR" tracker record --port serial:/dev/null --out "$TMP/rec" --list 2,99
  expect_bad_input "nowhere.csv" "" -- "$LUMAR" tracker emulate --trajectory "$TMP/nowhere.csv"
  expect_bad_input "/dev/null" "$TMP/rec" -- "$LUMAR" tracker record --port serial:/dev/null --out "$TMP/rec"
}

run_case
