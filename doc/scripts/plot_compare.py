#!/usr/bin/env python3
"""Compact figures of a hysteron comparison table (`<dir>/compare/<table>.csv`, the side-by-side
columns <col>_MPM, <col>_FEM, <col>_diff written by `set Method = compare`; doc/compare.md).

  plot_compare.py --out doc/verification/figures/x.png --title "..." \
      PANEL [PANEL ...]

A PANEL is TABLE:COLUMN[:SCALE[:LABEL]] (a time history: MPM and FEM on the left axis, FEM - MPM
in grey on the right) or TABLE:XCOLUMN,YCOLUMN[:XSCALE,YSCALE[:XLABEL,YLABEL]] (a loop: y against
x for both methods). Labels may use matplotlib mathtext. Uses matplotlib's Agg backend.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_columns(path):
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        columns = {h: [] for h in header}
        for row in reader:
            for h, v in zip(header, row):
                columns[h].append(float(v))
    return columns


def split_panel(text):
    # TABLE may contain ':' only as the separator; TABLE is a path ending in .csv.
    table, rest = text.split(".csv:", 1)
    parts = rest.split(":")
    return table + ".csv", parts


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("panels", nargs="+")
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="")
    ap.add_argument("--a", default="MPM", help="label of run A (column suffix)")
    ap.add_argument("--b", default="FEM", help="label of run B (column suffix)")
    ap.add_argument("--width", type=float, default=4.2, help="inches per panel")
    ap.add_argument("--height", type=float, default=3.0)
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    n = len(args.panels)
    fig, axes = plt.subplots(1, n, figsize=(args.width * n, args.height), squeeze=False)
    for ax, panel in zip(axes[0], args.panels):
        table, parts = split_panel(panel)
        data = read_columns(table)
        columns = parts[0].split(",")
        scales = [float(s) for s in parts[1].split(",")] if len(parts) > 1 and parts[1] else [1.0] * len(columns)
        labels = parts[2].split(",") if len(parts) > 2 else columns
        if len(columns) == 1:
            c, s = columns[0], scales[0]
            t = data["time"]
            ax.plot(t, [v * s for v in data[f"{c}_{args.a}"]], color="tab:blue", lw=1.4, label=args.a)
            ax.plot(t, [v * s for v in data[f"{c}_{args.b}"]], color="tab:red", lw=1.2, ls="--", label=args.b)
            ax.set_xlabel("time [s]")
            ax.set_ylabel(labels[0])
            ax.grid(alpha=0.3)
            right = ax.twinx()
            right.plot(t, [v * s for v in data[f"{c}_diff"]], color="0.55", lw=0.8, label=f"{args.b} - {args.a}")
            right.set_ylabel(f"{args.b} - {args.a}", color="0.4")
            right.tick_params(axis="y", colors="0.4")
            lines = ax.get_lines() + right.get_lines()
            ax.legend(lines, [l.get_label() for l in lines], fontsize=7, loc="upper left", framealpha=0.6)
        else:
            (cx, cy), (sx, sy) = columns, (scales + [1.0, 1.0])[:2]
            for label, style in ((args.a, dict(color="tab:blue", lw=1.4)),
                                 (args.b, dict(color="tab:red", lw=1.2, ls="--"))):
                ax.plot([v * sx for v in data[f"{cx}_{label}"]], [v * sy for v in data[f"{cy}_{label}"]],
                        label=label, **style)
            ax.set_xlabel(labels[0])
            ax.set_ylabel(labels[1] if len(labels) > 1 else cy)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8, loc="best")
    if args.title:
        fig.suptitle(args.title, fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out, dpi=args.dpi)


if __name__ == "__main__":
    main()
