#!/usr/bin/env python3
"""Energy in a bar that a pressure pulse leaves through an absorbing end, against a fixed end
(doc/fem.md, "Absorbing boundaries").

Runs prm/fem_absorbing_pulse.prm as shipped and with its absorbing end made fixed, and writes
doc/figures/fem_absorbing.png: the work of the pulse, the energy in the bar (kinetic + strain)
and the energy the dashpots absorbed (-boundary_work), over the time; on stdout the energy left
at the end as a fraction of the input. A few seconds. Usage:
doc/scripts/make_absorbing_figure.py [path/to/hysteron]
"""
import csv
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "prm", "fem_absorbing_pulse.prm")


def run(exe, work, end_type):
    text = open(SCENE).read().replace("set Type = absorbing", f"set Type = {end_type}")
    with open(os.path.join(work, "pulse.prm"), "w") as f:
        f.write(text)
    subprocess.run([exe, "--quiet", "pulse.prm"], cwd=work, check=True)
    with open(os.path.join(work, "output", "energy.csv")) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    exe = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    fig, (ax, ax_log) = plt.subplots(1, 2, figsize=(11, 4.5))
    for end_type, style in (("fixed", "--"), ("absorbing", "-")):
        with tempfile.TemporaryDirectory() as work:
            e = run(exe, work, end_type)
        t = [1e3 * x for x in e["time"]]
        bar = [k + s for k, s in zip(e["kinetic"], e["strain_energy"])]
        if end_type == "fixed":
            ax.plot(t, e["external_work"], "k:", label="work of the pulse")
        ax.plot(t, bar, style, label=f"kinetic + strain energy, {end_type} end")
        if end_type == "absorbing":
            ax.plot(t, [-w for w in e["boundary_work"]], "-.", label="absorbed by the dashpots")
        ax_log.semilogy(t, [max(b / e["external_work"][-1], 1e-12) for b in bar], style, label=f"{end_type} end")
        print(f"{end_type} end: energy left at t = {e['time'][-1]:g} s: {bar[-1] / e['external_work'][-1]:.2e} of the input")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("energy per unit thickness [J/m]")
    ax.set_title("Half-sine pulse in a bar (prm/fem_absorbing_pulse.prm)")
    ax.grid(alpha=0.3)
    ax.legend()
    ax_log.axhline(0.01, color="k", lw=0.8, ls=":", label="1 % (acceptance)")
    ax_log.set_xlabel("time [ms]")
    ax_log.set_ylabel("(kinetic + strain energy) / work of the pulse")
    ax_log.set_title("Energy left in the bar")
    ax_log.grid(alpha=0.3, which="both")
    ax_log.legend()
    fig.tight_layout()
    out = os.path.join(ROOT, "doc", "figures", "fem_absorbing.png")
    fig.savefig(out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    main()
