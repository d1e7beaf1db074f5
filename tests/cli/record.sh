# lumar record: a video file played as a live camera plus the tracker emulator on a
# pty, into a recording; killed with kill -9, stopped by a bad frame, stopped by a
# nearly full disk. Background processes are stopped by their process id; every wait
# has a deadline.
source "$(dirname "$0")/lib.sh"

VTEST="$SHARED/data/video/vtest.avi"

# Every frame frames.csv lists decodes: the overlay writes one PNG per frame.
check_readable() {  # recording, expected frames, [overlay options]
  "$LUMAR" overlay --recording "$1" "${@:3}" --scene "$SRC/data/scenes/room/scene.json" --frames-dir "$TMP/check" \
    >"$TMP/overlay.log" 2>&1 || { cat "$TMP/overlay.log"; fail "lumar overlay cannot read $1"; }
  local pngs
  pngs=$(find "$TMP/check" -name '*.png' | wc -l)
  [ "$pngs" -eq "$2" ] || fail "overlay gave $pngs frames, frames.csv lists $2"
  rm -rf "$TMP/check"
}

case_kill_9_keeps_all_but_the_last_second() {
  start_emulator --rate 60
  "$LUMAR" record --source "video:$VTEST" --tracker "serial:$TMP/tty" --out "$TMP/rec" >"$TMP/record.log" 2>&1 &
  local recorder=$!
  PIDS+=("$recorder")
  wait_for 10 grep -q "^recording" "$TMP/record.log" || { cat "$TMP/record.log"; fail "record did not start"; }
  local t0 t1
  t0=$(date +%s%N)
  # 10 fps, 10 frames per segment: wait for 4 closed segments.
  wait_for 30 at_least_lines "$TMP/rec/frames.csv" 41 || { cat "$TMP/record.log"; fail "no frames recorded"; }
  sleep 0.5
  kill -9 "$recorder"
  t1=$(date +%s%N)
  wait "$recorder" 2>/dev/null
  kill -TERM "$EMULATOR"
  wait "$EMULATOR"

  grep -q '"complete": false' "$TMP/rec/session.json" || fail "session.json should say the recording is incomplete"
  local frames poses captured
  frames=$(($(complete_lines "$TMP/rec/frames.csv") - 1))
  poses=$(($(complete_lines "$TMP/rec/poses.csv") - 1))
  # Frames the source had delivered by the kill (10 fps since "recording" was printed).
  captured=$(((t1 - t0) / 100000000))
  echo "after kill -9 at ${captured} frames' time: frames.csv $frames frames, poses.csv $poses poses"
  [ "$frames" -ge $((captured - 10 - 2)) ] || fail "lost more than the last second: $frames of ~$captured frames"
  [ "$poses" -ge 60 ] || fail "poses.csv holds only $poses poses"
  # frames.csv: indices and times increase; the times follow the file's 10 fps.
  awk -F, 'NR > 1 { if (NR > 2 && ($1 <= i || $2 <= t)) exit 1; i = $1; t = $2 }' "$TMP/rec/frames.csv" ||
    fail "frames.csv indices or times do not increase"
  "$LUMAR" tracker decode "$TMP/rec/tracker.raw" >"$TMP/raw.csv" 2>"$TMP/decode.err" ||
    { cat "$TMP/decode.err"; fail "tracker.raw does not reopen"; }
  local records
  records=$(($(complete_lines "$TMP/raw.csv") - 1))
  [ "$records" -ge "$poses" ] || fail "poses.csv holds poses whose raw bytes are not in tracker.raw"
  # Overlay refuses the unclosed recording with a hint, and replays its closed frames when asked.
  expect_bad_input "--allow-incomplete" "$TMP/check" -- "$LUMAR" overlay --recording "$TMP/rec" \
    --scene "$SRC/data/scenes/room/scene.json" --frames-dir "$TMP/check"
  check_readable "$TMP/rec" "$frames" --allow-incomplete
}

case_bad_frame_ends_with_a_valid_shorter_recording() {
  mkdir -p "$TMP/shots"
  # 12 real photographs, then a file that is not one.
  local i=0
  for f in "$SHARED"/data/calib/checkerboard-9x6/left*.jpg; do
    [ $i -lt 12 ] || break
    cp "$f" "$TMP/shots/frame-$((i++)).jpg"
  done
  [ "$i" -eq 12 ] || fail "expected 12 shared photographs, got $i"
  echo "not a picture" >"$TMP/shots/frame-12.jpg"
  "$LUMAR" record --source "images:$TMP/shots" --images-fps 30 --out "$TMP/rec" --segment-seconds 0.2 \
    >"$TMP/stdout" 2>"$TMP/stderr"
  local status=$?
  cat "$TMP/stderr"
  [ $status -eq 2 ] || fail "exit status $status, expected 2 for a corrupt input frame"
  [ "$(grep -c . "$TMP/stderr")" -eq 1 ] || fail "expected one line on stderr"
  grep -q "frame-12.jpg: cannot decode" "$TMP/stderr" || fail "the message does not name the bad frame"
  grep -q "holds the 12 frames" "$TMP/stderr" || fail "the message does not say what was kept"
  check_readable "$TMP/rec" 12
}

