#!/usr/bin/python3
"""RBSN: the reaction of a 3D bar in tension against E A eps, by cell size and seed.

A 1 x 0.2 x 0.2 m bar, E = 1 GPa, nu = 0, k_s = k_n (Shear stiffness ratio = 1), one static
step: the face x = 0 clamped (fixed), the face x = 1 m pulled by u_x = 1 mm, the lateral faces
free. Two ways of pulling:

  x    Components = x: u_y, u_z and the rotations of the pulled cells free (the force acts at
       the nucleus, not as a traction at the centroid of the cell's face piece);
  all  Components = all with u = (1 mm, 0, 0): the pulled cells move rigidly (theta = 0).

Error: pull_x / (E A eps) - 1 with E A eps = 40 kN. Prints a Markdown table.

Usage: benchmarks/rbsn_bar_tension.py HYSTERON [--across 5 10] [--seeds 1 2 3] [--ways x all]
"""
import argparse
import csv
import os
import subprocess
import tempfile

SCENE = """set Dimension = 3
set Method = rbsn
set Body names = bar
set Boundary names = clamp, pull
set Random seed = {seed}
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
end
subsection Body bar
  set Shape = box(0, 0, 0, 1, 0.2, 0.2)
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Boundary pull
  set Type = displacement
  set Faces = x+
  set Components = {way}
  set Displacement = 1e-3*t; 0; 0
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {d}
  set Shear stiffness ratio = 1
  set Number of increments = 1
end
subsection Output
  set Directory = {out}
  set Write VTU = false
end
"""

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("hysteron")
parser.add_argument("--across", type=int, nargs="+", default=[5, 10])
parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
parser.add_argument("--ways", nargs="+", default=["x", "all"])
args = parser.parse_args()

print("| pulled components | cells across | d_m [m] | seed | error |")
print("|---|---|---|---|---|")
with tempfile.TemporaryDirectory() as tmp:
    for way in args.ways:
        for n in args.across:
            d = 0.2 / n
            for seed in args.seeds:
                out = os.path.join(tmp, f"{way}_{n}_{seed}")
                prm = out + ".prm"
                with open(prm, "w") as f:
                    f.write(SCENE.format(seed=seed, way=way, d=d, out=out))
                subprocess.run([args.hysteron, prm], check=True, stdout=subprocess.DEVNULL)
                with open(os.path.join(out, "reactions.csv")) as f:
                    last = list(csv.DictReader(f))[-1]
                error = float(last["pull_x"]) / 4e4 - 1
                print(f"| {way} | {n} | {d:.4g} | {seed} | {error:.3e} |", flush=True)
