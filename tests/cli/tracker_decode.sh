# lumar tracker decode: raw bytes and tracker.raw chunks -> exact CSV, counts on stderr.
source "$(dirname "$0")/lib.sh"

HEADER="station,x,y,z,qw,qx,qy,qz"
# Two ISOTRAK II ASCII records (list 2,4,1, inches). Expected values by hand:
# 12.34 in = 0.313436 m, -5.67 in = -0.144018 m, 100 in = 2.54 m; azimuth 90 is Rz(90):
# q = (cos 45, 0, 0, sin 45). Elevation 90 is Ry(90): q = (cos 45, 0, sin 45, 0).
REC1=$'01   12.34  -5.67 100.00  90.00   0.00   0.00\r\n'
REC2=$'02    1.00  -2.00   3.00   0.00  90.00   0.00\r\n'
ROW1="1,0.313436,-0.144018,2.540000,0.707107,0.000000,0.000000,0.707107"
ROW2="2,0.025400,-0.050800,0.076200,0.707107,0.000000,0.707107,0.000000"

# Appends one tracker.raw chunk (magic "LTRK", i64 arrival 0, u32 length, u32 crc32,
# payload) holding the bytes of file $1 to file $2. gzip's trailer is the CRC-32 of
# its input, little-endian, so no extra tool is needed.
append_chunk() {
  local n
  n=$(stat -c %s "$1")
  printf 'LTRK\0\0\0\0\0\0\0\0' >>"$2"
  printf "$(printf '\\x%02x\\x%02x\\x%02x\\x%02x' $((n & 255)) $((n >> 8 & 255)) $((n >> 16 & 255)) $((n >> 24 & 255)))" >>"$2"
  gzip -c <"$1" | tail -c 8 | head -c 4 >>"$2"
  cat "$1" >>"$2"
}

expect_stdout_and_summary() {  # expected CSV file, expected summary text
  diff -u "$1" "$TMP/stdout" || fail "CSV differs"
  grep -qF -- "$2" "$TMP/stderr" || { cat "$TMP/stderr" >&2; fail "stderr lacks '$2'"; }
  [ "$(grep -c . "$TMP/stderr")" -eq 1 ] || { cat "$TMP/stderr" >&2; fail "expected one summary line"; }
}

case_ascii_with_garbage() {
  # garbage (5 bytes), record 1, a torn record 2 (20 bytes: one rejected candidate),
  # record 2, then the first 10 bytes of record 1: a torn tail.
  printf '%s' "junk!" "$REC1" "${REC2:0:20}" "$REC2" "${REC1:0:10}" >"$TMP/raw.bin"
  "$LUMAR" tracker decode "$TMP/raw.bin" >"$TMP/stdout" 2>"$TMP/stderr" || fail "exit status $?"
  printf '%s\n' "$HEADER" "$ROW1" "$ROW2" >"$TMP/expected.csv"
  expect_stdout_and_summary "$TMP/expected.csv" \
    "2 records, 1 rejected records, 35 skipped bytes (10 in a torn record at the end)"
  echo "ok: $(cat "$TMP/stderr")"
}

case_output_over_its_input_is_refused() {
  # `--out` naming the input (directly or through a link) destroyed it; now exit 2, one
  # line, and the input is untouched.
  printf '%s' "$REC1" "$REC2" >"$TMP/t.raw"
  cp "$TMP/t.raw" "$TMP/before.raw"
  ln -s t.raw "$TMP/link.raw"
  for out in "$TMP/t.raw" "$TMP/link.raw" "$TMP/./t.raw"; do
    local status=0
    "$LUMAR" tracker decode "$TMP/t.raw" --out "$out" >"$TMP/stdout" 2>"$TMP/stderr" || status=$?
    [ $status -eq 2 ] || { cat "$TMP/stderr"; fail "exit $status for --out $out, expected 2"; }
    [ "$(grep -c . "$TMP/stderr")" -eq 1 ] && grep -q "is an input" "$TMP/stderr" || { cat "$TMP/stderr"; fail "message"; }
    cmp -s "$TMP/t.raw" "$TMP/before.raw" || fail "the input was changed by --out $out"
  done
}

