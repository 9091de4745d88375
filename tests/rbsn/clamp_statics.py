#!/usr/bin/env python3
"""Statics of the clamp section of a 3D RBSN cantilever in plasticity (run by the
`# CHECK-SCRIPT` lines of tests/rbsn/plasticity_*_3d.prm in the scene's working directory).

The clamp section of a coarse network is the set of facets that join the clamp cells (the
cells whose facets among themselves have all six deformations exactly 0) to the rest. From
output/springs.csv at the end of the run and output/reactions.csv it checks:

(a) the springs' forces within their yield values (doc/rbsn3d.md): N_y = s A,
    V_y = s A / sqrt(3), M_y,i = s sqrt(12 I_i A) / 4, T_y = s sqrt(12 (I_1 + I_2) A) / (4 sqrt(3)),
    for the hysteretic part F^h = F - a k delta of each spring:
      elastic-perfectly-plastic, uncoupled:  |F^h_i| <= (1 - a) F_y,i
      coupled:                               sum_i (F^h_i / ((1 - a) F_y,i))^2 <= 1
(b) equilibrium of the part beyond the clamp: the moment of the clamp facets' forces about the
    z axis through (x0, y0) equals the tip force times L - x0, to Newton's tolerance;
(c) the bound of the clamp facets' mechanism (the part beyond them turning about (x0, y0)):
    no force exceeds sum over the facets of their largest moment / (L - x0), the largest moment
    being sum_i ((1 - a) F_y,i + a k_i |delta_i|) |arm_i| for independent springs and
    sqrt(sum_i ((1 - a) F_y,i arm_i)^2) + sum_i a k_i |delta_i arm_i| for the coupled law's
    ellipsoid (Cauchy-Schwarz); optionally the force reaches at least a fraction of it.

Usage: clamp_statics.py --law {elastic-perfectly-plastic,uncoupled,coupled} --yield-stress S
         --post-yield-ratio A --centre X0,Y0 --length L --yield-tolerance T
         [--whole-history] [--at-least R]
Exit status 0 when every check holds.
"""
import argparse
import csv
import math
import sys

FORCES = ("f_n", "f_1", "f_2", "m_1", "m_2", "m_t")
STIFFNESSES = ("k_n", "k_1", "k_2", "k_b1", "k_b2", "k_t")
DEFORMATIONS = ("delta_n", "delta_1", "delta_2", "phi_1", "phi_2", "phi_n")


def columns(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return {name: [float(r[j]) for r in rows[1:]] for j, name in enumerate(rows[0])}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--law", required=True, choices=["elastic-perfectly-plastic", "uncoupled", "coupled"])
    ap.add_argument("--yield-stress", type=float, required=True)
    ap.add_argument("--post-yield-ratio", type=float, default=0.0)
    ap.add_argument("--centre", required=True, help="x0,y0 of the hinge axis (parallel to z)")
    ap.add_argument("--length", type=float, required=True, help="x of the loaded end")
    ap.add_argument("--yield-tolerance", type=float, required=True)
    ap.add_argument("--whole-history", action="store_true",
                    help="(c) for every force of the history, not only the last")
    ap.add_argument("--at-least", type=float, help="(c) the last force reaches this fraction of the bound")
    args = ap.parse_args()
    s, q = args.yield_stress, args.post_yield_ratio
    x0, y0 = (float(v) for v in args.centre.split(","))

    c = columns("output/springs.csv")
    tip = columns("output/reactions.csv")["tip_y"]
    n = len(c["a"])
    F = [c[name] for name in FORCES]
    S = [c[name] for name in STIFFNESSES]
    D = [c[name] for name in DEFORMATIONS]

    def yield_values(k):
        A, I1, I2 = c["area"][k], c["I_1"][k], c["I_2"][k]
        return (s * A, s * A / math.sqrt(3), s * A / math.sqrt(3), s / 4 * math.sqrt(12 * I1 * A),
                s / 4 * math.sqrt(12 * I2 * A), s / 4 / math.sqrt(3) * math.sqrt(12 * (I1 + I2) * A))

    failures = []
    # (a) the hysteretic forces in units of their saturation values.
    worst = 0.0
    for k in range(n):
        Y = yield_values(k)
        h = [(F[i][k] - q * S[i][k] * D[i][k]) / ((1 - q) * Y[i]) for i in range(6)]
        worst = max(worst, math.sqrt(sum(v * v for v in h)) if args.law == "coupled" else max(map(abs, h)))
    print(f"(a) largest hysteretic force / saturation value: 1 {worst - 1:+.2e}")
    if worst > 1 + args.yield_tolerance:
        failures.append(f"(a) a spring force exceeds its yield value by {worst - 1:.2e}")

    # The clamp cells and the facets that join them to the rest.
    clamp = {v for k in range(n) if not any(d[k] for d in D) for v in (c["a"][k], c["b"][k])}
    section = [k for k in range(n) if (c["a"][k] in clamp) != (c["b"][k] in clamp)]

    def arms(k):
        """Lever arms of the six springs' forces about the z axis through (x0, y0)."""
        dx, dy = c["x"][k] - x0, c["y"][k] - y0
        return (dx * c["n_y"][k] - dy * c["n_x"][k], dx * c["s1_y"][k] - dy * c["s1_x"][k],
                dx * c["s2_y"][k] - dy * c["s2_x"][k], c["s1_z"][k], c["s2_z"][k], c["n_z"][k])

    lever = args.length - x0
    moment = sum((1 if c["a"][k] in clamp else -1) * sum(F[i][k] * arms(k)[i] for i in range(6))
                 for k in section) / lever
    bound = 0.0
    for k in section:
        Y, l = yield_values(k), arms(k)
        offset = sum(abs(q * S[i][k] * D[i][k] * l[i]) for i in range(6))
        if args.law == "coupled":
            bound += math.sqrt(sum(((1 - q) * Y[i] * l[i]) ** 2 for i in range(6))) + offset
        else:
            bound += sum((1 - q) * Y[i] * abs(l[i]) for i in range(6)) + offset
    bound /= lever
    print(f"(b) {len(section)} clamp facets of {len(clamp)} clamp cells: moment / lever {moment:.6g} N, "
          f"tip force {tip[-1]:.6g} N (relative difference {abs(moment - tip[-1]) / abs(tip[-1]):.1e})")
    if not abs(moment - tip[-1]) < 1e-8 * abs(tip[-1]):
        failures.append("(b) the clamp facets' moment does not balance the tip force")
    largest = max(abs(p) for p in (tip if args.whole_history else tip[-1:]))
    print(f"(c) mechanism bound {bound:.6g} N; the force reaches {largest / bound:.4f} of it")
    if largest > bound:
        failures.append(f"(c) a force of {largest:.6g} N exceeds the mechanism bound {bound:.6g} N")
    if args.at_least is not None and abs(tip[-1]) < args.at_least * bound:
        failures.append(f"(c) the end force reaches only {abs(tip[-1]) / bound:.4f} of the bound, "
                        f"not {args.at_least}")
    for f in failures:
        print("FAILED: " + f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
