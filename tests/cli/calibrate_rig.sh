# lumar calibrate-rig on a synthetic board recording (lumar synth --board): the offset,
# alignment and latency land near the truth, session.json is rewritten atomically, and
# bad input gets one line and exit status 2.
source "$(dirname "$0")/lib.sh"
CAM=$SRC/data/camera/webcam-640x480.yml

# json_check PYTHON_EXPRESSION: evaluated with j = the parsed stdout of the last run and
# s = the recording's session.json.
json_check() {
  python3 -c "import json,sys; j=json.load(open('$TMP/out.json')); s=json.load(open('$TMP/rec/session.json')); sys.exit(0 if ($1) else 1)" ||
    { cat "$TMP/out.json" >&2; fail "JSON check failed: $1"; }
}

make_recording() {
  "$LUMAR" synth --board 9x6 --square 0.025 --camera "$CAM" --out "$TMP/rec" "$@" >"$TMP/synth.log" 2>&1 ||
    { cat "$TMP/synth.log"; fail "synth --board failed"; }
}

case_recovers_truth_and_updates_session() {
  make_recording --seconds 8 --latency-ms 30 --assumed-latency-ms 5
  python3 -c "import json; s=json.load(open('$TMP/rec/session.json')); assert s['rig']['latency_ns'] == 5000000 and 'rig_calibration' not in s" ||
    fail "synth --board did not write the assumed latency"
  "$LUMAR" calibrate-rig --recording "$TMP/rec" --board 9x6 --square 0.025 --json >"$TMP/out.json" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr" >&2; fail "calibrate-rig failed"; }
  json_check "abs(j['latency_ns'] - 30e6) < 2e6 and abs(j['time_offset_ns'] - 25e6) < 2e6"
  json_check "j['views_used'] >= 200 and j['session_updated'] and j['peak_correlation'] > 0.9"
  # Offset and alignment against the truth the generator stored (2 mm; rotation via |w| of q_est^-1 q_true).
  local check="import json,math
s=json.load(open('$TMP/rec/session.json')); t=s['synth_board']['truth']; r=s['rig']
def dist(a,b): return 1e3*math.dist(a['translation'],b['translation'])
def angle(a,b):
  p,q=a['rotation_wxyz'],b['rotation_wxyz']; return math.degrees(2*math.acos(min(1,abs(sum(x*y for x,y in zip(p,q))))))
e=(dist(r['T_sensor_camera'],t['T_sensor_camera']),angle(r['T_sensor_camera'],t['T_sensor_camera']),dist(r['T_world_transmitter'],t['T_world_transmitter']),angle(r['T_world_transmitter'],t['T_world_transmitter']),(r['latency_ns']-t['latency_ns'])*1e-6)
print('ok: offset %.2f mm %.3f deg, world %.2f mm %.3f deg, latency %+.2f ms' % e)
assert e[0] < 2 and e[1] < 0.2 and e[2] < 3 and e[3] < 0.2 and abs(e[4]) < 2, e"
  python3 -c "$check" || fail "calibrated rig is not near the truth"
  json_check "s['rig_calibration']['latency_ns'] == s['rig']['latency_ns'] and s['format'] == 'lumar-recording'"
  no_temporaries "$TMP/rec"
  # A second run starts from the calibrated latency: nothing left to correct.
  "$LUMAR" calibrate-rig --recording "$TMP/rec" --every 2 --dry-run --json >"$TMP/out.json" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr" >&2; fail "second calibrate-rig failed"; }
  json_check "abs(j['time_offset_ns']) < 1.5e6 and not j['session_updated']"
}

case_plain_report() {
  make_recording --seconds 6
  "$LUMAR" calibrate-rig --recording "$TMP/rec" --dry-run >"$TMP/stdout" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr" >&2; fail "calibrate-rig failed"; }
  grep -q 'latency' "$TMP/stdout" || fail "no latency in the report"
  grep -q 'T_sensor_camera' "$TMP/stdout" || fail "no offset in the report"
  python3 -c "import json; s=json.load(open('$TMP/rec/session.json')); assert 'rig_calibration' not in s" ||
    fail "--dry-run wrote the session"
}

case_missing_recording() {
  expect_bad_input "$TMP/nothing" "" -- "$LUMAR" calibrate-rig --recording "$TMP/nothing"
}

case_wrong_board_size() {
  make_recording --seconds 1
  cp "$TMP/rec/session.json" "$TMP/before.json"
  expect_bad_input "no 7x5 board" "" -- "$LUMAR" calibrate-rig --recording "$TMP/rec" --board 7x5
  cmp -s "$TMP/rec/session.json" "$TMP/before.json" || fail "session.json changed on bad input"
}

case_too_few_views() {
  make_recording --seconds 0.3
  expect_bad_input "$TMP/rec" "" -- "$LUMAR" calibrate-rig --recording "$TMP/rec"
}

case_missing_camera_file() {
  make_recording --seconds 1
  expect_bad_input "$TMP/nocam.yml" "" -- "$LUMAR" calibrate-rig --recording "$TMP/rec" --camera "$TMP/nocam.yml"
}

# lumar calibrate --video: intrinsics from every 3rd frame of a board video (the first
# segment of a synthetic board recording, made with the webcam's calibration).
case_calibrate_from_video() {
  make_recording --seconds 1
  "$LUMAR" calibrate --video "$TMP/rec/video/segment-000000.mkv" --every 3 --out "$TMP/cam.yml" --json \
    >"$TMP/out.json" 2>"$TMP/stderr" || { cat "$TMP/stderr" >&2; fail "calibrate --video failed"; }
  json_check "j['views_used'] == 10 and abs(j['fx'] / 536.074 - 1) < 0.01 and abs(j['fy'] / 536.017 - 1) < 0.01"
  json_check "abs(j['cx'] - 342.37) < 3 and abs(j['cy'] - 235.54) < 3 and j['rms'] < 0.2"
  grep -q '^camera_matrix:' "$TMP/cam.yml" || fail "no camera_matrix in the YAML"
}

case_calibrate_missing_video() {
  expect_bad_input "$TMP/none.mkv" "$TMP/cam.yml" -- "$LUMAR" calibrate --video "$TMP/none.mkv" --out "$TMP/cam.yml"
}

run_case
