# lumar shadows: attenuation of query points by the sample scene's figurine, with the
# three methods (lines, reference, sphere), and bad input (exit 2, one line, no output).
source "$(dirname "$0")/lib.sh"
SCENE=$SRC/data/scenes/room/scene.json

# Floor points under and around the figurine (at the origin) and one far away.
write_query() {
  python3 - "$TMP/in.csv" <<'PY'
import sys
rows = ["x,y,z,nx,ny,nz"]
for i in range(-6, 7):
    for j in range(-6, 7):
        rows.append("%g,0,%g,0,1,0" % (0.06 * i, 0.06 * j))
rows.append("2.5,0,2.0,0,1,0")
open(sys.argv[1], "w").write("\n".join(rows) + "\n")
PY
}

# check_csv PYTHON_EXPRESSION with a = list of (r, g, b) rows of $TMP/$1.
check_csv() {
  python3 -c "
import csv,sys
rows=list(csv.reader(open('$TMP/$1')))
assert rows[0]==['r','g','b'], rows[0]
a=[tuple(map(float,r)) for r in rows[1:]]
sys.exit(0 if ($2) else 1)" || fail "check failed on $1: $2"
}

case_methods_agree_and_baseline_differs() {
  write_query
  for m in lines reference sphere; do
    "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/$m.csv" --method $m 2>"$TMP/stderr" ||
      { cat "$TMP/stderr" >&2; fail "shadows --method $m failed"; }
    no_temporaries "$TMP"
  done
  check_csv lines.csv "len(a) == 170 and all(0 <= v <= 1 for r in a for v in r)"
  check_csv lines.csv "min(r[1] for r in a) < 0.9"    # a shadow under the figurine
  check_csv lines.csv "min(a[-1]) > 0.99"               # the far corner: barely touched
  python3 - "$TMP" <<'PY' || fail "lines and reference disagree, or the 2004 baseline is not worse"
import csv, sys
read = lambda m: [tuple(map(float, r)) for r in list(csv.reader(open(f"{sys.argv[1]}/{m}.csv")))[1:]]
ref, lines, sphere = read("reference"), read("lines"), read("sphere")
def err(a):
    d = [abs(x - y) for ra, rr in zip(a, ref) for x, y in zip(ra, rr) if y < 0.98]
    return sum(d) / max(1, len(d))
e_lines, e_sphere = err(lines), err(sphere)
print("ok: mean |attenuation - reference| in shadow: lines %.4f, 2004 sphere %.4f" % (e_lines, e_sphere))
sys.exit(0 if e_lines <= 0.02 and e_sphere > 2 * e_lines else 1)
PY
}

case_default_method_is_lines() {
  write_query
  "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/default.csv" 2>/dev/null || fail "default run failed"
  "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/lines.csv" --method lines 2>/dev/null || fail "lines run failed"
  cmp -s "$TMP/default.csv" "$TMP/lines.csv" || fail "the default method is not lines"
}

case_query_columns_go_by_the_header() {
  # The header names the columns: the same points written nz,ny,nx,z,y,x give the same
  # answer (before, columns were read by position: 1.0 instead of 0.990).
  write_query
  python3 - "$TMP/in.csv" "$TMP/reordered.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
with open(sys.argv[2], "w") as f:
    for r in rows:
        f.write(",".join(reversed(r)) + "\n")
PY
  head -1 "$TMP/reordered.csv" | grep -q "^nz,ny,nx,z,y,x$" || fail "the reordered header is wrong"
  "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/a.csv" 2>/dev/null || fail "run failed"
  "$LUMAR" shadows --scene "$SCENE" --query "$TMP/reordered.csv" --out "$TMP/b.csv" 2>/dev/null || fail "run failed"
  cmp -s "$TMP/a.csv" "$TMP/b.csv" || fail "the answer depends on the column order"
  check_csv a.csv "min(min(r) for r in a) < 0.995"  # some points are shadowed, so the test can fail
}

