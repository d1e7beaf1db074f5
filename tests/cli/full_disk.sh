# A disk that fills up, for every command that writes: RLIMIT_FSIZE stands for the full
# disk (mounting a small tmpfs needs privileges the tests do not have), so writes past the
# limit fail with EFBIG. The limit is at least 1 KB: stderr goes to a file here too, and
# the one line must fit. Each command must exit 1 with one line saying so, and leave
# neither its final output nor a temporary file. (overlay: overlay.sh; record, which keeps
# what it had written: record.sh.)
source "$(dirname "$0")/lib.sh"
SCENE=$SRC/data/scenes/room/scene.json
CAM=$SRC/data/camera/webcam-640x480.yml

# 400 floor points: an answer of more than 1 KB.
write_query() {
  python3 -c "print('x,y,z,nx,ny,nz'); [print(f'{i * 0.01:.2f},0,{j * 0.01:.2f},0,1,0') for i in range(20) for j in range(20)]" \
    >"$TMP/query.csv"
}

case_synth() {
  mkdir "$TMP/out"
  expect_environment_error "the disk is full" "$TMP/out" -- \
    with_file_size_limit 50 "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/out/rec" --frames 30 --supersample 1
}

case_envmap() {
  "$LUMAR" synth --sweep --envmap "$SHARED/data/envmaps/courtyard.exr" --camera "$CAM" --out "$TMP/sweep" --frames 6 \
    --supersample 1 --exposures 2,-3 --codec ffv1 >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --sweep failed"; }
  mkdir "$TMP/out"
  expect_environment_error "cannot write environment map" "$TMP/out" -- \
    with_file_size_limit 100 "$LUMAR" envmap --recording "$TMP/sweep" --out "$TMP/out/m.exr" --width 256 --min-coverage 0
  # With its coverage and preview PNGs asked for as well: none of the three is left.
  expect_environment_error "cannot write environment map" "$TMP/out" -- \
    with_file_size_limit 100 "$LUMAR" envmap --recording "$TMP/sweep" --out "$TMP/out/m.exr" --width 256 \
    --min-coverage 0 --coverage "$TMP/out/c.png" --preview "$TMP/out/p.png"
}

case_calibrate() {
  mkdir "$TMP/out"
  expect_environment_error "c.yml: cannot write" "$TMP/out" -- \
    with_file_size_limit 1 "$LUMAR" calibrate --images "$SHARED/data/calib/checkerboard-9x6/left0*.jpg" --out "$TMP/out/c.yml"
  expect_environment_error "c.png: cannot write" "$TMP/out" -- \
    with_file_size_limit 8 "$LUMAR" calibrate --images "$SHARED/data/calib/checkerboard-9x6/left0*.jpg" \
    --out "$TMP/out/c.yml" --coverage "$TMP/out/c.png"
}

case_irradiance_and_shadows() {
  mkdir "$TMP/out"
  write_query
  expect_environment_error "i.csv: cannot write" "$TMP/out" -- \
    with_file_size_limit 1 "$LUMAR" irradiance --scene "$SCENE" --query "$TMP/query.csv" --out "$TMP/out/i.csv"
  expect_environment_error "s.csv: cannot write" "$TMP/out" -- \
    with_file_size_limit 1 "$LUMAR" shadows --scene "$SCENE" --query "$TMP/query.csv" --out "$TMP/out/s.csv"
}

case_tracker_decode() {
  mkdir "$TMP/out"
  expect_environment_error "d.csv: cannot write" "$TMP/out" -- \
    with_file_size_limit 1 "$LUMAR" tracker decode "$SRC/recordings/orbit/tracker.raw" --out "$TMP/out/d.csv"
}

run_case
