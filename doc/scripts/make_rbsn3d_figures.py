#!/usr/bin/python3
"""Regenerate the figures of doc/rbsn3d.md's Examples in doc/rbsn/ from the shipped 3D scenes.

  doc/scripts/make_rbsn3d_figures.py [build/hysteron] [--only cantilever|bending]

Runs, in a temporary directory (about 3 minutes on one core):

* prm/compare_rbsn_fem_cantilever_3d.prm (`--compare`: RBSN and FEM), and the RBSN of the same
  scene with seeds 2 and 3; draws the tip load against the tip deflection with P_y, P_u and the
  plane-strain hinge 2/sqrt(3) P_u into doc/rbsn/cantilever_plastic_3d.png, and prints the
  numbers of doc/rbsn3d.md (first yield, plateau, compare/summary.md's reaction rows).
* prm/rbsn_three_point_bending_3d.prm (d_m = 0.02 m) and the same with d_m = 0.0125 m (five
  nuclei per line), with `Write spring table`; draws the load against the load line's
  displacement and the broken facets (each as the rectangle of its area and second moments,
  w v^3 / 12 = I_1, v w^3 / 12 = I_2, in its axes) seen from the side, from below and in 3D
  into doc/rbsn/three_point_bending_3d.png, and prints the numbers.

Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import math
import os
import re
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "doc", "rbsn")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

P_Y, P_U = 40e3, 60e3             # the cantilever: sigma_y b h^2 / (6 L), / (4 L)
P_CR = 2 * 3e6 * 0.05 * 0.1**2 / (3 * 0.5)   # the beam: 2 f_t b h^2 / (3 L) = 2000 N


def set_entry(text, name, value):
    """Replace `set name = ...` (first occurrence), or add it to `subsection RBSN`."""
    new, n = re.subn(rf"(?m)^(\s*set {re.escape(name)}\s*=).*$", rf"\g<1> {value}", text, count=1)
    if n == 1:
        return new
    new, n = re.subn(r"(?m)^subsection RBSN\n", f"subsection RBSN\n  set {name} = {value}\n", text, count=1)
    if n != 1:
        raise RuntimeError(f"no entry '{name}'")
    return new


def run(hysteron, work, name, scene, **entries):
    """Run prm/<scene>.prm with entries replaced in WORK/NAME; return the output directory."""
    with open(os.path.join(ROOT, "prm", scene + ".prm")) as f:
        text = f.read()
    for key, value in entries.items():
        text = set_entry(text, key.replace("_", " "), value)
    directory = os.path.join(work, name)
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=ENV, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{name}: exit {p.returncode}\n{p.stderr}")
    cells = re.findall(r"\((\d+) cells", p.stdout)
    print(f"{name}: {cells[0] + ' cells' if cells else 'done'}", flush=True)
    return os.path.join(directory, "output"), int(cells[0]) if cells else 0


def table(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def first_yield(t, P, last=None):
    """The load where the tangent first falls below 95 % of the elastic one (the ctest's rule)."""
    k0 = P[1] / t[1]
    for i in range(2, last or len(t)):
        if (P[i] - P[i - 1]) / (t[i] - t[i - 1]) < 0.95 * k0:
            return P[i]
    return math.nan


def cantilever(hysteron, work):
    out, _ = run(hysteron, work, "cantilever", "compare_rbsn_fem_cantilever_3d")
    r = table(os.path.join(out, "compare", "reactions.csv"))
    p = table(os.path.join(out, "compare", "probe_0.csv"))
    t = r["time"]
    fig, ax = plt.subplots(figsize=(7, 4.6))
    curves = {}
    for label, style in (("RBSN", "C0-"), ("FEM", "C3--")):
        P = [-v for v in r[f"tip_y_{label}"]]
        d = [-1e3 * v for v in p[f"u_y_{label}"]]
        curves[label] = (d, P)
        name = "RBSN, d_m = 0.025 m, seed 1 (698 cells)" if label == "RBSN" else "FEM, Q2, h = 0.05 m (3075 DoFs)"
        ax.plot(d, [v / 1e3 for v in P], style, lw=1.8, label=name)
        print(f"{label}: first yield {first_yield(t, P, 31) / 1e3:.1f} kN = {first_yield(t, P, 31) / P_Y:.3f} P_y; "
              f"load at 50 mm {P[-1] / 1e3:.2f} kN = {P[-1] / P_U:.3f} P_u; elastic stiffness "
              f"{P[1] / d[1]:.4g} kN/m")
    print(f"RBSN / FEM at 50 mm: {curves['RBSN'][1][-1] / curves['FEM'][1][-1]:.4f}")
    for seed in (2, 3):
        o, n = run(hysteron, work, f"cantilever_seed{seed}", "compare_rbsn_fem_cantilever_3d",
                   Method="rbsn", Random_seed=seed)
        rs, ps = table(os.path.join(o, "reactions.csv")), table(os.path.join(o, "probe_0.csv"))
        P = [-v for v in rs["tip_y"]]
        ax.plot([-1e3 * v for v in ps["u_y"]], [v / 1e3 for v in P], "C0:" if seed == 2 else "C0-.", lw=1,
                label=f"RBSN, seed {seed} ({n} cells)")
        print(f"RBSN seed {seed}: {n} cells, load at 50 mm {P[-1] / 1e3:.2f} kN = {P[-1] / P_U:.3f} P_u, "
              f"first yield {first_yield(rs['time'], P, 31) / P_Y:.3f} P_y")
    for value, text in ((P_Y, "$P_y$"), (P_U, "$P_u$"), (2 / math.sqrt(3) * P_U, r"$2/\sqrt{3}\,P_u$")):
        ax.axhline(value / 1e3, color="gray", ls=":", lw=1)
        ax.text(51, value / 1e3, text, va="center", fontsize=9)
    ax.set_xlim(0, 50)
    ax.set_ylim(0, 75)
    ax.set_xlabel("tip deflection [mm]")
    ax.set_ylabel("tip load [kN]")
    ax.set_title("3D cantilever 1 m x 0.1 m x 0.1 m to collapse: RBSN (coupled springs) and FEM", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    path = os.path.join(OUT, "cantilever_plastic_3d.png")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")
    with open(os.path.join(out, "compare", "summary.md")) as f:
        print("".join(line for line in f if line.startswith("| reactions.csv | tip_y")
                      or line.startswith("| energy.csv | dissipated") or line.startswith("| table")))


def facet_rectangle(row):
    """The broken facet as the rectangle w x v of its area and second moments, in its axes."""
    c = [row["x"], row["y"], row["z"]]
    s1 = [row["s1_x"], row["s1_y"], row["s1_z"]]
    s2 = [row["s2_x"], row["s2_y"], row["s2_z"]]
    A = row["area"]
    v = math.sqrt(12 * row["I_1"] / A)      # along s2 (I_1 = w v^3 / 12 about s1)
    w = math.sqrt(12 * row["I_2"] / A)      # along s1
    return [[c[k] + a * w / 2 * s1[k] + b * v / 2 * s2[k] for k in range(3)]
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]


def bending(hysteron, work):
    runs = []
    fine_points = "; ".join(f"{x}, {y}, {z:g}" for x, y in ((0.05, 0), (0.55, 0), (0.3, 0.1))
                            for z in (0, 0.0125, 0.025, 0.0375, 0.05))
    for name, entries in (("coarse", {}),
                          ("fine", {"Minimum_distance": 0.0125, "Additional_points": fine_points})):
        out, n = run(hysteron, work, f"bending_{name}", "rbsn_three_point_bending_3d",
                     Write_spring_table="true", **entries)
        r = table(os.path.join(out, "reactions.csv"))
        f = table(os.path.join(out, "fracture.csv"))
        with open(os.path.join(out, "springs.csv")) as fh:
            springs = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(fh)]
        d_m = entries.get("Minimum_distance", 0.02)
        P = [-v for v in r["load_y"]]
        k0 = P[1] / r["time"][1]
        first = max(P[i] for i in range(1, len(P)) if abs(P[i] - k0 * r["time"][i]) < 1e-6 * k0 * r["time"][i])
        near = sum(1 for x in f["x"] if abs(x - 0.3) <= 2 * d_m)
        print(f"bending, d_m = {d_m}: {n} cells; first crack {first:.0f} N = {first / P_CR:.3f} P_cr at "
              f"({f['x'][0]:.4f}, {f['y'][0]:.4f}, {f['z'][0]:.4f}); peak {max(P):.0f} N = {max(P) / P_CR:.3f} P_cr; "
              f"at 0.2 mm {P[-1]:.0f} N = {P[-1] / max(P):.3f} of the peak; {len(f['x'])} broken facets, "
              f"{near} ({near / len(f['x']):.0%}) within 2 d_m of midspan")
        runs.append(dict(name=name, d_m=d_m, cells=n, t=r["time"], P=P, springs=springs))

    fig = plt.figure(figsize=(12, 9.5))
    grid = fig.add_gridspec(3, 2, height_ratios=(3.2, 1.6, 1.1))
    ax = fig.add_subplot(grid[0, 0])
    for k, run_ in enumerate(runs):
        ax.plot([2e-4 * 1e3 * t for t in run_["t"]], run_["P"], f"C{k}-", lw=1.5,
                label=f"d_m = {run_['d_m']} m ({run_['cells']} cells)")
    ax.axhline(P_CR, color="gray", ls=":", lw=1)
    ax.text(0.2, P_CR, r"$P_{cr} = 2 f_t b h^2 / (3 L)$", va="bottom", ha="right", fontsize=9)
    ax.set_xlabel("displacement of the load line [mm]")
    ax.set_ylabel("load [N]")
    ax.set_title("load against displacement (seed 1)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)

    fine = runs[-1]
    broken = [s for s in fine["springs"] if s["broken"] > 0.5]
    polygons = [facet_rectangle(s) for s in broken]
    ax = fig.add_subplot(grid[0, 1], projection="3d")
    ax.add_collection3d(Poly3DCollection(polygons, facecolor="C3", edgecolor="k", linewidths=0.2, alpha=0.6))
    for y in (0, 0.1):
        for z in (0, 0.05):
            ax.plot([0.2, 0.4], [y, y], [z, z], "k-", lw=0.6)
    for x in (0.2, 0.4):
        ax.plot([x, x, x, x, x], [0, 0.1, 0.1, 0, 0], [0, 0, 0.05, 0.05, 0], "k-", lw=0.6)
    ax.set_xlim(0.2, 0.4)
    ax.set_ylim(0, 0.1)
    ax.set_zlim(0, 0.05)
    ax.set_box_aspect((0.2, 0.1, 0.05))
    ax.view_init(elev=20, azim=-60)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(f"the crack, d_m = {fine['d_m']} m: {len(broken)} broken facets (x from 0.2 to 0.4 m)",
                 fontsize=10)
    for row, (i, j, height, ylabel, title) in zip(
            (1, 2), ((0, 1, 0.1, "y [m]", "broken facets seen from the side (x-y)"),
                     (0, 2, 0.05, "z [m]", "broken facets seen from below (x-z)"))):
        ax = fig.add_subplot(grid[row, :])
        for poly in polygons:
            ax.fill([p[i] for p in poly], [p[j] for p in poly], color="C3", alpha=0.35, lw=0.3, ec="k")
        ax.plot([0, 0.6, 0.6, 0, 0], [0, 0, height, height, 0], "k-", lw=0.8)
        if j == 1:
            ax.plot([0.05, 0.55], [-0.006, -0.006], "k^", ms=9)
            ax.plot([0.3], [0.106], "kv", ms=9)
        ax.set_aspect("equal")
        ax.set_xlim(-0.01, 0.61)
        ax.set_xlabel("x [m]")
        ax.set_ylabel(ylabel)
        ax.set_title(f"{title}, d_m = {fine['d_m']} m", fontsize=10)
    fig.suptitle("3D three-point bending, 0.6 m x 0.1 m x 0.05 m, f_t = 3 MPa: RBSN with brittle facets",
                 fontsize=11)
    fig.tight_layout()
    path = os.path.join(OUT, "three_point_bending_3d.png")
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("hysteron", nargs="?", default=os.path.join(ROOT, "build", "hysteron"))
    parser.add_argument("--only", choices=("cantilever", "bending"))
    args = parser.parse_args()
    hysteron = os.path.abspath(args.hysteron)
    with tempfile.TemporaryDirectory(prefix="rbsn3d_figures_") as work:
        if args.only in (None, "cantilever"):
            cantilever(hysteron, work)
        if args.only in (None, "bending"):
            bending(hysteron, work)


if __name__ == "__main__":
    main()
