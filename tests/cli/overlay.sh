# The overlay path end to end on the bundled sample recording.
source "$(dirname "$0")/lib.sh"
REC=$SRC/recordings/orbit

frames_in_recording() { grep -c '^[0-9]' "$REC/frames.csv"; }

case_headless_writes_video_and_frames() {
  [ -z "${DISPLAY:-}" ] || fail "DISPLAY should be unset"
  "$LUMAR" overlay --recording "$REC" --out "$TMP/out.mp4" --frames-dir "$TMP/frames" \
    --contact-sheet "$TMP/sheet.png" >"$TMP/log" 2>&1 ||
    { cat "$TMP/log"; fail "overlay failed"; }
  [ -s "$TMP/out.mp4" ] || fail "no video written"
  n=$(ls "$TMP/frames" | wc -l)
  [ "$n" -eq "$(frames_in_recording)" ] || fail "$n PNG frames, expected $(frames_in_recording)"
  grep -q "virtual objects" "$TMP/log" || fail "no per-stage timing summary"
  [ "$(head -c 8 "$TMP/sheet.png" | od -An -tx1 | tr -d ' ')" = "89504e470d0a1a0a" ] || fail "no PNG contact sheet"
  cat "$TMP/log"
}

case_window_under_xvfb() {
  command -v xvfb-run >/dev/null || fail "xvfb-run is not installed"
  xvfb-run -a -s "-screen 0 1024x768x24" "$LUMAR" overlay --recording "$REC" --window --max-frames 3 \
    --frames-dir "$TMP/frames" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "windowed overlay failed"; }
  [ "$(ls "$TMP/frames" | wc -l)" -eq 3 ] || fail "expected 3 frames"
}

case_window_without_display_fails_cleanly() {
  "$LUMAR" overlay --recording "$REC" --window --max-frames 1 >"$TMP/out" 2>"$TMP/err"
  status=$?
  [ $status -eq 1 ] || fail "exit status $status, expected 1"
  [ "$(grep -c . "$TMP/err")" -eq 1 ] || { cat "$TMP/err"; fail "expected one error line"; }
}

case_regress_sample() {
  "$LUMAR" regress "$REC" | tee "$TMP/log" || fail "regression failed"
  grep -q "^PASS" "$TMP/log" || fail "no PASS line"
}

# A copy of the sample recording at the same depth, so its relative scene path still resolves.
copy_recording() {
  ln -s "$SRC/data" "$TMP/data"
  mkdir -p "$TMP/recordings"
  cp -r "$REC" "$TMP/recordings/orbit"
}

case_regress_detects_a_wrong_golden_frame() {
  copy_recording
  cp "$TMP/recordings/orbit/expected/frame-000047.png" "$TMP/recordings/orbit/expected/frame-000015.png"
  "$LUMAR" regress "$TMP/recordings/orbit" >"$TMP/log" 2>&1
  status=$?
  cat "$TMP/log"
  [ $status -eq 1 ] || fail "regress passed with a wrong golden frame (status $status)"
  grep -q "^FAIL" "$TMP/log" || fail "no FAIL line"
}

case_regress_detects_a_shifted_tracker() {
  copy_recording
  # Claim a latency 150 ms off: the replayed poses lag the truth and the object drifts.
  sed -i 's/"latency_ns": 20000000/"latency_ns": 170000000/' "$TMP/recordings/orbit/session.json"
  grep -q '"latency_ns": 170000000' "$TMP/recordings/orbit/session.json" || fail "could not edit the latency"
  "$LUMAR" regress "$TMP/recordings/orbit" >"$TMP/log" 2>&1
  status=$?
  cat "$TMP/log"
  [ $status -eq 1 ] || fail "regress passed with a wrong latency (status $status)"
}

case_help_describes_every_option() {
  "$LUMAR" --help >"$TMP/h" || fail "lumar --help failed"
  for cmd in synth overlay regress calibrate; do
    grep -q "$cmd" "$TMP/h" || fail "lumar --help does not list $cmd"
    "$LUMAR" "$cmd" --help >"$TMP/h_$cmd" || fail "lumar $cmd --help failed"
    # every option line carries a description after the option names
    awk '/^  *-/ && NF < 2 { bad = 1 } END { exit bad }' "$TMP/h_$cmd" || fail "$cmd has an undocumented option"
  done
  grep -q -- "--tracker-noise-deg" "$TMP/h_synth" || fail "synth --help lacks --tracker-noise-deg"
  grep -q -- "--poses" "$TMP/h_overlay" || fail "overlay --help lacks --poses"
}

run_case
