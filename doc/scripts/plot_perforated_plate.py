#!/usr/bin/python3
"""Load-displacement curves of the perforated plate (prm/fem_perforated_plate.prm) and,
optionally, the von Mises field at the end of a run.

    /usr/bin/python3 doc/scripts/plot_perforated_plate.py --out curve.png \
        [--field-out field.png] [--labels 'first|second'] RUN_DIR [RUN_DIR ...]

Each RUN_DIR is the Output/Directory of a run of the scene (or of a variant with another
`FEM/Degree` or `FEM/Mesh/Cell size`, or a force-controlled variant): the load is the
reaction `top_y` of reactions.csv (the force of the prescribed edge displacement on the
quarter model) or, without a `top` condition (force control), minus the reaction
`bottom_y` of the symmetry roller; the displacement is `u_y` of probe_0.csv (the upper
left node, x = 0 on the loaded edge). The label of a
curve is read from the run's parameters.prm (degree, cell size, increments) unless
`--labels` gives them. The reference lines are the elastic stiffness of the independent
fine-mesh solution (`--stiffness`), the first-yield load sigma_y A_net / Kt_net
(`--first-yield`) and the net-section limit load sigma_y A_net (`--limit`); the defaults
are the values of the shipped scene (doc/verification/fem_perforated_plate.md).

`--field-out` draws the von Mises stress at the quadrature points of the first RUN_DIR
that has a quadrature_points.csv (FEM/Write quadrature point table = true), on the
reference configuration (or the deformed one with `--magnify` times the displacement),
next to the equivalent plastic strain eps_ps; the dots are the quadrature points.
"""
import argparse
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def run_label(directory):
    path = os.path.join(directory, "parameters.prm")
    if not os.path.exists(path):
        return os.path.basename(os.path.normpath(directory))
    text = open(path).read()

    def entry(name):
        m = re.search(r"^\s*set\s+" + re.escape(name) + r"\s*=\s*(\S+)", text, re.M)
        return m.group(1) if m else "?"

    return "Q{} h = {} m, {} increments".format(entry("Degree"), entry("Cell size"),
                                                 entry("Number of increments"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="output directories of runs of the scene")
    ap.add_argument("--out", default="fem_perforated_plate.png", help="load-displacement PNG")
    ap.add_argument("--field-out", default=None, help="von Mises field PNG (optional)")
    ap.add_argument("--labels", default=None,
                    help="the curves' labels, one per run directory, separated by '|'")
    ap.add_argument("--stiffness", type=float, default=6.907882e8,
                    help="reference elastic stiffness [N/m] (default: the independent Q9 solution)")
    ap.add_argument("--limit", type=float, default=262e6 * 0.125 * 0.025,
                    help="net-section limit load sigma_y A_net [N]")
    ap.add_argument("--first-yield", type=float, default=262e6 * 0.125 * 0.025 / 2.176,
                    help="first-yield load sigma_y A_net / Kt_net [N]")
    ap.add_argument("--hole-radius", type=float, default=0.125,
                    help="hole radius [m], to mask the hole in the field plot")
    ap.add_argument("--magnify", type=float, default=0.0,
                    help="displacement magnification of the field plot")
    args = ap.parse_args()
    labels = args.labels.split("|") if args.labels else None
    if labels and len(labels) != len(args.runs):
        sys.exit("--labels needs one label per run directory")

    fig, ax = plt.subplots(figsize=(8.0, 5.6))
    inset = ax.inset_axes([0.56, 0.08, 0.41, 0.34])
    d_max = 0.0
    for i, run in enumerate(args.runs):
        reactions = read_csv(os.path.join(run, "reactions.csv"))
        probe = read_csv(os.path.join(run, "probe_0.csv"))
        n = min(len(reactions["time"]), len(probe["time"]))
        d = [1e3 * u for u in probe["u_y"][:n]]
        if "top_y" in reactions:
            F = [1e-3 * f for f in reactions["top_y"][:n]]
        else:
            F = [-1e-3 * f for f in reactions["bottom_y"][:n]]
        d_max = max(d_max, max(d))
        label = labels[i].strip() if labels else run_label(run)
        style = "--" if "top_y" not in reactions else "-"
        line, = ax.plot(d, F, style, linewidth=1.2, label=label)
        inset.plot(d, F, style, linewidth=1.2, color=line.get_color())
    dd = [0.0, d_max]
    inset.set_xlim(1.0, 2.2)
    inset.set_ylim(640, 850)
    inset.axhline(args.limit * 1e-3, color="k", linestyle="--", linewidth=0.8)
    inset.tick_params(labelsize=7)
    inset.grid(True, alpha=0.3)
    inset.set_title("knee (zoom)", fontsize=7)
    ax.plot([0, args.limit / args.stiffness * 1e3 * 1.15], [0, args.limit * 1.15e-3], "k:",
            linewidth=1, label="elastic, K = {:.4g} MN/m (independent Q9 FE)".format(
                args.stiffness * 1e-6))
    ax.axhline(args.limit * 1e-3, color="k", linestyle="--", linewidth=1,
               label=r"limit load $\sigma_y A_{net}$ = %.1f kN" % (args.limit * 1e-3))
    ax.axhline(args.first_yield * 1e-3, color="grey", linestyle="-.", linewidth=1,
               label=r"first yield $\sigma_y A_{net}/K_{t,net}$ = %.1f kN" % (
                   args.first_yield * 1e-3))
    ax.set_xlim(dd)
    ax.set_ylim(0, args.limit * 1.12e-3)
    ax.set_xlabel("vertical displacement of the upper left node [mm]")
    ax.set_ylabel("reaction of the loaded edge (quarter model) [kN]")
    ax.set_title("Perforated aluminium plate, FEM (plane stress, Bouc-Wen n = 8)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper right", bbox_to_anchor=(0.995, 0.86))
    fig.tight_layout()
    fig.savefig(args.out, dpi=130)
    print("wrote", args.out)

    if args.field_out:
        table = next((os.path.join(r, "quadrature_points.csv") for r in args.runs
                      if os.path.exists(os.path.join(r, "quadrature_points.csv"))), None)
        if table is None:
            sys.exit("--field-out: no run directory has a quadrature_points.csv")
        q = read_csv(table)
        # x_* are current positions: the reference position is x - u.
        X = [x - u for x, u in zip(q["x_x"], q["u_x"])]
        Y = [y - u for y, u in zip(q["x_y"], q["u_y"])]
        xd = [x + args.magnify * u for x, u in zip(X, q["u_x"])]
        yd = [y + args.magnify * u for y, u in zip(Y, q["u_y"])]
        tri = mtri.Triangulation(xd, yd)
        # Mask the triangles over the hole and the long ones across the boundary.
        mask = []
        R = args.hole_radius
        for t in tri.triangles:
            cx = sum(X[k] for k in t) / 3
            cy = sum(Y[k] for k in t) / 3
            mask.append(math.hypot(cx, cy) < R)
        tri.set_mask(mask)
        fig, axes = plt.subplots(1, 2, figsize=(8.0, 6.4))
        vm = [s * 1e-6 for s in q["von_mises"]]
        c = axes[0].tricontourf(tri, vm, levels=20, cmap="viridis")
        fig.colorbar(c, ax=axes[0], label="von Mises stress [MPa]", shrink=0.8)
        axes[0].set_title("von Mises stress, end of the run" + (
            "\n(displacements x %g)" % args.magnify if args.magnify else ""), fontsize=9)
        if "eps_ps" in q:
            ep = [100 * e for e in q["eps_ps"]]
            c = axes[1].tricontourf(tri, ep, levels=20, cmap="magma")
            fig.colorbar(c, ax=axes[1], label="equivalent plastic strain eps_ps [%]",
                         shrink=0.8)
            axes[1].set_title("equivalent plastic strain", fontsize=9)
        for a in axes:
            a.plot(xd, yd, ",", color="w", alpha=0.5)
            a.set_aspect("equal")
            a.set_xlabel("x [m]")
        axes[0].set_ylabel("y [m]")
        fig.tight_layout()
        fig.savefig(args.field_out, dpi=130)
        print("wrote", args.field_out)


if __name__ == "__main__":
    main()
