# lumar synth makes a recording whose truth the overlay and regression recover.
source "$(dirname "$0")/lib.sh"
SCENE=$SRC/data/scenes/room/scene.json
CAM=$SRC/data/camera/webcam-640x480.yml

case_signals_stop_cleanly() {
  # SIGINT and SIGTERM mid-run: exit 130 within 2 s and the unfinished recording removed
  # (before: a folder with "complete": false and no frames, which overlay then replayed
  # as a 0-frame video); a later run into the same folder works.
  for signal in INT TERM; do
    stop_midway "$signal" "$TMP/rec/session.json" -- \
      "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 400 --supersample 1
    [ ! -e "$TMP/rec" ] || fail "the unfinished recording is left after SIG$signal"
  done
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 4 --supersample 1 >"$TMP/log" 2>&1 \
    || { cat "$TMP/log"; fail "later run"; }
  grep -q '"complete": true' "$TMP/rec/session.json" || fail "the later recording is not complete"
}

case_synth_then_regress() {
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 6 --fps 12 --supersample 1 \
    >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth failed"; }
  for f in session.json frames.csv tracker.raw poses.csv truth.csv; do
    [ -s "$TMP/rec/$f" ] || fail "synth wrote no $f"
  done
  [ "$(grep -c '^[0-9]' "$TMP/rec/frames.csv")" -eq 6 ] || fail "expected 6 frames in frames.csv"
  [ "$(grep -c '^[0-9]' "$TMP/rec/truth.csv")" -eq 6 ] || fail "expected 6 true poses"
  "$LUMAR" regress --update "$TMP/rec" || fail "regress --update failed"
  "$LUMAR" regress "$TMP/rec" | tee "$TMP/regress" || fail "regress on a fresh synthetic recording failed"
}

case_truth_beside_the_video() {
  # --truth: each frame again with the figurine physically present, the same with another
  # noise seed, and the figurine's mask (docs/ground_truth.md); a scene without objects
  # has no truth to render.
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 2 --supersample 1 --truth \
    >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --truth failed"; }
  local kind
  for kind in frame other-seed empty mask; do
    [ "$(ls "$TMP/rec/truth/$kind"-*.png | wc -l)" -eq 2 ] || fail "expected 2 truth/$kind-*.png"
  done
  cmp -s "$TMP/rec/truth/frame-00000.png" "$TMP/rec/truth/other-seed-00000.png" && fail "the two seeds agree"
  # regress measures the composite against it: one JSON object, every key of the measure,
  # the noise floors between 0.1 and 5 %, the composite's errors above their floors.
  "$LUMAR" regress --update "$TMP/rec" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "regress --update failed"; }
  "$LUMAR" regress --json "$TMP/rec" >"$TMP/json" 2>"$TMP/err" || { cat "$TMP/err"; fail "regress --json failed"; }
  cat "$TMP/err"
  [ "$(wc -l <"$TMP/json")" -eq 1 ] || fail "expected one JSON line on stdout"
  grep -q "composite vs truth" "$TMP/err" || fail "no measure on stderr"
  python3 - "$TMP/json" <<'PY' || fail "the measure's JSON"
import json, sys
r = json.load(open(sys.argv[1]))
keys = ["recording", "object_err", "edge_err", "shadow_err", "noise_ratio",
        "noise_floor_object_err", "noise_floor_edge_err", "noise_floor_shadow_err",
        "all_off_object_err", "all_off_edge_err", "all_off_shadow_err", "all_off_noise_ratio"]
missing = [k for k in keys if r.get(k) is None]
assert not missing, "missing: %s" % missing
for region in ("object", "edge", "shadow"):
    floor, err = r["noise_floor_%s_err" % region], r["%s_err" % region]
    assert 0.1 < floor < 5, "%s floor %s" % (region, floor)
    # The room's pixels are the video's, whose sensor noise is the truth's own (one take):
    # there the composite may come below the floor, which compares two takes.
    assert (0.1 if region == "shadow" else floor) < err < 50, "%s error %s (floor %s)" % (region, err, floor)
assert 0.2 < r["noise_ratio"] < 5, r["noise_ratio"]
# Antialiasing and self-occlusion close part of the gap (docs/ground_truth.md). Dark specks
# the truth has not: none on the closed figurine (the open scan gave 1-2; docs/solid.md).
assert r["specks"] == 0, r["specks"]
for region in ("object", "edge"):
    assert r["%s_err" % region] < 0.8 * r["all_off_%s_err" % region], region
