#!/usr/bin/env python3
"""Response spectra of a record: the elastic ones against an independent piecewise-exact
integration, the inelastic ones against the oscillator method.

The record is prm/records/synthetic_kanai_tajimi.AT2 (doc/scripts/synthetic_record.py, 0.3 g,
20 s at 0.01 s), scaled by 9.81. Periods 0.1 ... 3 s, zeta = 0.05; the storeys' Bouc-Wen law
a = 0.05, n = 2, beta = gamma = 1/2.
  * Elastic: Sd against the recurrence u_{i+1} = A u_i + B v_i + C p_i + D p_{i+1} (and the
    same for v) with the coefficients of the exact solution for a load linear over each step
    (Nigam and Jennings, as tabulated by Chopra), written here, with the record's steps split
    into parts of at most T / 50 as the method does: to 1e-9 (measured 4e-13);
    Sv = w Sd and Sa = w^2 Sd to 1e-12.
  * The same oscillator in the oscillator method at T = 1 s with 0.001 s steps (Newmark's
    average acceleration on the interpolated record): its peak within 1e-4 of the spectrum's
    Sd at 1000 steps per period (the same sampling).
  * Inelastic: the oscillator method with F_y = Ay_R and the spectrum's step reproduces mu_R to
    1e-9, and with F_y = Ay_mu the target ductility 4 within 1e-2 (the strength is bisected to
    1e-4 of it), at T = 0.5 and 2 s.
Usage: spectra.py HYSTERON RECORD WORKDIR
"""
import math
import os
import shutil
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import Checks, run, table  # noqa: E402

ZETA = 0.05
MATERIAL = """subsection Material
  set Model = bouc-wen
  set Young's modulus = 200e9
  subsection Bouc-Wen
    set Yield stress = 250e6
    set Post-yield stiffness ratio = 0.05
    set Smoothness n = 2
    set Integrator = adaptive
    set Tolerance = 1e-10
  end
end
subsection Ground motion
  set File = record.AT2
  set Scale factor = 9.81
end
"""
SPECTRUM = """set Dimension = 2
set Method = spectrum
""" + MATERIAL + """subsection Spectrum
  set Periods = 0.1:0.1:3
  set Damping ratio = 0.05
  set Strength reduction factor = 4
  set Target ductility = 4
end
subsection Output
  set Directory = spectrum
end
"""
OSCILLATOR = """set Dimension = 2
set Method = oscillator
""" + MATERIAL + """subsection Oscillator
  set Masses = 1
  set Stiffnesses = {k!r}
  set Yield forces = {fy!r}
  set Damping ratio = 0.05
  set Time step = {dt}
end
subsection Output
  set Directory = {name}
end
"""


def read_at2(path):
    with open(path) as f:
        lines = f.readlines()
    dt = float(lines[3].split("DT=")[1].split()[0])
    return dt, [9.81 * float(x) for line in lines[4:] for x in line.split()]


def nigam_jennings(T, dt, ag, steps_per_period=50):
    """The peak |u| of u'' + 2 zeta w u' + w^2 u = -a_g, a_g linear between samples, at the
    samples and m - 1 points between them (m dt_sub = dt, dt_sub <= T / steps_per_period)."""
    m = math.ceil(dt * steps_per_period / T - 1e-9)
    ag = [a + (b - a) * j / m for a, b in zip(ag, ag[1:]) for j in range(m)] + ag[-1:]
    dt = dt / m
    w = 2 * math.pi / T
    k, s1 = w * w, math.sqrt(1 - ZETA ** 2)
    wd, e = w * s1, math.exp(-ZETA * w * dt)
    sn, cs = math.sin(wd * dt), math.cos(wd * dt)
    A = e * (ZETA / s1 * sn + cs)
    B = e * sn / wd
    C = (2 * ZETA / (w * dt) + e * (((1 - 2 * ZETA ** 2) / (wd * dt) - ZETA / s1) * sn
                                    - (1 + 2 * ZETA / (w * dt)) * cs)) / k
    D = (1 - 2 * ZETA / (w * dt) + e * ((2 * ZETA ** 2 - 1) / (wd * dt) * sn + 2 * ZETA / (w * dt) * cs)) / k
    Ap = -e * w / s1 * sn
    Bp = e * (cs - ZETA / s1 * sn)
    Cp = (-1 / dt + e * ((w / s1 + ZETA / (dt * s1)) * sn + cs / dt)) / k
    Dp = (1 - e * (ZETA / s1 * sn + cs)) / (k * dt)
    u = v = peak = 0.0
    for i in range(len(ag) - 1):
        p0, p1 = -ag[i], -ag[i + 1]
        u, v = A * u + B * v + C * p0 + D * p1, Ap * u + Bp * v + Cp * p0 + Dp * p1
        peak = max(peak, abs(u))
    return peak


