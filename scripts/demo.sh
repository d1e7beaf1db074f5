#!/usr/bin/env bash
# Installs what is missing, builds the lumar command (Release) and composites the figurine into the
# bundled sample recording. Writes out/demo.mp4, out/demo-contact.png and out/demo-frames/*.png.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
bash "$top/scripts/build.sh" release lumar  # the command alone: no tests or benchmarks
lumar="$top/build/release/app/lumar"
mkdir -p "$top/out"
rm -rf "$top/out/demo.mp4" "$top/out/demo-frames" "$top/out/demo-contact.png"
"$lumar" overlay --recording "$top/recordings/orbit" --out "$top/out/demo.mp4" --frames-dir "$top/out/demo-frames" \
  --contact-sheet "$top/out/demo-contact.png"
echo "demo: wrote $top/out/demo.mp4, $top/out/demo-contact.png and $top/out/demo-frames/"
