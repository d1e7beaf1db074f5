# The overlay path end to end on the bundled sample recording.
source "$(dirname "$0")/lib.sh"
REC=$SRC/recordings/orbit

frames_in_recording() { grep -c '^[0-9]' "$REC/frames.csv"; }

case_headless_writes_video_and_frames() {
  [ -z "${DISPLAY:-}" ] || fail "DISPLAY should be unset"
  "$LUMAR" overlay --recording "$REC" --out "$TMP/out.mp4" --frames-dir "$TMP/frames" >"$TMP/log" 2>&1 ||
    { cat "$TMP/log"; fail "overlay failed"; }
  [ -s "$TMP/out.mp4" ] || fail "no video written"
  n=$(ls "$TMP/frames" | wc -l)
  [ "$n" -eq "$(frames_in_recording)" ] || fail "$n PNG frames, expected $(frames_in_recording)"
  grep -q "virtual objects" "$TMP/log" || fail "no per-stage timing summary"
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