print("ok:", {k: round(r[k], 2) for k in keys[1:]})
PY
  expect_bad_input "unknown feature 'sharpness'" "$TMP/none" -- \
    "$LUMAR" regress --without noise,sharpness "$TMP/rec"
  # The same scene without its figurine, its files named by absolute paths.
  python3 - "$SCENE" "$TMP/empty.json" <<'PY'
import json, os, sys
here = os.path.dirname(os.path.abspath(sys.argv[1]))
s = json.load(open(sys.argv[1]))
s["objects"] = []
s["room"]["mesh"] = os.path.join(here, s["room"]["mesh"])
s["environment_map"]["path"] = os.path.join(here, s["environment_map"]["path"])
json.dump(s, open(sys.argv[2], "w"))
PY
  expect_bad_input "--truth needs objects" "$TMP/empty" -- \
    "$LUMAR" synth --scene "$TMP/empty.json" --camera "$CAM" --out "$TMP/empty" --frames 2 --truth
  expect_bad_input "--truth-strata" "$TMP/few" -- \
    "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/few" --frames 2 --truth --truth-strata 1
}

case_truth_on_some_frames_and_its_limits() {
  # --truth-frames: truth for those frames only (a shipped recording keeps four), and
  # regress measures just them. --update writes the composite's limits into expected.json
  # and regress holds the composite to them.
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 3 --supersample 1 --truth \
    --truth-frames 0,2 >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --truth-frames failed"; }
  local kind
  for kind in frame other-seed empty mask; do
    [ -e "$TMP/rec/truth/$kind-00000.png" ] && [ -e "$TMP/rec/truth/$kind-00002.png" ] ||
      fail "truth/$kind of frames 0 and 2 missing"
    [ ! -e "$TMP/rec/truth/$kind-00001.png" ] || fail "frame 1 got truth/$kind"
  done
  "$LUMAR" regress --update "$TMP/rec" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "regress --update failed"; }
  grep -q "composite thresholds for .*1.2 x measured + 0.2 points" "$TMP/log" ||
    { cat "$TMP/log"; fail "the composite's thresholds were not explained"; }
  "$LUMAR" regress --json "$TMP/rec" >"$TMP/json" 2>"$TMP/err" || { cat "$TMP/err"; fail "regress --json failed"; }
  python3 - "$TMP/json" "$TMP/rec/expected.json" <<'PY' || fail "regress measured other frames, or wrote no limits"
import json, sys
r, e = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert r["composite_frames"] == 2, r["composite_frames"]
c = e["composite"]
lo, hi = c["noise_ratio_range"]
assert lo <= 0.8 and hi >= 1.25 and lo <= r["noise_ratio"] <= hi, (c, r["noise_ratio"])
for region in ("object", "edge", "shadow"):
    err, limit = r[region + "_err"], c[region + "_err_max"]
    assert err * 1.2 + 0.2 <= limit < err * 1.2 + 0.3, (region, err, limit)
assert c["specks_max"] == r["specks"] + 2 and r["composite_failure"] is None
print("ok: 2 frames measured; object %.2f %% (limit %.1f)" % (r["object_err"], c["object_err_max"]))
PY
  # A composite worse than its limit fails, and says which region.
  cp "$TMP/rec/expected.json" "$TMP/expected.json"
  python3 -c "import json; p='$TMP/rec/expected.json'; e=json.load(open(p)); e['composite']['object_err_max']=0.01; json.dump(e, open(p, 'w'))"
  "$LUMAR" regress "$TMP/rec" >"$TMP/log" 2>&1
  [ $? -eq 1 ] || { cat "$TMP/log"; fail "regress passed a composite over its object limit"; }
  grep -q "composite over its limits: object error % [0-9.]* > 0.0" "$TMP/log" || { cat "$TMP/log"; fail "no reason"; }
  cp "$TMP/expected.json" "$TMP/rec/expected.json"
  # A frame with truth but without its mask: one error line.
  mv "$TMP/rec/truth/mask-00002.png" "$TMP/mask.png"
  expect_bad_input "mask-00002.png: missing or unreadable truth frame" "" -- "$LUMAR" regress "$TMP/rec"
  mv "$TMP/mask.png" "$TMP/rec/truth/mask-00002.png"
  # Limits without the truth they need: a failure, not a silent pass.
  mv "$TMP/rec/truth" "$TMP/truth"
  "$LUMAR" regress "$TMP/rec" >"$TMP/log" 2>&1
  [ $? -eq 1 ] || { cat "$TMP/log"; fail "regress passed limits it could not measure"; }
  grep -q "truth/ is missing" "$TMP/log" || { cat "$TMP/log"; fail "no reason"; }
  # truth/ without any frame.
  mkdir "$TMP/rec/truth"
  expect_bad_input "no truth frame for any frame" "" -- "$LUMAR" regress "$TMP/rec"
  expect_bad_input "--truth-frames: frame 3 is not among the 3 frames" "$TMP/bad" -- \
    "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/bad" --frames 3 --truth --truth-frames 0,3
  expect_bad_input "--truth-frames goes with --truth" "$TMP/bad" -- \
    "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/bad" --frames 3 --truth-frames 0
}