case_full_disk_stops_cleanly() {
  # A disk "nearly full" by the recorder's own margin: it stops after the first segment.
  "$LUMAR" record --source "video:$VTEST" --out "$TMP/rec" --min-free-mb 1e15 >"$TMP/stdout" 2>"$TMP/stderr"
  local status=$?
  cat "$TMP/stderr"
  [ $status -eq 1 ] || fail "exit status $status, expected 1"
  grep -q "disk is nearly full" "$TMP/stderr" || fail "no clear message"
  grep -q '"complete": true' "$TMP/rec/session.json" || fail "the shorter recording was not closed"
  check_readable "$TMP/rec" 10
  # A disk that really fills (a file size limit below one segment: writes fail with
  # EFBIG, which OpenCV's writer does not report): the torn segment is refused, and the
  # recording stays readable, with the frames of the segments closed before.
  (trap '' XFSZ; ulimit -f 1000; "$LUMAR" record --source "video:$VTEST" --out "$TMP/full" --duration 20 \
    >"$TMP/stdout" 2>"$TMP/stderr")
  status=$?
  cat "$TMP/stderr"
  [ $status -eq 1 ] || fail "exit status $status, expected 1 on a full disk"
  [ "$(grep -c . "$TMP/stderr")" -eq 1 ] || fail "expected one line on stderr"
  grep -q "segment-000000.partial.avi: the video segment was cut short" "$TMP/stderr" || fail "no clear message for the full disk"
  grep -q '"complete": false' "$TMP/full/session.json" || fail "a failed recording must not claim to be complete"
  [ "$(complete_lines "$TMP/full/frames.csv")" -eq 1 ] || fail "frames.csv lists frames of a torn segment"
  [ -z "$(find "$TMP/full/video" -name 'segment-??????.avi')" ] || fail "a torn segment was published"
}

case_signals_end_the_recording_cleanly() {
  # Ctrl-C (SIGINT) is how a recording is ended, and a service manager sends SIGTERM: both
  # close it whole within 2 s (exit 0, "complete": true, every listed frame readable), and
  # overlay takes it without --allow-incomplete.
  for signal in INT TERM; do
    start_emulator --rate 60
    "$LUMAR" record --source "video:$VTEST" --tracker "serial:$TMP/tty" --out "$TMP/rec-$signal" \
      >"$TMP/record.log" 2>&1 &
    local recorder=$!
    PIDS+=("$recorder")
    wait_for 10 grep -q "^recording" "$TMP/record.log" || { cat "$TMP/record.log"; fail "record did not start"; }
    wait_for 30 at_least_lines "$TMP/rec-$signal/frames.csv" 11 || { cat "$TMP/record.log"; fail "no frames recorded"; }
    local t0 status=0
    t0=$(date +%s%N)
    kill -"$signal" "$recorder"
    wait "$recorder" || status=$?
    local ms=$((($(date +%s%N) - t0) / 1000000))
    kill -TERM "$EMULATOR"
    wait "$EMULATOR"
    [ $status -eq 0 ] || { cat "$TMP/record.log"; fail "exit status $status after SIG$signal, expected 0"; }
    [ $ms -lt 2000 ] || fail "took $ms ms to close after SIG$signal"
    grep -q '"complete": true' "$TMP/rec-$signal/session.json" || fail "not closed whole after SIG$signal"
    local frames
    frames=$(($(complete_lines "$TMP/rec-$signal/frames.csv") - 1))
    echo "SIG$signal: closed in $ms ms with $frames frames"
    check_readable "$TMP/rec-$signal" "$frames"
  done
}

case_live_overlay_runs_in_a_window() {
  command -v xvfb-run >/dev/null || fail "xvfb-run is not installed"
  start_emulator --rate 60
  xvfb-run -a -s "-screen 0 1024x768x24" "$LUMAR" overlay --source "video:$VTEST" --tracker "serial:$TMP/tty" \
    --scene "$SRC/data/scenes/room/scene.json" --max-frames 20 >"$TMP/out" 2>&1 || { cat "$TMP/out"; fail "live overlay failed"; }
  cat "$TMP/out"
  grep -q "overlay: 20 frames shown" "$TMP/out" || fail "the live overlay did not show 20 frames"
  # Past the first frames the tracker has connected: most frames have a pose.
  local without
  without=$(sed -n 's/.* \([0-9]*\) without a pose.*/\1/p' "$TMP/out")
  [ -n "$without" ] && [ "$without" -le 10 ] || fail "$without of 20 frames had no tracker pose"
}

run_case
