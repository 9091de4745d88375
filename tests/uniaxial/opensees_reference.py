#!/usr/bin/env python3
"""The OpenSees laws on the uniaxial bench against histories computed by OpenSees itself.

The CSV files of opensees_reference/ were written by OpenSees' own BoucWenMaterial,
BoucWenOriginal and BWBN classes, driven step by step along the bench's strain path
(opensees_reference/make_reference.sh; README.md there). Each file's first line holds the
driver's arguments: the material, the path and OpenSees' constructor numbers. The bench
runs the same path in the same steps with the law and numbers that correspond:

  BoucWen          -> OpenSees BoucWen, its numbers as they are (k = E = ko);
  BoucWenOriginal  -> OpenSees BoucWenOriginal (E, Yield stress = fy);
  BWBN             -> pinching, mapped: OpenSees' BWBN is Foliente's law with A = Ao fixed
                      (no deltaA, deltaNu, deltaEta), z in the units of the deformation and
                      the energy e = (1 - alpha) k int z d delta (doc/theory.md).

Both take one backward-Euler step per increment; OpenSees iterates Newton until the change
of z is below 1e-8, hysteron to round-off. Stresses agree to 1e-6 of the peak (measured:
1e-15 without degradation or pinching, 1e-11 to 5e-11 with, OpenSees' stopping tolerance).
Without the degradation or pinching the bench is far from OpenSees: those terms are tested.

Usage: opensees_reference.py HYSTERON WORKDIR
"""
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "oscillator"))
from common import Checks, uniaxial_bench  # noqa: E402

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "opensees_reference")
TOLERANCE = 1e-6


def read_reference(path):
    """(driver arguments, rows of t, strain, stress) of a reference CSV."""
    with open(path) as f:
        lines = f.read().splitlines()
    args = lines[0].split("driver ", 1)[1].split()
    rows = [tuple(float(x) for x in line.split(",")) for line in lines[2:]]
    return args, rows


def entries(subsection, values):
    body = "\n".join(f"      set {k} = {v!r}" for k, v in values.items())
    return f"    subsection {subsection}\n{body}\n    end"


def bouc_wen(p):
    """OpenSees BoucWen: alpha ko n gamma beta Ao deltaA deltaNu deltaEta tol maxNumIter."""
    names = ("alpha", "ko", "n", "gamma", "beta", "Ao", "deltaA", "deltaNu", "deltaEta")
    v = dict(zip(names, p))
    ko = v.pop("ko")
    law = "    set Uniaxial law = OpenSees BoucWen\n" + entries("OpenSees BoucWen", v)
    return ko, 1e-3 * ko, law  # the yield stress is not used by this law


def bouc_wen_original(p):
    """OpenSees BoucWenOriginal: E fy alphaL alphaNL mu eta beta gamma tol maxIter."""
    names = ("E", "fy", "alphaL", "alphaNL", "mu", "eta", "beta", "gamma")
    v = dict(zip(names, p))
    E, fy = v.pop("E"), v.pop("fy")
    law = "    set Uniaxial law = OpenSees BoucWenOriginal\n" + entries("OpenSees BoucWenOriginal", v)
    return E, fy, law


def bwbn(p):
    """OpenSees BWBN (alpha ko n gamma beta Ao q zetas p Shi deltaShi lamda tol maxNumIter)
    as the pinching law of a spring k = ko, y = 2.5e-3 ko, so z_y = y / k = 2.5e-3 (any value
    serves; this one differs from OpenSees' z_u in both histories). With
    w = z / z_y and e_h = int w dx = e / ((1 - alpha) k z_y^2) the two rate equations are one:
    beta, gamma scale by z_y^n; q w_u = q_o zu / z_y gives q = q_o Ao^(-1/n); psi_0 = Shi / z_y,
    delta_psi = deltaShi (1 - alpha) k z_y; p = p_o (1 - alpha) k z_y^2."""
    alpha, ko, n, gamma, beta, Ao, q, zetas, p_o, Shi, dShi, lamda = p[:12]
    zy = 2.5e-3
    c = (1 - alpha) * ko * zy * zy  # e_OpenSees = c e_hysteron
    v = {
        "alpha": alpha, "n": n, "beta": beta * zy**n, "gamma": gamma * zy**n, "A0": Ao,
        "delta_A": 0.0, "delta_nu": 0.0, "delta_eta": 0.0, "zeta_s": zetas, "p": p_o * c,
        "q": q * Ao ** (-1 / n), "psi_0": Shi / zy, "delta_psi": dShi * c / zy, "lambda": lamda,
    }
    return ko, zy * ko, "    set Uniaxial law = pinching\n" + entries("Pinching", v)


# Each material: the mapping and the positions of its degradation or pinching numbers.
LAWS = {"BoucWen": (bouc_wen, (6, 7, 8)), "BoucWenOriginal": (bouc_wen_original, ()), "BWBN": (bwbn, (7,))}


def bench(hysteron, workdir, name, args, numbers):
    """sigma and eps of the bench along the driver's path with the mapped @p numbers."""
    material, amplitude, drift, end, steps = args[:5]
    E, SY, law = LAWS[material][0](numbers)
    # The driver's strain: amplitude t / end sin(2 pi t) + drift t / end, in this order.
    strain = f"{amplitude}*t/{end}*sin(2*pi*t) + {drift}*t/{end}"
    return uniaxial_bench(hysteron, workdir, name, E, SY, law, strain, end, steps)


def difference(h, ref, rows, column, index):
    """max |h - ref| over the reference rows, relative to the reference's peak."""
    peak = max(abs(r[index]) for r in ref)
    return max(abs(h[column][k] - r[index]) for k, r in zip(rows, ref)) / peak, peak


def compare(hysteron, workdir, path, c):
    name = os.path.splitext(os.path.basename(path))[0]
    args, ref = read_reference(path)
    material, steps, every = args[0], int(args[4]), int(args[5])
    numbers = [float(x) for x in args[6:]]
    h = bench(hysteron, workdir, name, args, numbers)
    rows = [k for k in range(0, steps + 1) if k % every == 0 or k == steps]
    c.check(len(h["sig"]) == steps + 1 and len(rows) == len(ref), f"{name}: {steps} steps, {len(ref)} rows compared")
    eps_err = difference(h, ref, rows, "eps", 1)[0]
    c.check(eps_err <= 1e-13, f"{name}: the same strains (max difference {eps_err:.1e} of the peak)")
    err, peak = difference(h, ref, rows, "sig", 2)
    c.check(err < TOLERANCE, f"{name} ({material}): max |sigma - sigma_OpenSees| = {err:.2e} of the peak {peak:.4e} (< {TOLERANCE:g})")
    # The degradation or pinching matters: without it the history is far from OpenSees'.
    off = LAWS[material][1]
    if any(numbers[i] != 0 for i in off):
        plain = [0.0 if i in off else x for i, x in enumerate(numbers)]
        far = difference(bench(hysteron, workdir, name + "_off", args, plain), ref, rows, "sig", 2)[0]
        c.check(far > 0.05, f"{name}: without its degradation or pinching the difference is {far:.2f} of the peak (> 0.05)")


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    c = Checks()
    files = sorted(glob.glob(os.path.join(HERE, "*.csv")))
    c.check(len(files) >= 5, f"{len(files)} reference histories")
    for path in files:
        compare(hysteron, workdir, path, c)
    c.exit()


if __name__ == "__main__":
    main()
