#!/usr/bin/env bash
# Regenerate the figures of doc/verification/frames.md (doc/verification/frames/) from the two
# frame scenes and their elastic variants (needs the build and Debian's python3-matplotlib).
#
# Usage: doc/scripts/make_frame_figures.sh [path/to/hysteron] [runs]
#
# `runs` holds one subdirectory per run with its output/; a run whose output/compare/ is missing
# is made there first: prm/compare_portal_frame.prm and prm/compare_frame_corner.prm through
# tests/run_prm_test.py (so their # CHECK lines are asserted), and their elastic variants (the one
# line `set Model = linear elastic`) with hysteron directly. About 5 minutes on one core.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
exe=$(realpath "${1:-$root/build/hysteron}")
runs=$(realpath -m "${2:-$(mktemp -d)}")
fig="$root/doc/verification/frames"
mkdir -p "$fig" "$runs"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

for scene in compare_portal_frame compare_frame_corner; do
  if [ ! -d "$runs/$scene/output/compare" ]; then
    /usr/bin/python3 "$root/tests/run_prm_test.py" --hysteron "$exe" --workdir "$runs/$scene" \
      "$root/prm/$scene.prm" > "$runs/$scene.log"
  fi
  if [ ! -d "$runs/${scene}_elastic/output/compare" ]; then
    mkdir -p "$runs/${scene}_elastic"
    sed 's/^\( *set Model =\) bouc-wen$/\1 linear elastic/' "$root/prm/$scene.prm" \
      > "$runs/${scene}_elastic/$scene.prm"
    (cd "$runs/${scene}_elastic" && "$exe" --quiet "$scene.prm" > run.log)
  fi
done

/usr/bin/python3 "$root/doc/scripts/plot_frames.py" --out "$fig" \
  --portal "$runs/compare_portal_frame_elastic" "$runs/compare_portal_frame" \
  --corner "$runs/compare_frame_corner_elastic" "$runs/compare_frame_corner"
ls -l "$fig"
