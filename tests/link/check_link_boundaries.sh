#!/usr/bin/env bash
# Who may use whom (docs/architecture.md), checked on the build's own link lines: each
# probe is an empty program linked against one library target only, with --no-as-needed,
# so its DT_NEEDED entries are the shared libraries that target's link interface brings.
# Usage: check_link_boundaries.sh PROBE_base PROBE_tracking PROBE_capture PROBE_lighting PROBE_render
set -uo pipefail
[ $# -eq 5 ] || { echo "usage: $0 base tracking capture lighting render (probe programs)" >&2; exit 2; }
heavy='embree|OpenImageIO|assimp|libGL|libEGL|libX11|libglfw|libepoxy'
needed() { readelf -d "$1" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p'; }
status=0
for probe in "$1" "$2" "$3"; do
  bad=$(needed "$probe" | grep -E "$heavy" | tr '\n' ' ')
  if [ -n "$bad" ]; then
    echo "FAIL: $(basename "$probe") links $bad" >&2
    status=1
  else
    echo "ok: $(basename "$probe") links none of Embree, OpenImageIO, assimp, GL, EGL, X11 ($(needed "$probe" | wc -l) libraries)"
  fi
done
# The check itself: the libraries above them do link those, so a probe that showed none
# of them would mean the method no longer sees the link line.
needed "$4" | grep -q embree || { echo "FAIL: the lighting probe shows no Embree: the check sees nothing" >&2; status=1; }
needed "$5" | grep -qE 'libEGL|libepoxy' || { echo "FAIL: the render probe shows no EGL: the check sees nothing" >&2; status=1; }
[ $status -eq 0 ] && echo "ok: the lighting and render probes do show Embree and EGL"
exit $status