case_bounce_adds_the_objects_light() {
  # A white sphere on a plane under a uniform sky leaves the plane unchanged: it blocks F
  # of the sky and sends F back (1 - (1 - albedo) F); lines and reference agree with that,
  # and a black one leaves the shadow alone. The 2004 method has no bounce: refused.
  python3 - "$TMP" <<'PY'
import json, math, os, struct, sys
tmp = sys.argv[1]
# A uniform sky as a Radiance HDR (RGBE, flat scanlines), 64 x 32, radiance 1.
w, h = 64, 32
with open(os.path.join(tmp, "sky.hdr"), "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
    f.write(bytes([128, 128, 128, 129]) * (w * h))
# A UV sphere of radius 0.5 with its vertex normals.
rows = ["ply", "format ascii 1.0"]
verts, faces, n_lat, n_lon = [], [], 32, 64
for i in range(n_lat + 1):
    t = math.pi * i / n_lat
    for j in range(n_lon):
        p = 2 * math.pi * j / n_lon
        verts.append((math.sin(t) * math.cos(p), math.cos(t), math.sin(t) * math.sin(p)))
for i in range(n_lat):
    for j in range(n_lon):
        a, b = i * n_lon + j, i * n_lon + (j + 1) % n_lon
        c, d = a + n_lon, b + n_lon
        faces += [(a, c, d), (a, d, b)]
rows += ["element vertex %d" % len(verts), "property float x", "property float y", "property float z",
         "property float nx", "property float ny", "property float nz",
         "element face %d" % len(faces), "property list uchar int vertex_indices", "end_header"]
rows += ["%f %f %f %f %f %f" % (0.5 * x, 0.5 * y, 0.5 * z, x, y, z) for x, y, z in verts]
rows += ["3 %d %d %d" % f for f in faces]
open(os.path.join(tmp, "sphere.ply"), "w").write("\n".join(rows) + "\n")
# A floor 12 m wide.
open(os.path.join(tmp, "floor.obj"), "w").write(
    "v -6 0 -6\nv 6 0 -6\nv 6 0 6\nv -6 0 6\nf 1 3 2\nf 1 4 3\n")
for albedo in (1.0, 0.0):
    scene = {"format": "lumar-scene", "version": 1, "room": {"mesh": "floor.obj"},
             "environment_map": {"path": "sky.hdr", "capture_position": [0, 1, 0], "distant": True},
             "movement_box": {"min": [-1, 0, -1], "max": [1, 1, 1]},
             "objects": [{"name": "sphere", "mesh": "sphere.ply", "albedo": [albedo] * 3,
                          "pose": {"translation": [0, 0.5, 0]}}]}
    json.dump(scene, open(os.path.join(tmp, "sphere-%g.json" % albedo), "w"))
rows = ["x,y,z,nx,ny,nz"] + ["%g,0,0,0,1,0" % (0.5 * x) for x in (0.3, 0.6, 1.0, 1.5, 2.5)]
open(os.path.join(tmp, "in.csv"), "w").write("\n".join(rows) + "\n")
PY
  local albedo m
  for albedo in 1 0; do
    for m in lines reference; do
      XDG_CACHE_HOME="$TMP/cache" "$LUMAR" shadows --scene "$TMP/sphere-$albedo.json" --query "$TMP/in.csv" \
        --out "$TMP/$m-$albedo.csv" --method $m --bounce 2>"$TMP/stderr" ||
        { cat "$TMP/stderr" >&2; fail "shadows --method $m --bounce failed"; }
    done
  done
  python3 - "$TMP" <<'PY' || fail "the sphere's bounce is not 1 - (1 - albedo) F"
import csv, sys
xs = (0.3, 0.6, 1.0, 1.5, 2.5)
for albedo in (1, 0):
    for m in ("lines", "reference"):
        rows = [tuple(map(float, r)) for r in list(csv.reader(open("%s/%s-%d.csv" % (sys.argv[1], m, albedo))))[1:]]
        for x, r in zip(xs, rows):
            expected = 1 - (1 - albedo) * (1 / (x * x + 1)) ** 1.5
            assert abs(r[1] - expected) < 0.03, (m, albedo, x, r, expected)
        print("ok: %s, albedo %d: %s" % (m, albedo, " ".join("%.3f" % r[1] for r in rows)))
PY
  expect_bad_input "no bounce" "$TMP/sphere.csv" -- \
    "$LUMAR" shadows --scene "$TMP/sphere-1.json" --query "$TMP/in.csv" --out "$TMP/sphere.csv" --method sphere --bounce
}

case_bad_input() {
  write_query
  expect_bad_input "nope.csv" "$TMP/o1.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/nope.csv" --out "$TMP/o1.csv"
  printf 'x,y,z,nx,ny,nz\n0,0,0,0,1\n' >"$TMP/short.csv"
  expect_bad_input "short.csv:2:" "$TMP/o2.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/short.csv" --out "$TMP/o2.csv"
  printf 'x,y,z,nx,ny,nz\n0,0,0,0,0,0\n' >"$TMP/zero.csv"
  expect_bad_input "zero.csv:2:" "$TMP/o3.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/zero.csv" --out "$TMP/o3.csv"
  printf 'x,y,z,nx,ny,nz\n0,0,abc,0,1,0\n' >"$TMP/text.csv"
  expect_bad_input "text.csv:2:" "$TMP/o4.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/text.csv" --out "$TMP/o4.csv"
  printf 'x,y,z,nx,ny,nz\n' >"$TMP/header-only.csv"
  expect_bad_input "header-only.csv: no points" "$TMP/o8.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/header-only.csv" --out "$TMP/o8.csv"
  printf '0,0,0,0,1,0\n' >"$TMP/noheader.csv"
  expect_bad_input "noheader.csv" "$TMP/o5.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/noheader.csv" --out "$TMP/o5.csv"
  expect_bad_input "--method" "$TMP/o6.csv" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/o6.csv" --method bogus
  printf '{"format": "lumar-scene", "version": 1,' >"$TMP/broken.json"
  expect_bad_input "broken.json" "$TMP/o7.csv" -- "$LUMAR" shadows --scene "$TMP/broken.json" --query "$TMP/in.csv" --out "$TMP/o7.csv"
  expect_bad_input "missing-dir" "" -- "$LUMAR" shadows --scene "$SCENE" --query "$TMP/in.csv" --out "$TMP/missing-dir/o.csv"
}

run_case
