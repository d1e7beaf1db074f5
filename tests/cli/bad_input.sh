# Bad input: one clear line naming the file and the problem, exit status 2, no output.
source "$(dirname "$0")/lib.sh"
REC=$SRC/recordings/orbit
CAM=$SRC/data/camera/webcam-640x480.yml

# A copy of the sample scene whose paths point back into data/, for editing.
copy_scene() {
  sed -e "s#\"room.obj\"#\"$SRC/data/scenes/room/room.obj\"#" \
      -e "s#\"../../#\"$SRC/data/#g" "$SRC/data/scenes/room/scene.json" >"$TMP/scene.json"
}

case_missing_scene() {
  expect_bad_input "$TMP/nope/scene.json" "$TMP/rec" -- \
    "$LUMAR" synth --scene "$TMP/nope/scene.json" --camera "$CAM" --out "$TMP/rec" --frames 2
}

case_malformed_scene_json() {
  printf '{"format": "lumar-scene", "room": {"mesh": "room.obj",, }' >"$TMP/scene.json"
  expect_bad_input "$TMP/scene.json" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

case_corrupt_model() {
  copy_scene
  head -c 3000 /dev/urandom >"$TMP/broken.ply"
  sed -i "s#\"$SRC/data/models/parasaurolophus_solid.ply\"#\"$TMP/broken.ply\"#" "$TMP/scene.json"
  expect_bad_input "$TMP/broken.ply" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

case_unreadable_map() {
  copy_scene
  printf 'not an image at all' >"$TMP/broken.exr"
  sed -i "s#\"$SRC/data/envmaps/interior.exr\"#\"$TMP/broken.exr\"#" "$TMP/scene.json"
  expect_bad_input "$TMP/broken.exr" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

case_truncated_video() {
  cp -r "$REC" "$TMP/rec"
  seg=$(ls "$TMP"/rec/video/segment-* | head -1)
  truncate -s $(( $(stat -c %s "$seg") / 2 )) "$seg"
  expect_bad_input "$(basename "$seg")" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/rec" --scene "$SRC/data/scenes/room/scene.json" --out "$TMP/out.mp4"
}

case_malformed_session_json() {
  cp -r "$REC" "$TMP/rec"
  printf '{"camera": [' >"$TMP/rec/session.json"
  expect_bad_input "session.json" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/rec" --out "$TMP/out.mp4"
}

case_missing_recording() {
  expect_bad_input "$TMP/no-such-recording" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/no-such-recording" --out "$TMP/out.mp4"
}

case_missing_camera_file() {
  expect_bad_input "$TMP/none.yml" "$TMP/rec" -- \
    "$LUMAR" synth --scene "$SRC/data/scenes/room/scene.json" --camera "$TMP/none.yml" --out "$TMP/rec"
}

case_calibrate_no_images() {
  expect_bad_input "$TMP/*.jpg" "$TMP/cam.yml" -- \
    "$LUMAR" calibrate --images "$TMP/*.jpg" --out "$TMP/cam.yml"
}

# Corrupt inputs that were once accepted silently (exit 0, nothing on stderr).

case_garbage_tracker_stream_is_reported() {
  cp -r "$REC" "$TMP/rec"
  python3 -c "import sys; sys.stdout.buffer.write(bytes((i * 37 + 11) % 256 for i in range(9000)))" >"$TMP/rec/tracker.raw"
  "$LUMAR" overlay --recording "$TMP/rec" --scene "$SRC/data/scenes/room/scene.json" --out "$TMP/out.mp4" \
    --max-frames 2 >"$TMP/stdout" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr"; fail "overlay failed on a recording whose poses are lost"; }
  grep -q "tracker.raw: 9000 of 9000 bytes (100.0 %) of the tracker stream lost" "$TMP/stderr" ||
    { cat "$TMP/stderr"; fail "the lost tracker stream is not reported"; }
  # regress cannot measure anything without the tracker: an input error.
  expect_bad_input "tracker.raw: no tracker record in its 9000 bytes" "" -- \
    "$LUMAR" regress "$TMP/rec" --scene "$SRC/data/scenes/room/scene.json"
}

case_corrupt_first_tracker_chunk_loses_one_chunk() {
  cp -r "$REC" "$TMP/rec"
  # Byte 13 is in the first chunk's length: once, every pose after it was lost, "0 bytes skipped".
  python3 - "$TMP/rec/tracker.raw" <<'PY'
import sys
b = bytearray(open(sys.argv[1], "rb").read()); b[13] ^= 0x40; open(sys.argv[1], "wb").write(b)
PY
  local total records
  total=$(stat -c %s "$TMP/rec/tracker.raw")
  records=$("$LUMAR" tracker decode "$REC/tracker.raw" 2>&1 >/dev/null | sed -E 's/.*: ([0-9]+) records.*/\1/')
  "$LUMAR" overlay --recording "$TMP/rec" --scene "$SRC/data/scenes/room/scene.json" --out "$TMP/out.mp4" \
    --max-frames 2 >"$TMP/stdout" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr"; fail "overlay failed"; }
  local line
  line=$(grep "tracker:" "$TMP/stdout") || { cat "$TMP/stdout" "$TMP/stderr"; fail "no tracker summary"; }
  echo "$line"
  local got lost
  got=$(echo "$line" | sed -E 's/.*tracker: ([0-9]+) records.*/\1/')
  lost=$(echo "$line" | sed -E "s/.* ([0-9]+) of $total bytes lost.*/\1/")
  [ "$got" -ge $((records - 2)) ] && [ "$got" -lt "$records" ] || fail "read $got of $records records; one chunk should be lost"
  [ "$lost" -gt 0 ] && [ "$lost" -lt 200 ] || fail "$lost bytes reported lost; one chunk's worth expected"
}

case_session_camera_size_differs_from_video() {
  cp -r "$REC" "$TMP/rec"
  python3 - "$TMP/rec/session.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["camera"]["width"] = 320; s["camera"]["height"] = 240
json.dump(s, open(sys.argv[1], "w"), indent=2)
PY
  expect_bad_input "but the video is 640x480" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/rec" --out "$TMP/out.mp4"
}

case_frames_csv_out_of_order_or_empty() {
  cp -r "$REC" "$TMP/rec"
  local good
  good=$(cat "$REC/frames.csv")
  # Row 3 repeats row 2's time; then goes back in time; then a negative time.
  echo "$good" | awk -F, 'BEGIN { OFS = "," } NR == 3 { $2 = t } { t = $2; print }' >"$TMP/rec/frames.csv"
  expect_bad_input "frames.csv:3: time_ns" "$TMP/out.mp4" -- "$LUMAR" overlay --recording "$TMP/rec" --out "$TMP/out.mp4"
  echo "$good" | awk -F, 'BEGIN { OFS = "," } NR == 4 { $2 = 1 } { print }' >"$TMP/rec/frames.csv"
  expect_bad_input "frames.csv:4: time_ns 1 does not increase" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/rec" --out "$TMP/out.mp4"
  echo "$good" | awk -F, 'BEGIN { OFS = "," } NR == 2 { $2 = -5 } { print }' >"$TMP/rec/frames.csv"
  expect_bad_input "frames.csv:2: time_ns -5 is negative" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$TMP/rec" --out "$TMP/out.mp4"
  : >"$TMP/rec/frames.csv"
  expect_bad_input "frames.csv lists none" "$TMP/out.mp4" -- "$LUMAR" overlay --recording "$TMP/rec" \
    --scene "$SRC/data/scenes/room/scene.json" --out "$TMP/out.mp4"
  expect_bad_input "no frames" "$TMP/m.exr" -- "$LUMAR" envmap --recording "$TMP/rec" --out "$TMP/m.exr"
}

case_negative_environment_map() {
  copy_scene
  # A float PFM (rows bottom to top) of 64x32 whose every other value is negative.
  python3 - "$TMP/negative.pfm" <<'PY'
import struct, sys
w, h = 64, 32
vals = [(-1.0 if i % 2 else 1.0) for i in range(w * h * 3)]
with open(sys.argv[1], "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (w, h)); f.write(struct.pack("<%df" % len(vals), *vals))
PY
  sed -i "s#\"$SRC/data/envmaps/interior.exr\"#\"$TMP/negative.pfm\"#" "$TMP/scene.json"
  expect_bad_input "negative.pfm: environment map holds negative radiance" "$TMP/out.csv" -- \
    "$LUMAR" irradiance --scene "$TMP/scene.json" --query "$SRC/tests/fuzz/corpus/query_csv/standard" --out "$TMP/out.csv"
}

case_png_named_exr_as_environment_map() {
  copy_scene
  cp "$SRC/docs/envmap_quality_vs_resolution.png" "$TMP/map.exr"
  sed -i "s#\"$SRC/data/envmaps/interior.exr\"#\"$TMP/map.exr\"#" "$TMP/scene.json"
  expect_bad_input "map.exr: environment map is a png image of uint8 pixels, not high dynamic range" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

case_degenerate_object_mesh() {
  copy_scene
  printf 'v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n' >"$TMP/point.obj"
  sed -i "s#\"$SRC/data/models/parasaurolophus_solid.ply\"#\"$TMP/point.obj\"#" "$TMP/scene.json"
  expect_bad_input "point.obj: mesh is degenerate" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

# A folder, a device or a pipe where a file belongs: said as such, not "not found".
case_inputs_that_are_not_files() {
  mkdir -p "$TMP/folder.json"
  expect_bad_input "folder.json: scene manifest is a directory, not a file" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/folder.json" --out "$TMP/out.mp4"
  expect_bad_input "/dev/zero: query file is a device or a pipe, not a file" "$TMP/out.csv" -- \
    "$LUMAR" irradiance --scene "$SRC/data/scenes/room/scene.json" --query /dev/zero --out "$TMP/out.csv"
  expect_bad_input "/dev/stdin: camera calibration file is a device or a pipe" "$TMP/rec" -- \
    "$LUMAR" synth --scene "$SRC/data/scenes/room/scene.json" --camera /dev/stdin --out "$TMP/rec" </dev/null
  copy_scene
  sed -i "s#\"$SRC/data/scenes/room/room.obj\"#\"$TMP\"#" "$TMP/scene.json"
  expect_bad_input "room.mesh: $TMP is a directory, not a file" "$TMP/out.csv" -- \
    "$LUMAR" irradiance --scene "$TMP/scene.json" --query "$SRC/tests/fuzz/corpus/query_csv/standard" --out "$TMP/out.csv"
}

case_unknown_lighting_method_names_the_manifest() {
  copy_scene
  sed -i 's#"method": "volume"#"method": "bogus"#' "$TMP/scene.json"
  expect_bad_input "$TMP/scene.json: lighting.method: unknown method \"bogus\"" "$TMP/out.mp4" -- \
    "$LUMAR" overlay --recording "$REC" --scene "$TMP/scene.json" --out "$TMP/out.mp4"
}

run_case
