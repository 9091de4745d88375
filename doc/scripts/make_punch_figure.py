#!/usr/bin/env python3
"""Prandtl's punch with Q1, Q1 + B-bar and Q2 (doc/fem.md, "Volumetric locking and B-bar").

Runs the scene of tests/fem/prandtl_punch_bbar.prm with the element and the cell size of each
case, and writes doc/fem/prandtl_punch.png (p / k against the settlement) and, on stdout, the
Markdown table of the plateau values against the slip-line limit 2 + pi. About 4 minutes on one
core. Usage: doc/scripts/make_punch_figure.py [path/to/hysteron]
"""
import csv
import math
import os
import re
import subprocess
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "tests", "fem", "prandtl_punch_bbar.prm")
K = 240e6 / math.sqrt(3.0)  # shear yield stress [Pa]; the punch half-width is 1 m
LIMIT = 2.0 + math.pi

# (label, degree, B-bar, cell size)
CASES = [
    ("Q1, full integration, h = 0.125 m", 1, "false", 0.125),
    ("Q1, full integration, h = 0.0625 m", 1, "false", 0.0625),
    ("Q1 + B-bar, h = 0.125 m", 1, "true", 0.125),
    ("Q1 + B-bar, h = 0.0625 m", 1, "true", 0.0625),
    ("Q2, full integration, h = 0.25 m", 2, "false", 0.25),
    ("Q2, full integration, h = 0.125 m", 2, "false", 0.125),
]


def run(exe, work, degree, bbar, h):
    text = open(SCENE).read()
    text = re.sub(r"set Degree = \d", f"set Degree = {degree}", text)
    text = re.sub(r"set B-bar = \w+", f"set B-bar = {bbar}", text)
    text = re.sub(r"set Cell size = [\d.]+", f"set Cell size = {h}", text)
    with open(os.path.join(work, "punch.prm"), "w") as f:
        f.write(text)
    start = time.time()
    subprocess.run([exe, "--quiet", "punch.prm"], cwd=work, check=True)
    seconds = time.time() - start
    with open(os.path.join(work, "output", "history_punch.csv")) as f:
        rows = list(csv.DictReader(f))
    settlement = [-float(r["u_y"]) for r in rows]
    pressure = [-float(r["reaction_y"]) / K for r in rows]
    return settlement, pressure, seconds


def main():
    exe = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    fig, ax = plt.subplots(figsize=(7.5, 5))
    print("| element | h [m] | p / k at 60 mm | against 2 + pi | last quarter | run time [s] |")
    print("|---|---|---|---|---|---|")
    for label, degree, bbar, h in CASES:
        with tempfile.TemporaryDirectory() as work:
            s, p, seconds = run(exe, work, degree, bbar, h)
        rise = p[-1] / p[(3 * len(p)) // 4] - 1
        style = "-" if bbar == "true" else ("--" if degree == 1 else ":")
        ax.plot([1e3 * x for x in s], p, style, label=label)
        element = "Q1 + B-bar" if bbar == "true" else f"Q{degree}"
        print(f"| {element} | {h} | {p[-1]:.4f} | {100 * (p[-1] / LIMIT - 1):+.1f} % | "
              f"{100 * rise:+.2f} % | {seconds:.1f} |")
    ax.axhline(LIMIT, color="k", linewidth=0.8)
    ax.text(1, LIMIT + 0.05, "slip-line limit (2 + pi) k", fontsize=9)
    ax.set_xlabel("punch settlement [mm] (half-width 1 m)")
    ax.set_ylabel("mean punch pressure p / k")
    ax.set_title("Prandtl's punch, plane strain, perfectly plastic (Bouc-Wen, n = 20)")
    ax.set_ylim(0, 7)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    out = os.path.join(ROOT, "doc", "fem", "prandtl_punch.png")
    fig.tight_layout()
    fig.savefig(out + ".tmp.png", dpi=110)
    os.replace(out + ".tmp.png", out)
    print(f"\nwrote {os.path.relpath(out, ROOT)}")


if __name__ == "__main__":
    main()
