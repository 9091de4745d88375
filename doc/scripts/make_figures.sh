#!/usr/bin/env bash
# Regenerate the figures in doc/figures/ from the shipped scenes (needs the build and Debian's
# python3-matplotlib). Usage: doc/scripts/make_figures.sh [path/to/hysteron]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
exe=$(realpath "${1:-$root/build/hysteron}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
plot="/usr/bin/python3 $root/doc/scripts/plot_history.py"
fig="$root/doc/figures"
mkdir -p "$fig"

cd "$work"
for scene in default table_2_1_kinematic table_2_1_mixed table_2_1_isotropic table_2_2_degradation; do
  "$exe" --quiet "$root/prm/$scene.prm"
done
mkdir -p fem_cantilever && (cd fem_cantilever && "$exe" --quiet "$root/prm/fem_cantilever_plastic.prm")

$plot --x eps_xx --y sig_xx --xscale 100 --yscale 1e-6 --xlabel "strain $\\varepsilon_{xx}$ [%]" \
  --ylabel "stress $\\sigma_{xx}$ [MPa]" --title "default scene: steel, n = 8, m = 0.5" \
  --out "$fig/default_loop.png" output/default/history.csv:"Bouc-Wen, adaptive"

$plot --x eps_xx --y sig_xx --xscale 100 --yscale 1e-6 --xlabel "strain $\\varepsilon_{xx}$ [%]" \
  --ylabel "stress $\\sigma_{xx}$ [MPa]" --title "Table 2-1: effect of the hardening fraction m" \
  --out "$fig/table_2_1_hardening.png" \
  output/table_2_1_kinematic/history.csv:"m = 0 (kinematic)" \
  output/table_2_1_mixed/history.csv:"m = 0.2 (mixed)" \
  output/table_2_1_isotropic/history.csv:"m = 1 (isotropic)"

$plot --x eps --y sig --xscale 100 --yscale 1e-6 --xlabel "strain [%]" --ylabel "stress [MPa]" \
  --title "Table 2-2: stiffness and strength degradation" \
  --out "$fig/table_2_2_loops.png" output/table_2_2_degradation/history.csv:"c_eta = 30, c_nu = 0.001"
$plot --x t --y eta --xlabel "t [s]" --ylabel "stiffness degradation $\\eta$ [-]" \
  --title "Table 2-2: evolution of eta (constant while unloading)" \
  --out "$fig/table_2_2_eta.png" output/table_2_2_degradation/history.csv:"eta"
$plot --x t --y e_h --yscale 1e-6 --xlabel "t [s]" --ylabel 'dissipated energy $e_h$ [MJ/m$^3$]' \
  --title "Table 2-2: hysteretic energy" \
  --out "$fig/table_2_2_energy.png" output/table_2_2_degradation/history.csv:"e_h"

# §5.1 with the FEM: tip load against tip deflection (displacement control, 30 mm at t = 1).
$plot --x time --y tip_y --xscale 30 --yscale=-1e-3 --xlabel "tip deflection [mm]" \
  --ylabel "tip load P [kN]" --title "FEM cantilever (§5.1): P_y = 20 kN, P_u = 30 kN (beam theory)" \
  --out "$fig/fem_cantilever_plastic.png" fem_cantilever/output/reactions.csv:"FEM, Q2, h = 12.5 mm"

# The same cantilever cycled (amplitude table, load steps): the run draws the load-displacement
# loop of its named set `tip` itself (history_tip.png, with gnuplot).
mkdir -p fem_cyclic && (cd fem_cyclic && "$exe" --quiet "$root/doc/scenes/fem_cantilever_cyclic.prm")
cp fem_cyclic/output/history_tip.png "$fig/fem_cantilever_cyclic_history.png"

# The §5.4 fine patch on a fixed and on a moving grid (doc/mpm.md, "Moving grid").
/usr/bin/python3 "$root/doc/scripts/make_moving_grid_figure.py" "$exe"
