#!/usr/bin/env python3
"""Base excitation of the FEM (doc/oscillator.md): doc/figures/fem_base_excitation.png.

Runs prm/fem_base_excitation.prm (a Bouc-Wen steel pier with a deck mass under the synthetic
record scaled to 0.6 g, about 10 s) and draws the ground's acceleration and the deck's drift
against time, the base shear (ground.csv: the support's reactions) against the drift, and the
energies (relative input = kinetic + strain + hysteresis + damping).
Usage: doc/scripts/plot_base_excitation.py [path/to/hysteron] [output.png]
"""
import csv
import os
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    exe = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "doc", "figures", "fem_base_excitation.png")
    with tempfile.TemporaryDirectory() as work:
        shutil.copy(os.path.join(ROOT, "prm", "fem_base_excitation.prm"), work)
        os.makedirs(os.path.join(work, "records"))
        shutil.copy(os.path.join(ROOT, "prm", "records", "synthetic_kanai_tajimi.AT2"), os.path.join(work, "records"))
        p = subprocess.run([exe, "--quiet", "fem_base_excitation.prm"], cwd=work, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("hysteron failed: " + p.stderr)
        directory = os.path.join(work, "output", "fem_base_excitation")
        ground = columns(os.path.join(directory, "ground.csv"))
        deck = columns(os.path.join(directory, "probe_0.csv"))
        energy = columns(os.path.join(directory, "energy.csv"))

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    t = ground["time"]
    ax[0].plot(t, [a / 9.81 for a in ground["a_g"]], color="0.6", lw=0.7, label="ground a_g [g]")
    ax[0].plot(t, [a / 9.81 for a in deck["a_x"]], color="C0", lw=0.7, label="deck, absolute [g]")
    ax[0].set_xlabel("t [s]")
    ax[0].set_ylabel("acceleration [g]")
    twin = ax[0].twinx()
    twin.plot(t, [1e3 * u for u in deck["u_x"]], color="C3", lw=1.2, label="deck drift [mm]")
    twin.set_ylabel("drift relative to the ground [mm]", color="C3")
    ax[0].legend(loc="upper left", fontsize=8)
    ax[0].set_title("record and response")
    # The support pushes the body against its drift: the pier's restoring force is -base_x.
    ax[1].plot([1e3 * u for u in deck["u_x"]], [-b / 1e3 for b in ground["base_x"]], color="C0", lw=0.8)
    ax[1].axhline(392, color="0.5", ls="--", lw=0.8)
    ax[1].axhline(-392, color="0.5", ls="--", lw=0.8, label="plastic hinge, M_p / h")
    ax[1].set_xlabel("deck drift [mm]")
    ax[1].set_ylabel("restoring force = -base shear [kN]")
    ax[1].legend(loc="upper left", fontsize=8)
    ax[1].set_title("the pier's hysteresis")
    te = energy["time"]
    ax[2].plot(te, [w / 1e3 for w in energy["external_work"]], color="k", label="relative input")
    ax[2].stackplot(te, [d / 1e3 for d in energy["dissipated"]], [d / 1e3 for d in energy["damping_work"]],
                    [(k + s) / 1e3 for k, s in zip(energy["kinetic"], energy["strain_energy"])],
                    labels=["hysteresis", "Rayleigh damping", "kinetic + strain"],
                    colors=["C3", "C0", "C2"], alpha=0.6)
    ax[2].set_xlabel("t [s]")
    ax[2].set_ylabel("energy [kJ]")
    ax[2].legend(loc="upper left", fontsize=8)
    ax[2].set_title("energy balance")
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


if __name__ == "__main__":
    main()
