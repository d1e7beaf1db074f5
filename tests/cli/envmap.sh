# lumar synth --sweep makes a tracked sweep of a shared map; lumar envmap stitches it back.
source "$(dirname "$0")/lib.sh"
CAM=$SRC/data/camera/webcam-640x480.yml
MAP=$SHARED/data/envmaps/courtyard.exr

small_sweep() {
  "$LUMAR" synth --sweep --envmap "$MAP" --camera "$CAM" --out "$1" --frames 6 --supersample 1 \
    --exposures 2,-3 --codec ffv1 >"$TMP/synth.log" 2>&1 || { cat "$TMP/synth.log"; fail "synth --sweep failed"; }
}

case_sweep_then_envmap() {
  # A full sweep: 60 stations of 3 exposures, 0.75 deg tracker noise; refined rotations
  # must come within 0.15 deg RMS of the truth, and every output must appear.
  "$LUMAR" synth --sweep --envmap "$MAP" --camera "$CAM" --out "$TMP/rec" --frames 180 --supersample 1 \
    --exposures 4,-1,-6 --tracker-noise-deg 0.75 --codec ffv1 >"$TMP/synth.log" 2>&1 \
    || { cat "$TMP/synth.log"; fail "synth --sweep failed"; }
  for f in session.json frames.csv tracker.raw poses.csv truth.csv; do
    [ -s "$TMP/rec/$f" ] || fail "synth --sweep wrote no $f"
  done
  [ "$(grep -c '^[0-9]' "$TMP/rec/truth.csv")" -eq 180 ] || fail "expected 180 true poses"
  "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" --width 512 --coverage "$TMP/coverage.png" \
    --preview "$TMP/preview.png" --corrections "$TMP/corrections.csv" >"$TMP/envmap.log" 2>"$TMP/progress.log" \
    || { cat "$TMP/envmap.log" "$TMP/progress.log"; fail "envmap failed"; }
  cat "$TMP/envmap.log"
  for f in map.exr coverage.png preview.png corrections.csv; do
    [ -s "$TMP/$f" ] || fail "envmap wrote no $f"
  done
  grep -q "stitching" "$TMP/progress.log" || fail "no progress on stderr"
  [ "$(grep -c '^[0-9]' "$TMP/corrections.csv")" -eq 180 ] || fail "expected 180 corrections"
  local used
  used=$(sed -n 's/.*tracker \([0-9.]*\) deg RMS, used \([0-9.]*\) deg RMS.*/\2/p' "$TMP/envmap.log")
  [ -n "$used" ] || fail "envmap did not report the rotation error against the truth"
  awk -v u="$used" 'BEGIN { exit !(u <= 0.15) }' || fail "refined rotations are $used deg RMS off, expected <= 0.15"
}

case_envmap_no_frames() {
  small_sweep "$TMP/rec"
  head -1 "$TMP/rec/frames.csv" >"$TMP/frames" && mv "$TMP/frames" "$TMP/rec/frames.csv"
  expect_bad_input "$TMP/rec" "$TMP/map.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" --width 64
}

case_envmap_no_poses() {
  small_sweep "$TMP/rec"
  : >"$TMP/rec/tracker.raw"
  : >"$TMP/rec/poses.csv"
  expect_bad_input "$TMP/rec" "$TMP/map.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" --width 64
}

case_envmap_poses_do_not_cover_frames() {
  small_sweep "$TMP/rec"
  # Keep the first ~0.2 s of the tracker stream: later frames have no pose.
  head -c 1500 "$TMP/rec/tracker.raw" >"$TMP/raw" && mv "$TMP/raw" "$TMP/rec/tracker.raw"
  expect_bad_input "do not cover" "$TMP/map.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" --width 64
}

case_envmap_calibration_of_another_camera() {
  small_sweep "$TMP/rec"
  sed -e 's/image_width: 640/image_width: 320/' -e 's/image_height: 480/image_height: 240/' "$CAM" >"$TMP/small.yml"
  expect_bad_input "$TMP/small.yml" "$TMP/map.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" \
    --width 64 --camera "$TMP/small.yml"
}

case_envmap_bad_width() {
  small_sweep "$TMP/rec"
  expect_bad_input "--width" "$TMP/map.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/map.exr" --width 101
}

case_synth_sweep_bad_exposures() {
  expect_bad_input "--exposures" "$TMP/rec" -- "$LUMAR" synth --sweep --envmap "$MAP" --camera "$CAM" --out "$TMP/rec" \
    --exposures 0,x
}

run_case