def main():
    hysteron, record, workdir = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(workdir, exist_ok=True)
    shutil.copy(record, os.path.join(workdir, "record.AT2"))
    dt, ag = read_at2(record)
    checks = Checks()
    run(hysteron, workdir, "spectrum", SPECTRUM)
    s = table(os.path.join(workdir, "spectrum", "spectrum.csv"))
    worst = worst_pseudo = 0
    for i, T in enumerate(s["T"]):
        w = 2 * math.pi / T
        ref = nigam_jennings(T, dt, ag)
        worst = max(worst, abs(s["Sd"][i] - ref) / ref)
        worst_pseudo = max(worst_pseudo, abs(s["Sv"][i] - w * s["Sd"][i]) / s["Sv"][i],
                           abs(s["Sa"][i] - w * w * s["Sd"][i]) / s["Sa"][i])
    checks.check(worst <= 1e-9, f"elastic Sd against Nigam-Jennings over {len(s['T'])} periods: {worst:.3g}")
    checks.check(worst_pseudo <= 1e-12, f"Sv = w Sd, Sa = w^2 Sd: {worst_pseudo:.3g}")
    # The elastic oscillator at T = 1 s by Newmark, both at 0.001 s (1000 steps per period).
    run(hysteron, workdir, "fine", SPECTRUM.replace("0.1:0.1:3", "1").replace(
        "set Damping ratio = 0.05", "set Damping ratio = 0.05\n  set Steps per period = 1000").replace(
        "Directory = spectrum", "Directory = fine"))
    fine = table(os.path.join(workdir, "fine", "spectrum.csv"))["Sd"][0]
    # (A linear storey takes no yield force: the line is dropped.)
    run(hysteron, workdir, "elastic", OSCILLATOR.replace("bouc-wen", "linear elastic").replace(
        "  set Yield forces = {fy!r}\n", "").format(
        k=(2 * math.pi) ** 2, fy=1.0, dt=0.001, name="elastic"))
    peak = table(os.path.join(workdir, "elastic", "summary.csv"))["peak_drift"][0]
    checks.check(abs(peak - fine) <= 1e-4 * fine,
                 f"T = 1 s: the oscillator's peak {peak:.8g} m against Sd {fine:.8g} m")
    checks.check(abs(nigam_jennings(1.0, dt, ag, 1000) - fine) <= 1e-9 * fine, "T = 1 s at 1000 steps per period")
    for T in (0.5, 2.0):
        i = min(range(len(s["T"])), key=lambda j: abs(s["T"][j] - T))
        k = (2 * math.pi / T) ** 2
        step = dt / math.ceil(dt * 50 / T - 1e-9)
        for column, fy, expected, tolerance in (("mu_R", s["Ay_R"][i], s["mu_R"][i], 1e-9),
                                                 ("mu", s["Ay_mu"][i], 4.0, 1e-2)):
            name = f"inelastic_{T}_{column}"
            run(hysteron, workdir, name, OSCILLATOR.format(k=k, fy=fy, dt=step, name=name))
            mu = table(os.path.join(workdir, name, "summary.csv"))["ductility"][0]
            checks.check(abs(mu - expected) <= tolerance * expected,
                         f"T = {T} s, F_y = {fy:.6g} N (per kg): ductility {mu:.8g}, {column} {expected:.8g}")
    checks.exit()


if __name__ == "__main__":
    main()
