#!/usr/bin/env bash
# The stability suite (issue 7): every sweep, writing doc/stability/*.md, *.csv and *.png.
#   benchmarks/stability/run_all.sh [build] [--quick]
# --quick runs a small subset and writes into a temporary directory instead of doc/stability/.
# The fast checks run in ctest (tests/stability/).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(realpath "${1:-$root/build}")
quick=()
out="$root/doc/stability"
if [[ "${2:-}" == "--quick" ]]; then
  quick=(--quick)
  out=$(mktemp -d)
  echo "quick run: results in $out"
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "== Bouc-Wen: smoothness n x integrator"
/usr/bin/python3 "$root/benchmarks/stability/bouc_wen_smoothness.py" "$build" "${quick[@]}" --output "$out"
echo "== adaptive integrator: error against its tolerance at large increments"
/usr/bin/python3 "$root/benchmarks/stability/adaptive_tolerance.py" "$build" "${quick[@]}" --output "$out"
echo "== time step: 0.1 to 2.5 x the critical step"
/usr/bin/python3 "$root/benchmarks/stability/time_step_sweep.py" "$build" "${quick[@]}" --output "$out/time_step"
echo "== extreme but valid inputs"
/usr/bin/python3 "$root/benchmarks/stability/extreme_inputs.py" "$build" --output "$out/extreme_inputs"