case_truth_under_a_distant_sky_has_shadows() {
  # The courtyard: a distant map shown on a ground plane. The truth's objects cast their
  # shadows on that ground (before, a distant map meant no room to the truth: its
  # shadow region was the outlines' blur, 17,000 pixels over these 2 frames, and the
  # composite's right shadows counted as 10 % of error); the composite's fall where
  # they do, within 3 % and below the all-off composite's.
  "$LUMAR" synth --scene "$SRC/data/scenes/courtyard/scene.json" --camera "$CAM" --out "$TMP/sun" --frames 2 \
    --supersample 1 --truth >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --truth failed"; }
  "$LUMAR" regress --update "$TMP/sun" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "regress --update failed"; }
  "$LUMAR" regress "$TMP/sun" --json >"$TMP/sun.json" 2>"$TMP/err" || { cat "$TMP/err"; fail "regress failed"; }
  python3 - "$TMP/sun.json" "$TMP/err" <<'PY' || fail "the truth under a distant sky has no shadows to match"
import json, re, sys
j = json.loads(open(sys.argv[1]).readline())
pixels = int(re.search(r"over \d+ / \d+ / (\d+) pixels", open(sys.argv[2]).read()).group(1))
print(f"shadow region {pixels} pixels, error {j['shadow_err']:.2f} % (all off {j['all_off_shadow_err']:.2f} %)")
sys.exit(0 if pixels > 100000 and j["shadow_err"] < 3 and j["shadow_err"] < j["all_off_shadow_err"] else 1)
PY
}

case_under_a_sun_the_composite_meets_the_acceptance() {
  # data/scenes/city: the figurine and a sphere on the ground under city.exr, distant,
  # whose sun holds a quarter of the map's power in 50 texels (the courtyard's sky has
  # none). The composite against its truth meets issue 16's bounds: object and shadow
  # within 2 %, edge within 5 %, edge and shadow within a third of the 2004 look's, noise
  # ratio in [0.8, 1.25]. The object's third is below the noise floor here, so it is held
  # to the floor's margin instead (docs/ground_truth.md, "Under a sun").
  "$LUMAR" synth --scene "$SRC/data/scenes/city/scene.json" --camera "$CAM" --out "$TMP/sun" --frames 2 \
    --supersample 1 --truth >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --truth failed"; }
  "$LUMAR" regress --update "$TMP/sun" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "regress --update failed"; }
  "$LUMAR" regress "$TMP/sun" --json >"$TMP/sun.json" 2>"$TMP/err" || { cat "$TMP/err"; fail "regress failed"; }
  python3 - "$TMP/sun.json" <<'PY' || fail "under a sun the composite misses the acceptance's bounds"
import json, sys
j = json.loads(open(sys.argv[1]).readline())
print("object %.2f (floor %.2f, all off %.2f), edge %.2f (all off %.2f), shadow %.2f (all off %.2f) %%, noise ratio %.2f"
      % (j["object_err"], j["noise_floor_object_err"], j["all_off_object_err"], j["edge_err"], j["all_off_edge_err"],
         j["shadow_err"], j["all_off_shadow_err"], j["noise_ratio"]))
assert j["object_err"] <= 2 and j["shadow_err"] <= 2 and j["edge_err"] <= 5, j
assert j["edge_err"] <= j["all_off_edge_err"] / 3 and j["shadow_err"] <= j["all_off_shadow_err"] / 3, j
assert j["object_err"] <= j["noise_floor_object_err"] + 0.5, j
assert 0.8 <= j["noise_ratio"] <= 1.25, j
PY
}

