# lumar solidify: the figurine's open scan becomes a closed solid of its size; bad input
# is one line with exit status 2 and nothing written.
source "$(dirname "$0")/lib.sh"
SCAN=$SRC/data/models/parasaurolophus_6700.ply

case_scan_becomes_a_closed_solid() {
  "$LUMAR" solidify "$SCAN" --out "$TMP/solid.ply" --triangles 6000 >"$TMP/out" 2>"$TMP/err" ||
    { cat "$TMP/err" >&2; fail "solidify failed"; }
  cat "$TMP/out"
  # "SCAN: 9140 triangles, 4422 open edges -> OUT: N triangles (...), 0 open edges, T s"
  grep -qE "9140 triangles, 4422 open edges -> .*solid\.ply: [0-9]+ triangles .*\), 0 open edges" "$TMP/out" ||
    fail "unexpected summary"
  local n
  n=$(sed -E 's/.*solid\.ply: ([0-9]+) triangles.*/\1/' "$TMP/out")
  [ "$n" -le 6000 ] && [ "$n" -ge 5000 ] || fail "$n triangles, expected at most 6000 and close to it"
  grep -q "solidify: finding the inside" "$TMP/err" || fail "no progress on stderr"
  no_temporaries "$TMP"
}

case_bad_input() {
  expect_bad_input "missing.ply" "$TMP/a.ply" -- "$LUMAR" solidify "$TMP/missing.ply" --out "$TMP/a.ply"
  expect_bad_input "give a .ply file" "$TMP/a.obj" -- "$LUMAR" solidify "$SCAN" --out "$TMP/a.obj"
  expect_bad_input "alpha" "$TMP/a.ply" -- "$LUMAR" solidify "$SCAN" --out "$TMP/a.ply" --alpha 0
  printf 'not a mesh\n' >"$TMP/junk.ply"
  expect_bad_input "junk.ply" "$TMP/a.ply" -- "$LUMAR" solidify "$TMP/junk.ply" --out "$TMP/a.ply"
  cp "$SCAN" "$TMP/scan.ply"
  expect_bad_input "scan.ply" "" -- "$LUMAR" solidify "$TMP/scan.ply" --out "$TMP/scan.ply"
  cmp -s "$SCAN" "$TMP/scan.ply" || fail "the input was overwritten"
}

run_case
