#!/usr/bin/env python3
"""Velocity-gradient study of the dissertation, §4.6.1 (Tables 4-1 and 4-2).

A 5 m x 0.5 m strip (E = 1e4 Pa, nu = 0, rho = 1000 kg/m^3) with the initial velocity
v_x = 0.01 cos(pi/5 (x - 0.5)) (eq. 4.49) is mapped to the grid (P2G, nodal velocity
p_i / m_i) and the velocity gradient L_p = sum_i v_i dN_i/dx at the points is compared with
the analytic L = -0.01 pi/5 sin(pi/5 (x - 0.5)) (eq. 4.50). One MUSL step of 1e-6 s gives
L_p = eps_xx / dt to round-off.

Norms (stated, since the dissertation does not): RMS of L_p - L over the points,
  * "interior": points with 1 <= x <= 4 (away from the strip's ends, where the mass-weighted
    nodal velocity of a truncated support is only first-order accurate);
  * "all": every point.
Assertions: with cubic B-splines and 1 point per cell the interior error falls by 3.5-4.5x per
halving of h (Table 4-1: 4.6x and 4.1x); with linear shape functions more points per cell do
not help (Table 4-2's trend: in the interior, 4x4 points per cell are less accurate than 1,
which sits at the cell centre where the piecewise-constant gradient is superconvergent).

Usage: velocity_gradient.py HYSTERON WORKDIR [--markdown FILE] [--plot FILE.png]
"""
import csv
import math
import os
import subprocess
import sys
import time

SCENE = """set Dimension = 2
set Method = mpm
set Body names = strip
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e4
  set Poisson's ratio = 0
  set Density = 1000
  set Stress state = plane stress
end
subsection Body strip
  set Shape = rectangle(0, 0, 5, 0.5)
  set Particles per cell = {k}
  set Initial velocity = 0.01*cos(pi/5*(x - 0.5)); 0
end
subsection MPM
  subsection Grid
    set Lower corner = 0, {ylow}
    set Upper corner = 5, {yhigh}
    set Cell size = {h}
  end
  set Basis = {basis}
  set Write particle table = true
end
subsection Time
  set End time = 1e-6
  set Time step = 1e-6
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def run_case(hysteron, workdir, n, k, basis):
    h = 5.0 / n
    directory = os.path.join(workdir, f"{basis.split()[0]}_n{n}_k{k}")
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(k=k, h=h, ylow=-h, yhigh=0.5 + h, basis=basis))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.perf_counter()
    subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=directory, env=env, check=True)
    seconds = time.perf_counter() - start
    interior, everywhere = [], []
    with open(os.path.join(directory, "output", "particles.csv")) as f:
        for row in csv.DictReader(f):
            x = float(row["x_x"])
            error = float(row["eps_xx"]) / 1e-6 + 0.01 * math.pi / 5 * math.sin(math.pi / 5 * (x - 0.5))
            everywhere.append(error * error)
            if 1.0 <= x <= 4.0:
                interior.append(error * error)
    rms = lambda v: math.sqrt(sum(v) / len(v))
    return rms(interior), rms(everywhere), len(everywhere), seconds


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    markdown = sys.argv[sys.argv.index("--markdown") + 1] if "--markdown" in sys.argv else None
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    results = {}
    for basis in ("cubic B-spline", "linear"):
        for n in (10, 20, 40):
            for k in (1, 2, 4):
                results[(basis, n, k)] = run_case(hysteron, workdir, n, k, basis)
    lines = ["| basis | cells along x | points per cell | points | interior RMS error [1/s] | "
             "all-points RMS error [1/s] |", "|---|---|---|---|---|---|"]
    for (basis, n, k), (interior, everywhere, points, _) in results.items():
        lines.append(f"| {basis} | {n} | {k}x{k} | {points} | {interior:.4g} | {everywhere:.4g} |")
    print("\n".join(lines))
    if markdown:
        with open(markdown, "w") as f:
            f.write("\n".join(lines) + "\n")

    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, which, title in ((axes[0], 0, "interior points (1 <= x <= 4)"),
                                 (axes[1], 1, "all points")):
            for basis, style in (("cubic B-spline", "-"), ("linear", "--")):
                for k, marker in ((1, "o"), (2, "s"), (4, "^")):
                    hs = [5.0 / n for n in (10, 20, 40)]
                    errors = [results[(basis, n, k)][which] for n in (10, 20, 40)]
                    ax.loglog(hs, errors, style + marker, label=f"{basis}, {k}x{k} per cell")
            ax.loglog([0.125, 0.5], [1.0e-5, 1.6e-4], "k:", label="slope 2")
            ax.set_xlabel("cell size h [m]")
            ax.set_ylabel("RMS error of L_p [1/s]")
            ax.set_title(title)
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize=7)
        fig.suptitle("MPM velocity gradient, dissertation §4.6.1")
        fig.tight_layout()
        fig.savefig(plot, dpi=110)

    failures = []
    for k in (1, 2):
        for coarse, fine in ((10, 20), (20, 40)):
            ratio = results[("cubic B-spline", coarse, k)][0] / results[("cubic B-spline", fine, k)][0]
            print(f"cubic, {k}x{k} points per cell: interior error ratio {coarse} -> {fine} cells: {ratio:.3f}")
            if not 3.5 <= ratio <= 4.5:
                failures.append(f"cubic {k}x{k}: ratio {ratio:.3f} outside [3.5, 4.5]")
    for n in (10, 20, 40):
        one, four = results[("linear", n, 1)][0], results[("linear", n, 4)][0]
        print(f"linear, {n} cells: interior error 1 point {one:.4g}, 4x4 points {four:.4g}")
        if not four > one:
            failures.append(f"linear, {n} cells: 4x4 points ({four:.4g}) not worse than 1 ({one:.4g})")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("velocity-gradient study: all assertions hold")


if __name__ == "__main__":
    main()
