#!/usr/bin/env python3
"""An elastic SDOF oscillator under a harmonic ground acceleration, against the closed form.

m = 1000 kg, k = 4 pi^2 m (T = 1 s), zeta = 0.05, a_g = A sin(W t) with A = 1 m/s^2 and
W = 2 pi 0.8 rad/s, at rest at t = 0: u'' + 2 zeta w u' + w^2 u = -A sin(W t) has
  u = C1 sin Wt + C2 cos Wt + exp(-zeta w t) (B1 cos wd t + B2 sin wd t),
  D = (w^2 - W^2)^2 + (2 zeta w W)^2, C1 = -A (w^2 - W^2) / D, C2 = 2 zeta w W A / D,
  B1 = -C2, B2 = (zeta w B1 - W C1) / wd, wd = w sqrt(1 - zeta^2).
Checked over 10 s at dt = T/100 and T/200 (Newmark's average acceleration):
  * the largest error of u below 1e-3 of max |u| at T/200, and second order: the error ratio
    of the two steps within [3.6, 4.4] (measured 5.0e-4 and 4.00);
  * the absolute acceleration a = -(c v + k u) / m, the equation of motion, to 1e-9;
  * the energy balance input = kinetic + damped + elastic (+ hysteretic 0) to 1e-9 of the input.
Usage: sdof_harmonic.py HYSTERON WORKDIR
"""
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import Checks, run, table  # noqa: E402

M, K, ZETA, A, W = 1000.0, 4 * math.pi ** 2 * 1000.0, 0.05, 1.0, 2 * math.pi * 0.8

SCENE = """set Dimension = 2
set Method = oscillator
subsection Material
  set Model = linear elastic
  set Young's modulus = 200e9
end
subsection Oscillator
  set Masses = {M}
  set Stiffnesses = {K!r}
  set Damping ratio = {ZETA}
  set Ground acceleration = {A}*sin({W!r}*t)
  set Time step = {dt}
  set Duration = 10
end
subsection Output
  set Directory = {name}
end
"""


def exact(t):
    w = math.sqrt(K / M)
    wd = w * math.sqrt(1 - ZETA ** 2)
    D = (w ** 2 - W ** 2) ** 2 + (2 * ZETA * w * W) ** 2
    C1, C2 = -A * (w ** 2 - W ** 2) / D, 2 * ZETA * w * W * A / D
    B1 = -C2
    B2 = (ZETA * w * B1 - W * C1) / wd
    return C1 * math.sin(W * t) + C2 * math.cos(W * t) + math.exp(-ZETA * w * t) * (
        B1 * math.cos(wd * t) + B2 * math.sin(wd * t))


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    checks, errors = Checks(), []
    c = 2 * ZETA * math.sqrt(K / M) * M
    for dt in (0.01, 0.005):
        name = f"sdof_{dt}"
        run(hysteron, workdir, name, SCENE.format(M=M, K=K, ZETA=ZETA, A=A, W=W, dt=dt, name=name))
        h = table(os.path.join(workdir, name, "history.csv"))
        e = table(os.path.join(workdir, name, "energy.csv"))
        peak = max(abs(u) for u in h["u_1"])
        error = max(abs(u - exact(t)) for t, u in zip(h["t"], h["u_1"]))
        errors.append(error / peak)
        print(f"dt = {dt}: max |u| = {peak:.6g} m, error {error:.3g} m ({error / peak:.3g})")
        motion = max(abs(a + (c * v + K * u) / M) for a, v, u in zip(h["a_1"], h["v_1"], h["u_1"]))
        checks.check(motion <= 1e-9 * max(abs(a) for a in h["a_1"]),
                     f"dt = {dt}: a = -(c v + k u)/m to {motion:.3g} m/s^2")
        balance = max(abs(b) for b in e["balance"])
        checks.check(balance <= 1e-9 * max(abs(x) for x in e["input"]),
                     f"dt = {dt}: energy balance {balance:.3g} J of input {max(e['input']):.6g} J")
    checks.check(errors[1] < 1e-3, f"error at T/200 {errors[1]:.3g} < 1e-3 of max |u|")
    ratio = errors[0] / errors[1]
    checks.check(3.6 <= ratio <= 4.4, f"second order: error ratio {ratio:.3f} in [3.6, 4.4]")
    checks.exit()


if __name__ == "__main__":
    main()
