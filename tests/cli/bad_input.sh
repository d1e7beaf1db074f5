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
  sed -i "s#\"$SRC/data/models/parasaurolophus_6700.ply\"#\"$TMP/broken.ply\"#" "$TMP/scene.json"
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

run_case
