# lumar calibrate-response and calibrate-vignetting on synthetic images made here with
# a known response (sRGB) and a known fall-off, and their bad input.
source "$(dirname "$0")/lib.sh"
CAMERA=$SRC/data/camera/webcam-640x480.yml

# write_png FILE W H PY_EXPR: an RGB PNG whose 8-bit grey value at (x, y) is PY_EXPR.
write_png() {
  python3 - "$1" "$2" "$3" "$4" <<'PY'
import math, struct, sys, zlib
path, w, h, expr = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
def srgb(v):
    v = min(max(v, 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
value = eval('lambda x, y: ' + expr)
rows = []
for y in range(h):
    row = bytearray(b'\x00')
    for x in range(w):
        v = max(0, min(255, int(round(value(x, y)))))
        row += bytes((v, v, v))
    rows.append(bytes(row))
png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
png += chunk(b'IDAT', zlib.compress(b''.join(rows))) + chunk(b'IEND', b'')
open(path, 'wb').write(png)
PY
}

# A bracket of a scene spanning three decades of radiance, seen through sRGB.
write_bracket() {
  local t
  for t in 0.0625 0.25 1 4; do
    write_png "$TMP/bracket-$t.png" 96 64 "255 * srgb($t * 10 ** (-2 + 3 * x / 95) * (0.5 + 0.5 * y / 63))"
  done
}

json_check() {
  python3 -c "import json,sys; j=json.load(open('$TMP/out.json')); sys.exit(0 if ($1) else 1)" ||
    { cat "$TMP/out.json" >&2; fail "JSON check failed: $1"; }
}

case_response_recovers_srgb_shape() {
  write_bracket
  mkdir "$TMP/rec" && cp "$SRC/recordings/orbit/session.json" "$TMP/rec/"
  "$LUMAR" calibrate-response --images "$TMP"/bracket-{0.0625,0.25,1,4}.png --times 0.0625 0.25 1 4 \
    --out "$TMP/response.json" --hdr "$TMP/merged.hdr" --session "$TMP/rec" --json >"$TMP/out.json" 2>"$TMP/stderr" ||
    { cat "$TMP/stderr" >&2; fail "calibrate-response failed"; }
  # Debevec's curve is normalised so code 128 -> 1; sRGB puts code 64 at 0.2378 of that
  # and code 192 at 2.463 of it.
  json_check "abs(j['samples']['g'][2] - 1) < 1e-3"
  json_check "abs(j['samples']['g'][1] / 0.2378 - 1) < 0.15 and abs(j['samples']['g'][3] / 2.463 - 1) < 0.15"
  [ -s "$TMP/merged.hdr" ] || fail "merged HDR missing"
  no_temporaries "$TMP"
  python3 -c "import json; j=json.load(open('$TMP/rec/session.json')); assert j['radiometry']['response'].endswith('response.json')" ||
    fail "session.json does not name the response"
  python3 -c "import json; j=json.load(open('$TMP/out.json')); print('ok: code 64 -> %.4f (sRGB 0.2378), 192 -> %.3f (sRGB 2.463)' % (j['samples']['g'][1], j['samples']['g'][3]))"
}

case_vignetting_fit_and_session() {
  read -r CX CY < <(python3 -c "import re; d=re.search(r'camera_matrix:.*?data: \[([^\]]*)\]', open('$CAMERA').read(), re.S).group(1).split(','); print(float(d[2]), float(d[5]))")
  # Flat field of linear level 0.5 under 1 - 0.3 r^2 + 0.05 r^4, r over the half-diagonal (400 px).
  write_png "$TMP/flat.png" 640 480 "255 * srgb(0.5 * (1 - 0.3 * (((x - $CX)**2 + (y - $CY)**2) / 160000) + 0.05 * (((x - $CX)**2 + (y - $CY)**2) / 160000)**2))"
  mkdir "$TMP/rec" && cp "$SRC/recordings/orbit/session.json" "$TMP/rec/"
  "$LUMAR" calibrate-vignetting --images "$TMP/flat.png" --camera "$CAMERA" --session "$TMP/rec" --json \
    >"$TMP/out.json" 2>"$TMP/stderr" || { cat "$TMP/stderr" >&2; fail "calibrate-vignetting failed"; }
  json_check "abs(j['a'] + 0.3) < 0.01 and abs(j['b'] - 0.05) < 0.01 and abs(j['level'] - 0.5) < 0.01"
  python3 -c "import json; v=json.load(open('$TMP/rec/session.json'))['radiometry']['vignetting']; assert abs(v[0]+0.3) < 0.01, v" ||
    fail "session.json does not hold the fit"
  python3 -c "import json; j=json.load(open('$TMP/out.json')); print('ok: a %.4f (-0.3), b %.4f (0.05)' % (j['a'], j['b']))"
}

case_bad_input() {
  write_bracket
  expect_bad_input "exposure times" "$TMP/r.json" -- \
    "$LUMAR" calibrate-response --images "$TMP"/bracket-{0.0625,0.25}.png --times 1 --out "$TMP/r.json"
  expect_bad_input "$TMP/missing.png" "$TMP/r.json" -- \
    "$LUMAR" calibrate-response --images "$TMP/missing.png" "$TMP/bracket-1.png" --times 1 2 --out "$TMP/r.json"
  # A 96x64 image is not a flat field of the 640x480 camera.
  expect_bad_input "640x480" "" -- \
    "$LUMAR" calibrate-vignetting --images "$TMP/bracket-1.png" --camera "$CAMERA"
  printf 'not json' >"$TMP/bad.json"
  expect_bad_input "$TMP/bad.json" "" -- \
    "$LUMAR" calibrate-vignetting --images "$TMP/bracket-1.png" --camera "$CAMERA" --response "$TMP/bad.json"
}

run_case
