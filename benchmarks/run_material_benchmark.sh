#!/usr/bin/env bash
# Material-update benchmark: updates per second per core and error against a converged
# reference, for every stress state, integrator and n in {2, 8, 32}. Writes
# doc/benchmarks/material_updates.{csv,md,png}; doc/benchmarks.md includes the table.
# Usage: benchmarks/run_material_benchmark.sh [build dir]   (a Release build)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(realpath "${1:-$root/build}")
grep -q 'CMAKE_BUILD_TYPE:STRING=Release' "$build/CMakeCache.txt" ||
  { echo "run_material_benchmark.sh: $build is not a Release build" >&2; exit 1; }
out="$root/doc/benchmarks"
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$build/benchmarks/material_updates" --repeats 5 --points 1000 --steps 600 \
  --csv "$out/material_updates.csv" > "$out/material_updates.table.md"
/usr/bin/python3 "$root/benchmarks/report_material_updates.py" "$out/material_updates.csv" \
  "$out/material_updates.png"
{
  echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs);"
  echo "build: Release (deal.II $(grep -o 'DEAL_II_PACKAGE_VERSION "[^"]*"' /usr/include/deal.II/base/config.h | cut -d'"' -f2)), 1 core, median of 5 runs of 1000 points x 1200 steps (increments about eps_y/20);"
  echo "date: $(date -u +%Y-%m-%d). Command: benchmarks/run_material_benchmark.sh"
  echo
  cat "$out/material_updates.table.md"
} > "$out/material_updates.md"
rm "$out/material_updates.table.md"
echo "wrote $out/material_updates.md and .png"
