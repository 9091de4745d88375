#!/bin/bash
# Mesh / degree / increment study of prm/fem_perforated_plate.prm
# (doc/verification/fem_perforated_plate.md).
#
#   doc/scripts/perforated_plate_study.sh HYSTERON OUTDIR [p:h:N ...]
#
# Runs a variant of the shipped scene for each p:h:N (FEM/Degree, FEM/Mesh/Cell size,
# FEM/Number of increments; default: the table of the report) in OUTDIR/p<p>_h<h>_N<N>/,
# with `--quiet`, and prints a markdown table (stiffness error against the independent
# reference, loads at 1, 1.5, 2 and 4 mm, the general-yield load, Newton iterations, wall
# time). Plot the curves with doc/scripts/plot_perforated_plate.py OUTDIR/*/.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene="$here/../../prm/fem_perforated_plate.prm"
hysteron=$(readlink -f "$1")
out=$2
shift 2
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
  cases=(1:0.1:40 1:0.05:40 1:0.025:40 1:0.0125:40 1:0.00625:40
         2:0.1:40 2:0.05:40 2:0.025:40 2:0.0125:40
         2:0.05:20 2:0.05:80 2:0.05:160 2:0.05:320)
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
for c in "${cases[@]}"; do
  IFS=: read -r p h n <<< "$c"
  name="p${p}_h${h}_N${n}"
  mkdir -p "$out/$name"
  sed -e "s/^\( *set Degree *=\).*/\1 $p/" \
      -e "s/^\( *set Cell size *=\).*/\1 $h/" \
      -e "s/^\( *set Number of increments *=\).*/\1 $n/" \
      -e "s#^\( *set Directory *=\).*#\1 .#" \
      -e "s/^\( *set Probe points *=.*\)/\1\n  set Write VTU    = false/" \
      -e "s/^\( *set Write quadrature point table *=\).*/\1 false/" \
      "$scene" > "$out/$name/scene.prm"
  start=$(date +%s.%N)
  (cd "$out/$name" && "$hysteron" --quiet scene.prm)
  end=$(date +%s.%N)
  echo "$end - $start" | bc > "$out/$name/wall_time"
done
/usr/bin/python3 - "$out" "${cases[@]}" <<'EOF'
import csv, os, sys
out, cases = sys.argv[1], sys.argv[2:]
K_ref, F_lim, D = 6.907882e8, 262e6 * 0.125 * 0.025, 4e-3
print("| element | h [m] | increments | K0 - K_ref | F(1 mm) [kN] | F(1.5 mm) | F(2 mm) | F(4 mm) "
      "| F_gy [kN] (/F_lim) | Newton iterations | wall time [s] |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for c in cases:
    p, h, n = c.split(":")
    d = os.path.join(out, f"p{p}_h{h}_N{n}")
    r = list(csv.DictReader(open(os.path.join(d, "reactions.csv"))))
    u = [D * float(x["time"]) for x in r]
    F = [float(x["top_y"]) for x in r]
    k0 = F[1] / u[1]
    kp = (F[-1] - F[-2]) / (u[-1] - u[-2])
    f_gy = k0 * (F[-1] - kp * u[-1]) / (k0 - kp)
    def at(x):
        for i in range(1, len(u)):
            if u[i] >= x - 1e-15:
                return 1e-3 * (F[i - 1] + (F[i] - F[i - 1]) * (x - u[i - 1]) / (u[i] - u[i - 1]))
    its = sum(1 for _ in open(os.path.join(d, "newton.csv"))) - 1
    wall = float(open(os.path.join(d, "wall_time")).read())
    print(f"| Q{p} | {h} | {n} | {100 * (k0 / K_ref - 1):+.2f} % | {at(1e-3):.1f} | {at(1.5e-3):.1f} "
          f"| {at(2e-3):.1f} | {at(4e-3):.1f} | {f_gy / 1e3:.1f} ({f_gy / F_lim:.3f}) | {its} | {wall:.1f} |")
EOF
