#!/usr/bin/env bash
# Regenerate the figures of doc/verification/fem_mpm_compare.md (doc/verification/fem_mpm_compare/)
# from the FEM-versus-MPM scenes (needs the build and Debian's python3-matplotlib).
#
# Usage: doc/scripts/make_compare_figures.sh [path/to/hysteron] [runs]
#
# `runs` is a directory with one subdirectory per scene holding its output/ (as ctest leaves
# them in build/tests/runs/scenes/, or as `tests/run_prm_test.py --workdir runs/<scene>`
# writes them); a scene whose output/compare/ is missing is run there first. The full beam of
# doc/scenes/compare_beam_sinusoidal_full.prm (about 15 min) is plotted only if
# runs/compare_beam_sinusoidal_full/output/compare exists.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
exe=$(realpath "${1:-$root/build/hysteron}")
runs=$(realpath -m "${2:-$(mktemp -d)}")
fig="$root/doc/verification/fem_mpm_compare"
plot="/usr/bin/python3 $root/doc/scripts/plot_compare.py"
mkdir -p "$fig" "$runs"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

for scene in compare_patch_tension compare_patch_sinusoidal_isotropic compare_patch_sinusoidal_kinematic \
             compare_beam_sinusoidal compare_beam_degradation; do
  if [ ! -d "$runs/$scene/output/compare" ]; then
    /usr/bin/python3 "$root/tests/run_prm_test.py" --hysteron "$exe" --workdir "$runs/$scene" \
      "$root/prm/$scene.prm" > "$runs/$scene.log"
  fi
done

c() { echo "$runs/$1/output/compare/$2"; }
eps='$\varepsilon_{xx}$'
sig='$\sigma_{xx}$'

$plot --out "$fig/patch_tension.png" \
  --title "compare_patch_tension: §5.4 patch, constant velocity (MPM h = 1/60 m, 1 point/cell; FEM Q2 h = 1/60 m, quasi-static)" \
  "$(c compare_patch_tension probe_0.csv):von_mises:1:von Mises at A [Pa]" \
  "$(c compare_patch_tension probe_0.csv):s_yy:1:sigma_yy at A [Pa]" \
  "$(c compare_patch_tension reactions.csv):right_x:1:force of the right block [N]"

for h in isotropic kinematic; do
  $plot --out "$fig/patch_sinusoidal_$h.png" \
    --title "compare_patch_sinusoidal_$h: §5.4 patch, v = 0.015 cos(4 pi t / T) (MPM h = 1/60 m; FEM Q2 h = 0.05 m, implicit dynamics)" \
    "$(c compare_patch_sinusoidal_$h probe_0.csv):von_mises:1:von Mises at A [Pa]" \
    "$(c compare_patch_sinusoidal_$h probe_0.csv):eps_xx,s_xx:100,1:$eps at A [%],$sig at A [Pa]" \
    "$(c compare_patch_sinusoidal_$h reactions.csv):right_x:1:force of the right block [N]"
done

for scene in compare_beam_sinusoidal compare_beam_degradation compare_beam_sinusoidal_full; do
  [ -d "$runs/$scene/output/compare" ] || continue
  $plot --out "$fig/${scene#compare_}.png" \
    --title "$scene: §5.5 beam, F = 60 sin(pi t) kN at mid-span" \
    "$(c $scene average_0.csv):u_y:1000:mid-span deflection (strip mean) [mm]" \
    "$(c $scene average_1.csv):eps_xx,s_xx:100,1e-6:$eps bottom strip [%],$sig bottom strip [MPa]" \
    "$(c $scene average_1.csv):s_xx:1e-6:$sig bottom strip [MPa]"
done
ls -l "$fig"
