#!/usr/bin/env bash
# Makes the sample recordings again from the sample scenes: recordings/orbit (the camera
# orbits the figurine) and recordings/walk (a still camera, the figurine walks), each with
# its truth on the golden frames (docs/ground_truth.md), then their expectations
# (lumar regress --update). The truth takes 32² rays per object pixel: their noise is the
# same in both of its takes, so the noise floor does not show it, but the composite is
# measured against it (docs/ground_truth.md). Needs a release build (scripts/build.sh release).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
lumar="${LUMAR:-$top/build/release/app/lumar}"
[ -x "$lumar" ] || { echo "make-recordings: $lumar not built; run scripts/build.sh release" >&2; exit 1; }
make_one() {  # NAME SCENE [synth options...]
  local name=$1 scene=$2
  shift 2
  # Made beside the old one, at the same depth (the session names its scene relative to
  # itself), and swapped in only when complete.
  local new="$top/recordings/.$name.new"
  rm -rf "$new"
  "$lumar" synth --scene "$top/data/scenes/room/$scene" --camera "$top/data/camera/webcam-640x480.yml" \
    --out "$new" --frames 48 --truth --truth-frames 0,15,31,47 --truth-strata 32 "$@"
  rm -rf "$top/recordings/$name"
  mv "$new" "$top/recordings/$name"
  "$lumar" regress --update "$top/recordings/$name"
}
make_one orbit scene.json
make_one walk walk.json --path still
"$lumar" regress "$top/recordings/orbit" "$top/recordings/walk"
