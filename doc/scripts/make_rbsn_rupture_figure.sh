#!/usr/bin/env bash
# doc/rbsn/rupture_released.png: tests/rbsn/rupture_force.prm (a double-notched bar pulled to
# rupture under load control) on 2 MPI ranks; the last output's cells coloured by `released`
# (the right half, cut off and held by nothing) and the broken facets in red, read from the
# .pvtu pieces.
# Usage: doc/scripts/make_rbsn_rupture_figure.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "${1:?usage: make_rbsn_rupture_figure.sh BUILD_DIR}" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's/set Write VTU = false/set Write VTU = true\n  set Interval = 0.5/' "$root/tests/rbsn/rupture_force.prm" > "$work/scene.prm"
(cd "$work" && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  mpirun -np 2 "$build/hysteron" --quiet scene.prm)
/usr/bin/python3 "$root/doc/scripts/plot_rbsn_cells.py" "$work/output/rbsn-00002.pvtu" \
  "$root/doc/rbsn/rupture_released.png" --field released --magnify 100 \
  --title "Load-controlled rupture on 2 ranks: the released half (displacements x100)"
echo "wrote doc/rbsn/rupture_released.png"
