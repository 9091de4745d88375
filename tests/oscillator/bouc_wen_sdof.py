#!/usr/bin/env python3
"""A Bouc-Wen SDOF oscillator against an independent integration of its ODEs.

m = 1000 kg, k = 4 pi^2 m (T = 1 s), F_y = 2000 N, zeta = 0.05, the storey's Bouc-Wen law
with a = 0.05, n = 2, beta = gamma = 1/2 (adaptive integrator, tolerance 1e-10), under
a_g = 4 sin(2 pi 0.8 t) m/s^2 for t < 6.25 s (5 whole cycles, so a_g is continuous), then
free vibration to 8 s. The reference integrates the first-order system
  u' = v,  v' = -a_g - 2 zeta w v - (a k u + (1 - a) k z) / m,
  z' = v [1 - |z / z_y|^n (beta + gamma sgn(z v))],  z_y = F_y / k,
by classical Runge-Kutta with h = 1e-4 s (written here, independent of the code under test).
Checked at dt = 0.005 and 0.0025 s:
  * u within 3e-4 of max |u| and the spring force within 1e-3 F_y at 0.0025 s (measured
    4.0e-5 and 1.0e-4), second order (error ratio of u >= 3.2; measured 3.8);
  * the storey yields: ductility demand > 5 (measured 6.2), hysteretic energy > half the input;
  * the energy balance to 1e-9 of the input (Newton's tolerance; measured 6e-11).
Usage: bouc_wen_sdof.py HYSTERON WORKDIR
"""
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import Checks, run, table  # noqa: E402

M, FY, ZETA, A_R, N, BETA, GAMMA = 1000.0, 2000.0, 0.05, 0.05, 2.0, 0.5, 0.5
K = 4 * math.pi ** 2 * M

SCENE = """set Dimension = 2
set Method = oscillator
subsection Material
  set Model = bouc-wen
  set Young's modulus = 200e9
  subsection Bouc-Wen
    set Yield stress = 250e6
    set Post-yield stiffness ratio = {A_R}
    set Smoothness n = {N}
    set Beta = {BETA}
    set Gamma = {GAMMA}
    set Integrator = adaptive
    set Tolerance = 1e-10
  end
end
subsection Oscillator
  set Masses = {M}
  set Stiffnesses = {K!r}
  set Yield forces = {FY}
  set Damping ratio = {ZETA}
  set Ground acceleration = 4*sin(2*pi*0.8*t)*(t < 6.25)
  set Time step = {dt}
  set Duration = 8
end
subsection Output
  set Directory = {name}
end
"""


def ground(t):
    return 4 * math.sin(2 * math.pi * 0.8 * t) * (t < 6.25)


def reference(h=1e-4, duration=8.0, every=5):
    """RK4 of (u, v, z); the states at the multiples of every * h (keys: round(t, 6))."""
    w = math.sqrt(K / M)
    c, zy = 2 * ZETA * w * M, FY / K

    def f(t, y):
        u, v, z = y
        s = (z * v > 0) - (z * v < 0)
        return (v, -ground(t) - (c * v + A_R * K * u + (1 - A_R) * K * z) / M,
                v * (1 - abs(z / zy) ** N * (BETA + GAMMA * s)))

    y, out = (0.0, 0.0, 0.0), {0.0: (0.0, 0.0, 0.0)}
    for i in range(int(round(duration / h))):
        t = i * h
        k1 = f(t, y)
        k2 = f(t + h / 2, tuple(a + h / 2 * b for a, b in zip(y, k1)))
        k3 = f(t + h / 2, tuple(a + h / 2 * b for a, b in zip(y, k2)))
        k4 = f(t + h, tuple(a + h * b for a, b in zip(y, k3)))
        y = tuple(a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4))
        if (i + 1) % every == 0:
            out[round((i + 1) * h, 6)] = y
    return out


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    checks, ref, errors = Checks(), reference(), []
    for dt in (0.005, 0.0025):
        name = f"bouc_wen_{dt}"
        run(hysteron, workdir, name,
            SCENE.format(A_R=A_R, N=N, BETA=BETA, GAMMA=GAMMA, M=M, K=K, FY=FY, ZETA=ZETA, dt=dt, name=name))
        h = table(os.path.join(workdir, name, "history.csv"))
        e = table(os.path.join(workdir, name, "energy.csv"))
        s = table(os.path.join(workdir, name, "summary.csv"))
        peak = max(abs(u) for u in h["u_1"])
        eu = max(abs(u - ref[round(t, 6)][0]) for t, u in zip(h["t"], h["u_1"]))
        ef = max(abs(F - (A_R * K * ref[round(t, 6)][0] + (1 - A_R) * K * ref[round(t, 6)][2]))
                 for t, F in zip(h["t"], h["F_1"]))
        errors.append(eu)
        print(f"dt = {dt}: max |u| = {peak:.6g} m, error of u {eu / peak:.3g}, of F {ef / FY:.3g} F_y")
        if dt == 0.0025:
            checks.check(eu <= 3e-4 * peak, f"u within 3e-4 of max |u| ({eu / peak:.3g})")
            checks.check(ef <= 1e-3 * FY, f"F within 1e-3 F_y ({ef / FY:.3g})")
        checks.check(s["ductility"][0] > 5, f"dt = {dt}: ductility demand {s['ductility'][0]:.3f} > 5")
        checks.check(e["hysteretic"][-1] > 0.5 * e["input"][-1],
                     f"dt = {dt}: hysteretic energy {e['hysteretic'][-1]:.6g} J > half the input "
                     f"{e['input'][-1]:.6g} J")
        balance = max(abs(b) for b in e["balance"])
        checks.check(balance <= 1e-9 * max(e["input"]), f"dt = {dt}: energy balance {balance:.3g} J")
    ratio = errors[0] / errors[1]
    checks.check(ratio >= 3.2, f"second order: error ratio {ratio:.3f} >= 3.2")
    checks.exit()


if __name__ == "__main__":
    main()