case_bounce_lowers_the_shadow_error() {
  # A saturated red box beside the figurine (data/scenes/room/red_box.json): the truth
  # carries the light it reflects onto the floor, so the composite's shadow region is
  # closer to it with bounce than without, in the same run of the same recording; and
  # `--without all` (the 2004 look) switches bounce off too, its shadows the bounding
  # spheres' (`--without lines`).
  "$LUMAR" synth --scene "$SRC/data/scenes/room/red_box.json" --camera "$CAM" --out "$TMP/rec" --frames 2 \
    --supersample 1 --truth >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth --truth failed"; }
  "$LUMAR" regress --update "$TMP/rec" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "regress --update failed"; }
  "$LUMAR" regress --json "$TMP/rec" >"$TMP/with.json" 2>"$TMP/err" || { cat "$TMP/err"; fail "regress failed"; }
  "$LUMAR" regress --json --without bounce "$TMP/rec" >"$TMP/without.json" 2>"$TMP/err" ||
    { cat "$TMP/err"; fail "regress --without bounce failed"; }
  # The golden frames were made with the lines: the spheres' composite fails them (exit
  # 1), as it should, and still reports its errors.
  "$LUMAR" regress --json --without lines,bounce "$TMP/rec" >"$TMP/spheres.json" 2>"$TMP/err"
  [ $? -eq 1 ] && grep -q '"pass":false' "$TMP/spheres.json" ||
    { cat "$TMP/err"; fail "regress --without lines,bounce did not measure and fail its golden frames"; }
  python3 - "$TMP/with.json" "$TMP/without.json" "$TMP/spheres.json" <<'PY' ||
import json, sys
a, b, c = (json.load(open(f)) for f in sys.argv[1:4])
print("ok: shadow_err %.3f %% with bounce, %.3f %% without, noise floor %.3f %%; --without all %.3f %%"
      % (a["shadow_err"], b["shadow_err"], a["noise_floor_shadow_err"], a["all_off_shadow_err"]))
assert a["shadow_err"] < b["shadow_err"] - 0.05, (a["shadow_err"], b["shadow_err"])
# All off has no bounce and the 2004 shadows: its shadow error is the one of the bounding
# spheres without bounce (the other features barely touch the room's pixels), far above
# the lines'.
print("the bounding spheres without bounce: shadow_err %.3f %%" % c["shadow_err"])
assert abs(a["all_off_shadow_err"] - c["shadow_err"]) < 0.1, (a["all_off_shadow_err"], c["shadow_err"])
assert c["shadow_err"] > 2 * b["shadow_err"], (c["shadow_err"], b["shadow_err"])
PY
    fail "bounce does not bring the shadow region closer to the truth, or all off is not the 2004 look"
}

case_synth_refuses_existing_output() {
  mkdir -p "$TMP/rec"
  touch "$TMP/rec/keep-me"
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 2 2>"$TMP/err"
  [ $? -eq 2 ] || fail "expected exit status 2"
  [ -e "$TMP/rec/keep-me" ] || fail "synth touched an existing folder"
}

case_light_change_darkens_the_lamp_and_refuses_bad_boxes() {
  # The ceiling lamp at (-1.2, 3, 0.3) goes out half-way through a recording looking up at it:
  # the last frame is darker than the first where the lamp was; no other change.
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/rec" --frames 4 --supersample 1 --path room \
    --change-box -1.45 2.9 0.15 -0.95 3.1 0.45 --change-brighter-than 5 --change-scale 0 0 0 --change-at 0.05 \
    >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth with a light change failed"; }
  "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/same" --frames 4 --supersample 1 --path room \
    >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "synth failed"; }
  "$LUMAR" overlay --recording "$TMP/rec" --without all --frames-dir "$TMP/changed" >"$TMP/log" 2>&1 || fail "overlay"
  "$LUMAR" overlay --recording "$TMP/same" --without all --frames-dir "$TMP/unchanged" >"$TMP/log" 2>&1 || fail "overlay"
  first=$(python3 "$(dirname "$0")/png_tool.py" mean-abs-diff "$TMP/changed/frame-000000.png" "$TMP/unchanged/frame-000000.png")
  last=$(python3 "$(dirname "$0")/png_tool.py" mean-abs-diff "$TMP/changed/frame-000003.png" "$TMP/unchanged/frame-000003.png")
  python3 -c "import sys; sys.exit(0 if $first < 0.001 and $last > 0.01 else 1)" ||
    fail "frame 0 differs by $first levels (want ~0, before the change), frame 3 by $last (want the lamp gone)"
  echo "ok: before the change $first levels from the unchanged room, after $last"
  for box in "10 10 10 11 11 11" "-1 -1 -1 1 1"; do
    # shellcheck disable=SC2086
    "$LUMAR" synth --scene "$SCENE" --camera "$CAM" --out "$TMP/bad" --frames 2 --supersample 1 \
      --change-box $box --change-scale 0 0 0 2>"$TMP/err" >/dev/null
    [ $? -eq 2 ] || fail "--change-box $box: expected exit status 2"
    [ ! -e "$TMP/bad" ] || fail "--change-box $box: a recording was left behind"
    echo "ok: $(tail -1 "$TMP/err")"
  done
}

run_case