case_isotrak_binary() {
  # The hand-packed ISOTRAK II binary record of tests/tracking/record_codec_test.cpp
  # (list 2,11, counts x=1000, y=-1, z=200 at 166.32 cm / 32767; q = (28378, -16384,
  # 0, 128) / 32767, renormalised). The same counts mean the same lengths in inches.
  local rec='\xb0\x31\x20\x68\x03\x7f\x7f\x68\x48\x00\x5a\x6e\x00\x40\x00\x25\x00\x00\x00\x02'
  printf "$rec\\xb0\\x7f$rec" >"$TMP/raw.bin"  # a stray start and garbage between them
  printf '%s\n' "$HEADER" "1,0.050758,-0.000051,0.010152,0.866019,-0.499995,0.000000,0.003906" \
    "1,0.050758,-0.000051,0.010152,0.866019,-0.499995,0.000000,0.003906" >"$TMP/expected.csv"
  for units in cm in; do
    "$LUMAR" tracker decode "$TMP/raw.bin" --binary --list 2,11 --units $units >"$TMP/stdout" 2>"$TMP/stderr" \
      || fail "exit status $?"
    expect_stdout_and_summary "$TMP/expected.csv" "2 records, 0 rejected records, 2 skipped bytes"
  done
  # As an ASCII stream the same bytes hold no record at all.
  "$LUMAR" tracker decode "$TMP/raw.bin" --list 2,11 >"$TMP/stdout" 2>"$TMP/stderr" || fail "exit status $?"
  printf '%s\n' "$HEADER" >"$TMP/expected.csv"
  expect_stdout_and_summary "$TMP/expected.csv" "0 records, 0 rejected records, 42 skipped bytes"
  echo "ok: $(cat "$TMP/stderr")"
}

case_fastrak_station_four() {
  # Station 4 exists on a Fastrak, not on an ISOTRAK II.
  printf '%s' "${REC1/01/04}" >"$TMP/raw.bin"
  "$LUMAR" tracker decode "$TMP/raw.bin" --device fastrak >"$TMP/stdout" 2>"$TMP/stderr" || fail "exit status $?"
  printf '%s\n' "$HEADER" "${ROW1/1,/4,}" >"$TMP/expected.csv"
  expect_stdout_and_summary "$TMP/expected.csv" "1 records, 0 rejected records, 0 skipped bytes"
  "$LUMAR" tracker decode "$TMP/raw.bin" >"$TMP/stdout" 2>"$TMP/stderr" || fail "exit status $?"
  printf '%s\n' "$HEADER" >"$TMP/expected.csv"
  expect_stdout_and_summary "$TMP/expected.csv" "0 records, 0 rejected records, 47 skipped bytes"
  echo "ok: $(cat "$TMP/stderr")"
}

case_tracker_raw_chunks() {
  # A recording's tracker.raw: record 1 split over two chunks, record 2 in a third, a
  # damaged chunk (its CRC is wrong), then a torn chunk (its header promises more bytes
  # than follow): the damage is counted apart from the torn tail a crash leaves.
  printf '%s' "${REC1:0:30}" >"$TMP/p1"
  printf '%s' "${REC1:30}" >"$TMP/p2"
  printf '%s' "$REC2" >"$TMP/p3"
  : >"$TMP/tracker.raw"
  for p in p1 p2 p3; do append_chunk "$TMP/$p" "$TMP/tracker.raw"; done
  printf 'LTRK\0\0\0\0\0\0\0\0\x03\0\0\0\0\0\0\0xyz' >>"$TMP/tracker.raw"
  printf 'LTRK\0\0\0\0\0\0\0\0\x40\0\0\0\0\0\0\0abc' >>"$TMP/tracker.raw"
  "$LUMAR" tracker decode "$TMP/tracker.raw" --out "$TMP/poses.csv" >"$TMP/stdout" 2>"$TMP/stderr" \
    || fail "exit status $?"
  [ ! -s "$TMP/stdout" ] || fail "--out given but CSV went to stdout"
  no_temporaries "$TMP"
  printf '%s\n' "$HEADER" "$ROW1" "$ROW2" >"$TMP/expected.csv"
  diff -u "$TMP/expected.csv" "$TMP/poses.csv" || fail "CSV differs"
  grep -qF "2 records, 0 rejected records, 0 skipped bytes, 23 bytes of damaged chunks skipped, 23 bytes of a torn chunk ignored" "$TMP/stderr" \
    || { cat "$TMP/stderr" >&2; fail "summary"; }
  echo "ok: $(cat "$TMP/stderr")"
}

