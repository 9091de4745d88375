#!/usr/bin/env python3
"""Plot columns of hysteron CSV outputs (history.csv, probe_<i>.csv, energy.csv, ...) as a PNG.

  plot_history.py --x eps_xx --y sig_xx --xscale 100 --yscale 1e-6 \
      --xlabel "strain [%]" --ylabel "stress [MPa]" --out doc/figures/loop.png \
      output/a/history.csv:"m = 0" output/b/history.csv:"m = 1"

Each input is FILE or FILE:LABEL. Uses matplotlib's Agg backend (no display needed).
"""
import argparse
import csv
import os
import sys

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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="FILE or FILE:LABEL")
    ap.add_argument("--x", required=True)
    ap.add_argument("--y", required=True, help="one column, or several separated by commas")
    ap.add_argument("--xscale", type=float, default=1.0)
    ap.add_argument("--yscale", type=float, default=1.0)
    ap.add_argument("--xlabel")
    ap.add_argument("--ylabel")
    ap.add_argument("--title", default="")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()

    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=110)
    for spec in args.inputs:
        path, _, label = spec.partition(":")
        columns = read_columns(path)
        for y in args.y.split(","):
            if args.x not in columns or y not in columns:
                sys.exit(f"plot_history.py: {path} has no column '{args.x}' or '{y}'")
            name = label or os.path.basename(os.path.dirname(path)) or path
            if len(args.y.split(",")) > 1:
                name = f"{name} {y}" if label else y
            ax.plot([v * args.xscale for v in columns[args.x]],
                    [v * args.yscale for v in columns[y]], lw=1.2, label=name)
    ax.set_xlabel(args.xlabel or args.x)
    ax.set_ylabel(args.ylabel or args.y)
    ax.set_title(args.title)
    ax.grid(True, alpha=0.3)
    if len(args.inputs) > 1 or len(args.y.split(",")) > 1:
        ax.legend()
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    tmp = args.out + ".tmp.png"
    fig.savefig(tmp)
    os.replace(tmp, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
