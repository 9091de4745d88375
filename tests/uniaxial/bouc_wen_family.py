#!/usr/bin/env python3
"""The Bouc-Wen family's uniaxial laws (Bouc-Wen/Uniaxial law) on the uniaxial bench.

1. Each law against an independent implementation, written here from the equations of
   doc/theory.md ("The Bouc-Wen family"): the same implicit step per increment (OpenSees'
   discretisation), its root found by bisection instead of Newton. Stresses agree to 1e-9
   of the peak (measured: 1e-15 to 1e-13).
2. The pinching law with degradation against a Runge-Kutta integration of its rate
   equations: the implicit step is first order, the error halves when the steps are halved.
3. Closed-form plateaus: the asymmetric law saturates at a E eps + (1 - a) sigma_y in tension
   and a E eps - (1 - a) r_c sigma_y in compression, BoucWenOriginal at q_d + k_2 eps.

Usage: bouc_wen_family.py HYSTERON WORKDIR
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "oscillator"))
from common import Checks, uniaxial_bench  # noqa: E402

E, SY = 200e9, 200e6
EY = SY / E  # yield strain 1e-3
END = 4.0
PATH = "3e-3*t/4*sin(2*pi*t) + 1e-3*t/4"  # growing cycles with a drift


def strain(t):
    return 3e-3 * t / 4 * math.sin(2 * math.pi * t) + 1e-3 * t / 4


def signum(x):  # OpenSees' signum: -1 at 0
    return 1.0 if x > 0 else -1.0


def sign(x):
    return (x > 0) - (x < 0)


# Each law: g(z, e, D) = dz/d delta, the energy factor c (e' = c z delta'), the force F(delta, z).
def opensees_bouc_wen(alpha, n, gamma, beta, A0, dA, dnu, deta):
    def g(z, e, D):
        psi = gamma + beta * signum(D * z)
        return (A0 - dA * e - (1 + dnu * e) * abs(z) ** n * psi) / (1 + deta * e)

    return g, (1 - alpha) * E, lambda d, z: alpha * E * d + (1 - alpha) * E * z


def pinching(alpha, n, beta, gamma, A0, dA, dnu, deta, zs, p, q, psi0, dpsi, lam):
    zy = EY

    def g(z, e, D):
        w = z / zy
        A, nu = A0 - dA * e, 1 + dnu * e
        base = (A - nu * abs(w) ** n * (gamma + beta * signum(D * z))) / (1 + deta * e)
        wu = (A / (nu * (beta + gamma))) ** (1 / n)
        z1 = zs * (1 - math.exp(-p * e))
        z2 = (psi0 + dpsi * e) * (lam + z1)
        return (1 - z1 * math.exp(-(((signum(D) * w - q * wu) / z2) ** 2))) * base

    return g, 1 / zy**2, lambda d, z: alpha * E * d + (1 - alpha) * E * z


def asymmetric(a, n, beta, gamma, ratio):
    def g(z, e, D):
        zy = EY if z >= 0 else ratio * EY
        return 1 - abs(z / zy) ** n * (beta + gamma * sign(D * z))

    return g, 0.0, lambda d, z: a * E * d + (1 - a) * E * z


def original(aL, aNL, mu, eta, beta, gamma):
    qd = SY - aL * E * EY - aNL * E * EY**mu

    def g(z, e, D):
        return 1 - abs(z / EY) ** eta * (gamma + beta * sign(z * D))

    return g, 0.0, lambda d, z: qd * z / EY + aL * E * d + aNL * E * sign(d) * abs(d) ** mu


def implicit_history(law, steps):
    """sigma at the steps of the bench: z_1 = z_0 + D g(z_1, e_0 + c D z_1), by bisection."""
    g, c, force = law
    z = e = d = 0.0
    out = []
    for k in range(steps + 1):
        D = strain(END * k / steps) - d
        if D != 0:
            r = lambda x: x - z - D * g(x, e + c * D * x, D)
            r0 = r(z)
            step, direction = abs(r0) + 1e-15, (-1 if r0 > 0 else 1)
            x = z + direction * step
            while (r(x) > 0) == (r0 > 0):
                step *= 2
                x = z + direction * step
            lo, hi = (z, x) if r0 < 0 else (x, z)
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if r(mid) < 0:
                    lo = mid
                else:
                    hi = mid
            z1 = 0.5 * (lo + hi)
            e += c * D * z1
            z = z1
        d += D
        out.append(force(d, z))
    return out


def rk4_history(law, steps, substeps):
    """sigma at the same steps from the rate equations (RK4 in delta, sgn(D) per step)."""
    g, c, force = law
    z = e = d = 0.0
    out = []
    for k in range(steps + 1):
        D = strain(END * k / steps) - d
        h = D / substeps

        def f(z, e):
            rate = g(z, e, D)
            return rate, c * z

        for _ in range(substeps if D != 0 else 0):
            k1 = f(z, e)
            k2 = f(z + h / 2 * k1[0], e + h / 2 * k1[1])
            k3 = f(z + h / 2 * k2[0], e + h / 2 * k2[1])
            k4 = f(z + h * k3[0], e + h * k3[1])
            z += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            e += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        d += D
        out.append(force(d, z))
    return out


def bench(hysteron, workdir, name, entries, steps, path=PATH, end=END):
    return uniaxial_bench(hysteron, workdir, name, E, SY, entries, path, end, steps)


LAWS = {
    "opensees_bouc_wen": (
        """    set Uniaxial law = OpenSees BoucWen
    subsection OpenSees BoucWen
      set alpha = 0.05
      set n = 2
      set gamma = 3e5
      set beta = 7e5
      set Ao = 1
      set deltaA = 1e-7
      set deltaNu = 2e-6
      set deltaEta = 1e-6
    end""",
        opensees_bouc_wen(0.05, 2, 3e5, 7e5, 1, 1e-7, 2e-6, 1e-6),
    ),
    "pinching": (
        """    set Uniaxial law = pinching
    subsection Pinching
      set alpha = 0.02
      set n = 1.5
      set beta = 0.6
      set gamma = 0.4
      set delta_nu = 0.01
      set delta_eta = 0.01
      set zeta_s = 0.85
      set p = 0.2
      set q = 0.15
      set psi_0 = 0.3
      set delta_psi = 0.005
      set lambda = 0.5
    end""",
        pinching(0.02, 1.5, 0.6, 0.4, 1, 0, 0.01, 0.01, 0.85, 0.2, 0.15, 0.3, 0.005, 0.5),
    ),
    "asymmetric": (
        """    set Post-yield stiffness ratio = 0.03
    set Smoothness n = 4
    set Uniaxial law = asymmetric
    subsection Asymmetric
      set Compression yield ratio = 1.6
    end""",
        asymmetric(0.03, 4, 0.5, 0.5, 1.6),
    ),
    "original": (
        """    set Uniaxial law = OpenSees BoucWenOriginal
    subsection OpenSees BoucWenOriginal
      set alphaL = 0.05
      set alphaNL = 1e-4
      set mu = 2
      set eta = 3
      set beta = 0.6
      set gamma = 0.4
    end""",
        original(0.05, 1e-4, 2, 3, 0.6, 0.4),
    ),
}


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    c = Checks()
    steps = 2000
    for name, (entries, law) in LAWS.items():
        h = bench(hysteron, workdir, name, entries, steps)
        ref = implicit_history(law, steps)
        peak = max(abs(s) for s in ref)
        err = max(abs(a - b) for a, b in zip(h["sig"], ref)) / peak
        c.check(len(h["sig"]) == steps + 1 and err <= 1e-9,
                f"{name}: the implicit step as written independently, max error {err:.2e} of the peak {peak:.3e} Pa (<= 1e-9)")
        area = sum(0.5 * (h["sig"][i] + h["sig"][i - 1]) * (h["eps"][i] - h["eps"][i - 1]) for i in range(1, len(h["sig"])))
        c.check(area > 0, f"{name}: the loops dissipate (net work {area:.3e} J/m^3 > 0)")

    # 2. First-order convergence to the rate equations (pinching with degradation).
    entries, law = LAWS["pinching"]
    errors = []
    for n in (2000, 4000):
        h = bench(hysteron, workdir, f"pinching_{n}", entries, n)
        ref = rk4_history(law, n, 20)
        peak = max(abs(s) for s in ref)
        errors.append(max(abs(a - b) for a, b in zip(h["sig"], ref)) / peak)
    ratio = errors[0] / errors[1]
    c.check(errors[1] < 2e-2 and 1.6 <= ratio <= 2.5,
            f"pinching: against RK4 of the rate equations, errors {errors[0]:.2e}, {errors[1]:.2e} of the peak, ratio {ratio:.2f} (first order: 2)")

    # 3. Plateaus in closed form.
    h = bench(hysteron, workdir, "asymmetric_tension", LAWS["asymmetric"][0], 200, path="0.02*t", end=1)
    expect = 0.03 * E * 0.02 + 0.97 * SY
    c.check(abs(h["sig"][-1] - expect) <= 1e-6 * SY, f"asymmetric: tension plateau {h['sig'][-1]:.6e} vs {expect:.6e} Pa")
    h = bench(hysteron, workdir, "asymmetric_compression", LAWS["asymmetric"][0], 200, path="-0.02*t", end=1)
    expect = -0.03 * E * 0.02 - 0.97 * 1.6 * SY
    c.check(abs(h["sig"][-1] - expect) <= 1e-6 * SY, f"asymmetric: compression plateau {h['sig'][-1]:.6e} vs {expect:.6e} Pa")
    h = bench(hysteron, workdir, "original_plateau", LAWS["original"][0].replace("alphaNL = 1e-4", "alphaNL = 0"), 400, path="0.02*t", end=1)
    expect = (SY - 0.05 * SY) + 0.05 * E * 0.02
    c.check(abs(h["sig"][-1] - expect) <= 1e-6 * SY, f"BoucWenOriginal: plateau q_d + k_2 eps = {expect:.6e}, got {h['sig'][-1]:.6e} Pa")
    c.exit()


if __name__ == "__main__":
    main()