case_sample_recording_matches_its_poses() {
  # The sample recording's tracker.raw, decoded, gives the poses its writer decoded
  # live (poses.csv: time_ns,station,x,y,z,qw,qx,qy,qz at full precision).
  local rec=$SRC/recordings/orbit
  [ -f "$rec/tracker.raw" ] || fail "no sample recording at $rec"
  # The tracker settings from session.json (one line, no spaces, for grep).
  local session list units=in
  session=$(tr -d ' \n' <"$rec/session.json")
  grep -q '"encoding":"ascii"' <<<"$session" || fail "sample recording is not ASCII"
  list=$(grep -o '"output_list":\[[0-9,]*\]' <<<"$session" | grep -o '[0-9][0-9,]*')
  [ -n "$list" ] || fail "no output list in session.json"
  grep -q '"centimetres":true' <<<"$session" && units=cm
  "$LUMAR" tracker decode "$rec/tracker.raw" --list "$list" --units $units >"$TMP/stdout" 2>"$TMP/stderr" \
    || fail "exit status $?"
  [ "$(head -1 "$TMP/stdout")" = "$HEADER" ] || fail "header"
  tail -n +2 "$rec/poses.csv" | cut -d, -f2- >"$TMP/poses"
  tail -n +2 "$TMP/stdout" >"$TMP/decoded"
  [ "$(wc -l <"$TMP/poses")" -gt 100 ] || fail "too few poses in the sample"
  [ "$(wc -l <"$TMP/poses")" -eq "$(wc -l <"$TMP/decoded")" ] || fail "row counts differ"
  paste -d, "$TMP/poses" "$TMP/decoded" | awk -F, '
    { for (i = 1; i <= 8; ++i) { d = $i - $(i + 8); if (d < 0) d = -d; if (d > 5.1e-7) { print "row " NR " column " i ": " $i " vs " $(i + 8); bad = 1 } } }
    END { exit bad }' || fail "decoded poses differ from poses.csv"
  echo "ok: $(wc -l <"$TMP/decoded") poses match; $(cat "$TMP/stderr")"
}

case_missing_file() {
  expect_bad_input "$TMP/nope.raw" "$TMP/out.csv" -- \
    "$LUMAR" tracker decode "$TMP/nope.raw" --out "$TMP/out.csv"
}

case_bad_list() {
  printf '%s' "$REC1" >"$TMP/raw.bin"
  expect_bad_input "item 5" "$TMP/out.csv" -- "$LUMAR" tracker decode "$TMP/raw.bin" --list 2,5,1 --out "$TMP/out.csv"
  expect_bad_input "2,x" "$TMP/out.csv" -- "$LUMAR" tracker decode "$TMP/raw.bin" --list 2,x --out "$TMP/out.csv"
}

case_bad_device() {
  printf '%s' "$REC1" >"$TMP/raw.bin"
  expect_bad_input "liberty" "$TMP/out.csv" -- "$LUMAR" tracker decode "$TMP/raw.bin" --device liberty --out "$TMP/out.csv"
}

case_bad_units() {
  printf '%s' "$REC1" >"$TMP/raw.bin"
  expect_bad_input "mm" "$TMP/out.csv" -- "$LUMAR" tracker decode "$TMP/raw.bin" --units mm --out "$TMP/out.csv"
}

run_case
