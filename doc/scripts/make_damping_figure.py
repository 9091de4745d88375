#!/usr/bin/env python3
"""Damping in the MPM (doc/mpm.md, "Damping"): doc/figures/mpm_damping.png.

Runs tests/mpm/damping_rayleigh_mass.prm and damping_rayleigh_stiffness.prm (the vibrating bar
with a0 = 2 1/s and with a1 = 0.1 / omega, xi = 0.05), the same bar undamped, and
prm/mpm_gravity_settling.prm with and without `Local damping`, and draws the tip displacement of
the bars against the analytic envelopes u_max exp(-xi omega t) and the settling layer's top
displacement against the static solution. About 15 s.
Usage: doc/scripts/make_damping_figure.py [path/to/hysteron] [output.png]
"""
import csv
import math
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OMEGA = math.pi / 2 * 10  # first mode of the bar, pi c / 2L


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def run(exe, work, text):
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, "scene.prm"), "w") as f:
        f.write(text)
    p = subprocess.run([exe, "--quiet", "scene.prm"], cwd=work, capture_output=True, text=True,
                       env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    if p.returncode != 0:
        sys.exit(f"{work}: exit {p.returncode}: {p.stderr[-1000:]}")
    return os.path.join(work, "output")


def undamped(text):
    return re.sub(r"\n  subsection Damping\n.*?\n  end", "", text, flags=re.S)


def main():
    exe = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "doc", "figures", "mpm_damping.png")
    mass = open(os.path.join(ROOT, "tests", "mpm", "damping_rayleigh_mass.prm")).read()
    stiff = open(os.path.join(ROOT, "tests", "mpm", "damping_rayleigh_stiffness.prm")).read()
    settle = open(os.path.join(ROOT, "prm", "mpm_gravity_settling.prm")).read()
    with tempfile.TemporaryDirectory() as work:
        bars = {name: columns(os.path.join(run(exe, os.path.join(work, name), text), "probe_0.csv"))
                for name, text in (("none", undamped(mass)), ("mass", mass), ("stiffness", stiff))}
        local = columns(os.path.join(run(exe, os.path.join(work, "local"), settle), "probe_0.csv"))
        free = columns(os.path.join(run(exe, os.path.join(work, "free"), undamped(settle)), "probe_0.csv"))

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    u0 = max(bars["none"]["u_x"])
    a.plot(bars["none"]["time"], bars["none"]["u_x"], color="0.6", lw=1, label="undamped")
    for name, xi, colour in (("mass", 2 / (2 * OMEGA), "C0"), ("stiffness", 0.05, "C3")):
        c = bars[name]
        label = "a0 = 2 1/s" if name == "mass" else "a1 = 0.1/omega (xi = 0.05)"
        a.plot(c["time"], c["u_x"], colour + "-", lw=1.4, label="MPM, " + label)
        env = [u0 * math.exp(-xi * OMEGA * t) for t in c["time"]]
        a.plot(c["time"], env, colour + ":", lw=1.2)
        a.plot(c["time"], [-e for e in env], colour + ":", lw=1.2)
    a.plot([], [], "k:", label="u_max exp(-xi omega t)")
    a.set_xlabel("t [s]")
    a.set_ylabel("tip displacement u_x [m]")
    a.set_title("Rayleigh damping, first mode of a fixed-free bar")
    a.legend(fontsize=8, loc="lower right")
    a.grid(alpha=0.3)

    y = local["x_y"][0]
    static = -10 * (y - y * y / 2) * 1.3 * 0.4 / (1000 * 0.7)
    b.plot(free["time"], free["u_y"], color="0.6", lw=1, label="undamped")
    b.plot(local["time"], local["u_y"], "C2-", lw=1.6, label="Local damping = 0.8")
    b.axhline(static, color="k", ls="--", lw=1, label="static rho g (H y - y^2/2) / M")
    b.set_xlabel("t [s]")
    b.set_ylabel("top displacement u_y [m]")
    b.set_title("Settling under gravity (prm/mpm_gravity_settling.prm)")
    b.legend(fontsize=8, loc="upper right")
    b.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


if __name__ == "__main__":
    main()
