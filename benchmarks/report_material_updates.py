#!/usr/bin/env python3
"""Error versus cost of the Bouc-Wen integrators (from material_updates' CSV) as a PNG."""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

NAMES = {1: "forward Euler", 2: "adaptive (tol 1e-6)", 3: "backward Euler"}
MARKERS = {2: "o", 8: "s", 32: "^"}


def main(csv_file, png_file):
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(csv_file))]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), dpi=100, sharey=True)
    states = [("plane stress", 2, 1), ("plane strain", 2, 0), ("3D", 3, 0)]
    for ax, (title, dim, ps) in zip(axes, states):
        for integrator, name in NAMES.items():
            for n, marker in MARKERS.items():
                sel = [r for r in rows if r["dim"] == dim and r["plane_stress"] == ps
                       and r["integrator"] == integrator and r["n"] == n]
                for r in sel:
                    ax.loglog(1e9 / r["updates_per_second"], max(r["error"], 1e-12),
                              marker=marker, color=f"C{integrator - 1}", ls="none",
                              label=f"{name}, n = {n}" if title == "plane stress" else None)
        floor = [r for r in rows if r["dim"] == dim and r["plane_stress"] == ps
                 and r["integrator"] == 0]
        for r in floor:
            ax.axvline(1e9 / r["updates_per_second"], color="gray", ls=":", lw=1)
        ax.set_title(f"{title} (dotted: Hooke's law)")
        ax.set_xlabel("cost [ns per update]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel(r"max $|\sigma - \sigma_{ref}| / \sigma_y$")
    axes[0].legend(fontsize=7, ncol=1)
    fig.tight_layout()
    fig.savefig(png_file)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
