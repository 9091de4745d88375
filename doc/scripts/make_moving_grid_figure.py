#!/usr/bin/env python3
"""The §5.4 fine patch on a fixed and on a moving grid (doc/mpm.md, "Moving grid").

Runs prm/compare_patch_moving_grid.prm (36 cells x 16 points, linear basis, the updated-Lagrangian
FEM beside it) as it is and with the grid fixed, and writes doc/mpm/moving_grid_patch.png: the
von Mises stress at A = (0.175, 0.175) against time for the FEM and the two MPM runs, and the
grid's cell sizes h_x, h_y of the moving run against the patch's mean strain. About 10 s.
Usage: doc/scripts/make_moving_grid_figure.py [path/to/hysteron]
"""
import csv
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "prm", "compare_patch_moving_grid.prm")


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def run(exe, work, text):
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, "scene.prm"), "w") as f:
        f.write(text)
    p = subprocess.run([exe, "--quiet", "scene.prm"], cwd=work, capture_output=True, text=True,
                       env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    if p.returncode != 0:
        sys.exit(f"{work}: exit {p.returncode}: {p.stderr[-1000:]}")


def main():
    exe = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    text = open(SCENE).read()
    fixed = re.sub(r"\n    subsection Motion\n.*?\n    end", "", text, flags=re.S).replace(
        "set Method = compare", "set Method = mpm")
    with tempfile.TemporaryDirectory() as work:
        run(exe, os.path.join(work, "moving"), text)
        run(exe, os.path.join(work, "fixed"), fixed)
        fem = columns(os.path.join(work, "moving", "output", "fem", "probe_0.csv"))
        moving = columns(os.path.join(work, "moving", "output", "mpm", "probe_0.csv"))
        still = columns(os.path.join(work, "fixed", "output", "probe_0.csv"))
        grid = columns(os.path.join(work, "moving", "output", "mpm", "grid.csv"))

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    a.plot(fem["time"], fem["von_mises"], "k-", lw=2.2, label="FEM, updated Lagrangian, Q2")
    a.plot(moving["time"], moving["von_mises"], "C0--", lw=1.6, label="MPM, moving grid (follow)")
    a.plot(still["time"], still["von_mises"], "C3-", lw=1.2, label="MPM, fixed grid")
    a.set_xlabel("t [s]")
    a.set_ylabel("von Mises stress at A [Pa]")
    a.set_title("§5.4 patch, 36 cells x 16 points, linear basis")
    a.legend(loc="lower right")
    a.grid(alpha=0.3)
    strain = [0.001 * t / 0.3 for t in grid["time"]]
    b.plot(grid["time"], [h / 0.05 - 1 for h in grid["h_x"]], "C0-", label="h_x / h_0 - 1")
    b.plot(grid["time"], [h / 0.05 - 1 for h in grid["h_y"]], "C2-", label="h_y / h_0 - 1")
    b.plot(grid["time"], strain, "k:", label="mean strain 0.001 t / 0.3")
    b.set_xlabel("t [s]")
    b.set_ylabel("stretch of the grid's cells [-]")
    b.set_title("the grid follows the patch (grid.csv)")
    b.legend(loc="upper left")
    b.grid(alpha=0.3)
    fig.tight_layout()
    out = os.path.join(ROOT, "doc", "mpm", "moving_grid_patch.png")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}; von Mises at A at the end: FEM {fem['von_mises'][-1]:.3f} Pa, "
          f"moving grid {moving['von_mises'][-1]:.3f} Pa, fixed grid {still['von_mises'][-1]:.3f} Pa")


if __name__ == "__main__":
    main()
