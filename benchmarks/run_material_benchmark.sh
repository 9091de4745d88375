#!/usr/bin/env bash
# Material-update benchmark: updates per second per core and error against a converged
# reference, for every stress state, integrator and n in {2, 8, 32}; then the error-versus-cost
# sweep at n = 8 over increments per cycle and tolerances (material_updates --sweep). Writes
# OUT/material_updates.{csv,md,png} and OUT/material_sweep.csv (OUT = doc/benchmarks).
# Usage: benchmarks/run_material_benchmark.sh [build dir] [--out OUT] [--quick]
#        (a Release build; --quick: 1 repeat of 100 points, to check the script)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(realpath "${1:-$root/build}")
shift || true
out="$root/doc/benchmarks"
repeats=5 points=1000 sweep_points=200
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --quick) repeats=1 points=100 sweep_points=20; shift ;;
    *) echo "run_material_benchmark.sh: unknown argument '$1'" >&2; exit 1 ;;
  esac
done
grep -q 'CMAKE_BUILD_TYPE:STRING=Release' "$build/CMakeCache.txt" ||
  { echo "run_material_benchmark.sh: $build is not a Release build" >&2; exit 1; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$build/benchmarks/material_updates" --repeats "$repeats" --points "$points" --steps 600 \
  --csv "$out/material_updates.csv" > "$out/material_updates.table.md"
"$build/benchmarks/material_updates" --repeats "$repeats" --points "$sweep_points" \
  --sweep "$out/material_sweep.csv"
/usr/bin/python3 "$root/benchmarks/report_material_updates.py" "$out/material_updates.csv" \
  "$out/material_updates.png"
{
  echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs);"
  echo "build: Release (deal.II $(grep -o 'DEAL_II_PACKAGE_VERSION "[^"]*"' /usr/include/deal.II/base/config.h | cut -d'"' -f2)), 1 core, median of $repeats runs of $points points x 1200 steps (increments about eps_y/20);"
  echo "date: $(date -u +%Y-%m-%d). Command: benchmarks/run_material_benchmark.sh"
  echo
  cat "$out/material_updates.table.md"
} > "$out/material_updates.md"
rm "$out/material_updates.table.md"
echo "wrote $out/material_updates.md, .png and material_sweep.csv"
