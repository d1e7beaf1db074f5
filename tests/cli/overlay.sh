# The overlay path end to end on the bundled sample recording.
source "$(dirname "$0")/lib.sh"
REC=$SRC/recordings/orbit

frames_in_recording() { grep -c '^[0-9]' "$REC/frames.csv"; }

case_headless_writes_video_and_frames() {
  [ -z "${DISPLAY:-}" ] || fail "DISPLAY should be unset"
  "$LUMAR" overlay --recording "$REC" --out "$TMP/out.mp4" --frames-dir "$TMP/frames" \
    --contact-sheet "$TMP/sheet.png" >"$TMP/log" 2>&1 ||
    { cat "$TMP/log"; fail "overlay failed"; }
  [ -s "$TMP/out.mp4" ] || fail "no video written"
  n=$(ls "$TMP/frames" | wc -l)
  [ "$n" -eq "$(frames_in_recording)" ] || fail "$n PNG frames, expected $(frames_in_recording)"
  grep -q "virtual objects" "$TMP/log" || fail "no per-stage timing summary"
  [ "$(head -c 8 "$TMP/sheet.png" | od -An -tx1 | tr -d ' ')" = "89504e470d0a1a0a" ] || fail "no PNG contact sheet"
  cat "$TMP/log"
}

case_window_under_xvfb() {
  command -v xvfb-run >/dev/null || fail "xvfb-run is not installed"
  xvfb-run -a -s "-screen 0 1024x768x24" "$LUMAR" overlay --recording "$REC" --window --max-frames 3 \
    --frames-dir "$TMP/frames" >"$TMP/log" 2>&1 || { cat "$TMP/log"; fail "windowed overlay failed"; }
  [ "$(ls "$TMP/frames" | wc -l)" -eq 3 ] || fail "expected 3 frames"
}

case_window_without_display_fails_cleanly() {
  "$LUMAR" overlay --recording "$REC" --window --max-frames 1 >"$TMP/out" 2>"$TMP/err"
  status=$?
  [ $status -eq 1 ] || fail "exit status $status, expected 1"
  [ "$(grep -c . "$TMP/err")" -eq 1 ] || { cat "$TMP/err"; fail "expected one error line"; }
}

case_regress_sample() {
  "$LUMAR" regress "$REC" | tee "$TMP/log" || fail "regression failed"
  grep -q "^PASS" "$TMP/log" || fail "no PASS line"
}

# A copy of the sample recording at the same depth, so its relative scene path still resolves.
copy_recording() {
  ln -s "$SRC/data" "$TMP/data"
  mkdir -p "$TMP/recordings"
  cp -r "$REC" "$TMP/recordings/orbit"
}

case_regress_detects_a_wrong_golden_frame() {
  copy_recording
  cp "$TMP/recordings/orbit/expected/frame-000047.png" "$TMP/recordings/orbit/expected/frame-000015.png"
  "$LUMAR" regress "$TMP/recordings/orbit" >"$TMP/log" 2>&1
  status=$?
  cat "$TMP/log"
  [ $status -eq 1 ] || fail "regress passed with a wrong golden frame (status $status)"
  grep -q "^FAIL" "$TMP/log" || fail "no FAIL line"
}

case_regress_detects_a_shifted_tracker() {
  copy_recording
  # Claim a latency 150 ms off: the replayed poses lag the truth and the object drifts.
  sed -i 's/"latency_ns": 20000000/"latency_ns": 170000000/' "$TMP/recordings/orbit/session.json"
  grep -q '"latency_ns": 170000000' "$TMP/recordings/orbit/session.json" || fail "could not edit the latency"
  "$LUMAR" regress "$TMP/recordings/orbit" >"$TMP/log" 2>&1
  status=$?
  cat "$TMP/log"
  [ $status -eq 1 ] || fail "regress passed with a wrong latency (status $status)"
}

case_undistortion_modes() {
  # 'keep' shows every input pixel, so parts of the output's border fall outside the
  # video and are black; 'crop' shows only valid pixels, so its border is not black.
  local mode
  for mode in same crop keep; do
    "$LUMAR" overlay --recording "$REC" --max-frames 1 --undistort $mode --frames-dir "$TMP/$mode" >"$TMP/log" 2>&1 ||
      { cat "$TMP/log"; fail "overlay --undistort $mode failed"; }
  done
  # Share of black pixels on the ring one pixel inside the image border.
  black_border() {
    python3 -c "import struct,sys,zlib
d=open(sys.argv[1],'rb').read(); i=8; idat=b''
while i < len(d):
    n,t=struct.unpack('>I4s',d[i:i+8]); c=d[i+8:i+8+n]; i+=12+n
    if t==b'IHDR': w,h,bits,ct=struct.unpack('>IIBB',c[:10])
    if t==b'IDAT': idat+=c
raw=zlib.decompress(idat); bpp=3 if ct==2 else 4; stride=w*bpp
rows=[]; prev=bytearray(stride)
for y in range(h):
    f=raw[y*(stride+1)]; line=bytearray(raw[y*(stride+1)+1:(y+1)*(stride+1)])
    for x in range(stride):
        a=line[x-bpp] if x>=bpp else 0; b=prev[x]; cc=prev[x-bpp] if x>=bpp else 0
        if f==1: line[x]=(line[x]+a)&255
        elif f==2: line[x]=(line[x]+b)&255
        elif f==3: line[x]=(line[x]+(a+b)//2)&255
        elif f==4:
            p=a+b-cc; pa,pb,pc=abs(p-a),abs(p-b),abs(p-cc)
            line[x]=(line[x]+(a if pa<=pb and pa<=pc else b if pb<=pc else cc))&255
    rows.append(line); prev=line
ring=[(1,x) for x in range(1,w-1)]+[(h-2,x) for x in range(1,w-1)]+[(y,1) for y in range(2,h-2)]+[(y,w-2) for y in range(2,h-2)]
print('%.4f' % (sum(1 for y,x in ring if sum(rows[y][x*bpp:x*bpp+3])==0)/len(ring)))" "$1"
  }
  local keep crop
  keep=$(black_border "$TMP"/keep/*.png)
  crop=$(black_border "$TMP"/crop/*.png)
  python3 -c "import sys; sys.exit(0 if $keep > 0.05 and $crop < 0.005 else 1)" ||
    fail "black border share: keep $keep (want > 0.05), crop $crop (want < 0.005)"
  cmp -s "$TMP"/same/*.png "$TMP"/crop/*.png && fail "crop gave the same image as same"
  echo "ok: black share of the border ring: keep $keep, crop $crop"
}

case_help_describes_every_option() {
  "$LUMAR" --help >"$TMP/h" || fail "lumar --help failed"
  for cmd in synth overlay regress calibrate; do
    grep -q "$cmd" "$TMP/h" || fail "lumar --help does not list $cmd"
    "$LUMAR" "$cmd" --help >"$TMP/h_$cmd" || fail "lumar $cmd --help failed"
    # every option line carries a description after the option names
    awk '/^  *-/ && NF < 2 { bad = 1 } END { exit bad }' "$TMP/h_$cmd" || fail "$cmd has an undocumented option"
  done
  grep -q -- "--tracker-noise-deg" "$TMP/h_synth" || fail "synth --help lacks --tracker-noise-deg"
  grep -q -- "--poses" "$TMP/h_overlay" || fail "overlay --help lacks --poses"
}

run_case
