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
