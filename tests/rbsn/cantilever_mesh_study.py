#!/usr/bin/env python3
"""RBSN mesh study of the elastic cantilever, dissertation §3.7.1 and Table 3-2.

A 1 m x 0.1 m cantilever (E = 400000 N/m^2, nu = 0.3, b = 1 m, P = 1 N at the free end; beam
theory PL^3 / (3EI) = 0.01 m) is discretised with random Voronoi cells at eight minimum
distances d_m from 0.05 m to 0.005 m, three seeds each. As in the dissertation, the nuclei at
the two ends are placed uniformly (spacing <= d_m along x = 0 and x = 1, where the clamp and
the load act) and the rest are random (saturated Poisson-disk sampling). The clamp fixes the
cells whose nuclei lie on x = 0; the load is shared by the cells on x = 1; the deflection is
that of the probe at (1, 0.05).

Assertions (against Table 3-2; the dissertation gives one value per seed):
  * per d_m, the mean number of cells lies within 15 % of the dissertation's mean, and within
    5 % for d_m <= 0.02 m (the coarse meshes depend most on how the end points are laid out,
    which the dissertation does not state exactly);
  * per d_m, the mean deflection lies within 10 % of the dissertation's mean, and within 2 %
    for the fine meshes d_m <= 0.01 m, where the scatter between seeds is small;
  * the mesh dependency of lattice models: the finest meshes (0.005 m) are softer than the
    coarsest (0.05 m) by more than 10 %, as in the table (0.0117 against 0.0094).

Usage: cantilever_mesh_study.py HYSTERON WORKDIR [--markdown FILE] [--plot FILE.png]
"""
import csv
import math
import os
import statistics
import subprocess
import sys
import time

# Table 3-2: d_m -> [(deflection, cells)] for the three cases.
TABLE = {
    0.050: [(0.009212, 40), (0.009529, 43), (0.009448, 42)],
    0.040: [(0.009528, 63), (0.009501, 63), (0.009542, 61)],
    0.030: [(0.010029, 97), (0.009999, 92), (0.010677, 96)],
    0.025: [(0.010559, 130), (0.010511, 128), (0.010421, 129)],
    0.020: [(0.010299, 193), (0.010569, 194), (0.010701, 189)],
    0.015: [(0.010684, 326), (0.010829, 335), (0.010738, 331)],
    0.010: [(0.011433, 705), (0.011407, 725), (0.011623, 715)],
    0.005: [(0.011728, 2765), (0.011683, 2760), (0.011651, 2770)],
}

SCENE = """set Dimension = 2
set Method = rbsn
set Body names = beam
set Boundary names = clamp
set Load names = tip
set Random seed = {seed}
subsection Material
  set Model = linear elastic
  set Young's modulus = 400000
  set Poisson's ratio = 0.3
  set Stress state = plane stress
end
subsection Body beam
  set Shape = rectangle(0, 0, 1, 0.1)
  set Thickness = 1
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Load tip
  set Type = force
  set Region = rectangle(0.999, -1, 1.001, 1)
  set Value = 0; -1
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {d_m}
  set Points on the boundary = false
  set Additional points = {points}
  set Number of increments = 1
end
subsection Output
  set Directory = output
  set Write VTU = {vtu}
  set Probe points = 1, 0.05
end
"""


def end_points(d_m):
    n = max(1, math.ceil(0.1 / d_m - 1e-9))
    return "; ".join(f"{x}, {j * 0.1 / n:.12g}" for x in (0, 1) for j in range(n + 1))


def run_case(hysteron, workdir, d_m, seed, vtu=False):
    directory = os.path.join(workdir, f"dm{d_m:g}_seed{seed}")
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(seed=seed, d_m=d_m, points=end_points(d_m), vtu="true" if vtu else "false"))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.perf_counter()
    p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=env, check=True,
                       capture_output=True, text=True)
    seconds = time.perf_counter() - start
    cells = int(p.stdout.split("rbsn: ")[1].split(" cells")[0])
    facets = int(p.stdout.split(" cells, ")[1].split(" facets")[0])
    with open(os.path.join(directory, "output", "probe_0.csv")) as f:
        deflection = -float(list(csv.DictReader(f))[-1]["u_y"])
    return deflection, cells, facets, seconds


def main():
    hysteron, workdir = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    markdown = sys.argv[sys.argv.index("--markdown") + 1] if "--markdown" in sys.argv else None
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    results = {(d_m, seed): run_case(hysteron, workdir, d_m, seed) for d_m in TABLE for seed in (1, 2, 3)}

    failures = []
    lines = ["| d_m [m] | seed | deflection [m] | cells | facets | run time [s] | dissertation: deflection, cells |",
             "|---|---|---|---|---|---|---|"]
    for d_m, cases in TABLE.items():
        for seed, (reference, ref_cells) in zip((1, 2, 3), cases):
            deflection, cells, facets, seconds = results[(d_m, seed)]
            lines.append(f"| {d_m:g} | {seed} | {deflection:.6f} | {cells} | {facets} | {seconds:.2f} | "
                         f"{reference:.6f}, {ref_cells} |")
        ours = statistics.mean(results[(d_m, s)][0] for s in (1, 2, 3))
        theirs = statistics.mean(c[0] for c in cases)
        our_cells = statistics.mean(results[(d_m, s)][1] for s in (1, 2, 3))
        their_cells = statistics.mean(c[1] for c in cases)
        print(f"d_m = {d_m:g}: deflection {ours:.6f} (dissertation {theirs:.6f}, {100 * (ours / theirs - 1):+.1f} %), "
              f"cells {our_cells:.0f} ({their_cells:.0f}, {100 * (our_cells / their_cells - 1):+.1f} %)")
        if abs(our_cells / their_cells - 1) > (0.05 if d_m <= 0.02 else 0.15):
            failures.append(f"d_m = {d_m:g}: {our_cells:.0f} cells against {their_cells:.0f}")
        if abs(ours / theirs - 1) > (0.02 if d_m <= 0.01 else 0.10):
            failures.append(f"d_m = {d_m:g}: deflection {ours:.6f} against {theirs:.6f}")
    coarse = statistics.mean(results[(0.05, s)][0] for s in (1, 2, 3))
    fine = statistics.mean(results[(0.005, s)][0] for s in (1, 2, 3))
    if not fine > 1.10 * coarse:
        failures.append(f"no mesh dependency: {fine:.6f} (0.005 m) against {coarse:.6f} (0.05 m)")
    table = "\n".join(lines)
    print(table)

    if markdown:
        with open(markdown, "w") as f:
            f.write(table + "\n")
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        d = sorted(TABLE)
        for seed, marker in ((1, "o"), (2, "s"), (3, "^")):
            ax.semilogx(d, [results[(x, seed)][0] for x in d], marker, color="C0",
                        label="hysteron" if seed == 1 else None)
            ax.semilogx(d, [TABLE[x][seed - 1][0] for x in d], marker, color="C1", mfc="none",
                        label="dissertation, Table 3-2" if seed == 1 else None)
        ax.axhline(0.01, color="k", ls=":", label="beam theory PL^3/(3EI)")
        ax.set_xlabel("minimum distance d_m [m]")
        ax.set_ylabel("tip deflection [m]")
        ax.set_title("RBSN elastic cantilever, three random meshes per d_m")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(plot, dpi=110)
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("RBSN cantilever mesh study: all assertions hold")


if __name__ == "__main__":
    main()
