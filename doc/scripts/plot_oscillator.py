#!/usr/bin/env python3
"""The figures of doc/oscillator.md: runs prm/oscillator_record.prm and prm/spectrum_record.prm
with the given executable (in a temporary directory) and draws

  doc/figures/oscillator_loop.png      the storey's force-drift loop and its drift history
  doc/figures/oscillator_energy.png    the energies of the run (input = kinetic + damped +
                                       elastic + hysteretic)
  doc/figures/spectrum_record.png      elastic Sa and the yield pseudo-accelerations at R = 4
                                       and mu = 4

Usage: plot_oscillator.py HYSTERON [--out doc/figures]. Uses matplotlib's Agg backend.
"""
import argparse
import csv
import os
import shutil
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def run(hysteron, scene, workdir):
    shutil.copy(os.path.join(ROOT, "prm", scene), workdir)
    os.makedirs(os.path.join(workdir, "records"), exist_ok=True)
    shutil.copy(os.path.join(ROOT, "prm", "records", "synthetic_kanai_tajimi.AT2"), os.path.join(workdir, "records"))
    subprocess.run([os.path.abspath(hysteron), "--quiet", scene], cwd=workdir, check=True)
    return os.path.join(workdir, "output", scene[:-4])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("hysteron")
    ap.add_argument("--out", default=os.path.join(ROOT, "doc", "figures"))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as work:
        out = run(a.hysteron, "oscillator_record.prm", work)
        h, e = columns(os.path.join(out, "history.csv")), columns(os.path.join(out, "energy.csv"))
        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
        left.plot([1e3 * u for u in h["u_1"]], [1e-3 * F for F in h["F_1"]], lw=0.8)
        left.set_xlabel("drift [mm]")
        left.set_ylabel("storey force [kN]")
        left.set_title("Bouc-Wen storey, F_y = 110 kN")
        left.grid(alpha=0.3)
        right.plot(h["t"], [1e3 * u for u in h["u_1"]], lw=0.8)
        right.set_xlabel("time [s]")
        right.set_ylabel("drift [mm]")
        right.set_title("synthetic record, PGA 0.3 g")
        right.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "oscillator_loop.png"), dpi=110)
        plt.close(fig)

        fig, ax = plt.subplots(figsize=(7, 4))
        for key, label in (("input", "input"), ("hysteretic", "hysteretic"), ("damped", "damped"),
                           ("kinetic", "kinetic"), ("elastic", "elastic")):
            ax.plot(e["t"], [1e-3 * x for x in e[key]], label=label, lw=1)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("energy [kJ]")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "oscillator_energy.png"), dpi=110)
        plt.close(fig)

        out = run(a.hysteron, "spectrum_record.prm", work)
        s = columns(os.path.join(out, "spectrum.csv"))
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(s["T"], s["Sa"], lw=1.5, label="elastic Sa")
        ax.plot(s["T"], s["Ay_R"], lw=1.5, label="yield A_y at R = 4")
        ax.plot(s["T"], s["Ay_mu"], lw=1.5, label="yield A_y at ductility 4")
        ax.set_xlabel("period T [s]")
        ax.set_ylabel("pseudo-acceleration [m/s$^2$]")
        ax.set_title("5 % damping, Bouc-Wen n = 2, a = 0.05")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "spectrum_record.png"), dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main()
