#!/usr/bin/env python3
"""Figures of doc/verification/frames.md from the side-by-side tables of the frame scenes
(`<run>/output/compare/average_0.csv`, written by `set Method = compare`).

  plot_frames.py --portal ELASTIC_RUN PLASTIC_RUN --corner ELASTIC_RUN PLASTIC_RUN --out DIR

Writes DIR/portal_frame.png (top displacement of the portal frame against time, MPM and FEM,
elastic and elastic-plastic) and DIR/frame_corner.png (load against the closing displacement of
the knee, MPM and FEM, elastic and elastic-plastic). Uses matplotlib's Agg backend.
"""
import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def columns(run, table="average_0.csv"):
    with open(os.path.join(run, "output", "compare", table), newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        data = {h: [] for h in header}
        for row in reader:
            for h, v in zip(header, row):
                data[h].append(float(v))
    return data


def portal(elastic, plastic, out):
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    for ax, run, title in ((axes[0], elastic, "elastic"), (axes[1], plastic, "elastic-plastic (Bouc-Wen, 5 %)")):
        c = columns(run)
        ax.plot(c["time"], [1e3 * u for u in c["u_x_FEM"]], "k-", lw=1.4, label="FEM (Q2, implicit)")
        ax.plot(c["time"], [1e3 * u for u in c["u_x_MPM"]], "r--", lw=1.2, label="MPM (linear basis)")
        ax.set_title(title)
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("top displacement u_x, left joint [mm]")
    axes[0].legend(loc="lower right")
    fig.suptitle("Portal frame W12x120 / W16x36, 444.82 kN step at the top-left joint")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "portal_frame.png"), dpi=110)


def corner(elastic, plastic, out):
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    for ax, (run, p_max, end), title in ((axes[0], elastic, "elastic"),
                                        (axes[1], plastic, "elastic-plastic (A36, Bouc-Wen, 5 %)")):
        c = columns(run)
        load = [p_max * math.sin(math.pi * t / 0.5) ** 2 / 1e3 for t in c["time"]]
        for m, style, label in (("FEM", "k-", "FEM (Q2, implicit)"), ("MPM", "r--", "MPM (linear basis)")):
            closing = [-1e3 * (a + b) / math.sqrt(2) for a, b in zip(c["u_x_" + m], c["u_y_" + m])]
            ax.plot(closing, load, style, lw=1.3, label=label)
        ax.set_title(title)
        ax.set_xlabel("closing displacement of the loaded end [mm]")
        ax.set_ylabel("load P [kN]")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="lower right")
    fig.suptitle("Frame corner W30x108, P along the line through the arms' ends")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "frame_corner.png"), dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--portal", nargs=2, required=True, metavar=("ELASTIC", "PLASTIC"))
    ap.add_argument("--corner", nargs=2, required=True, metavar=("ELASTIC", "PLASTIC"))
    ap.add_argument("--corner-loads", nargs=2, type=float, default=(750e3, 750e3),
                    help="P_max of the elastic and the plastic corner runs [N]")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    portal(*args.portal, args.out)
    corner((args.corner[0], args.corner_loads[0], 0.5), (args.corner[1], args.corner_loads[1], 0.5), args.out)


if __name__ == "__main__":
    main()
