#!/usr/bin/env python3
"""Write a synthetic ground-motion record in the PEER .AT2 format (accelerations in g).

Not a recorded earthquake: Gaussian white noise (seeded, so the file is reproducible) filtered
by the Kanai-Tajimi ground filter (omega_g, zeta_g: firm soil by default), the filter's absolute
acceleration -(2 zeta_g omega_g x' + omega_g^2 x) taken as the ground's, shaped by Jennings'
envelope ((t/t1)^2 up to t1, 1 up to t2, exp(-c (t - t2)) after) and scaled to the peak ground
acceleration PGA. The filter is integrated by RK4 with 10 substeps per sample (the noise held
constant over a sample).

Usage: synthetic_record.py OUTPUT.AT2 [--seed 2026] [--pga 0.3] [--dt 0.01] [--duration 20]
"""
import argparse
import math
import random


def record(seed, pga, dt, duration, omega_g=15.6, zeta_g=0.6, t1=2.0, t2=8.0, decay=0.4):
    rng = random.Random(seed)
    n = int(round(duration / dt)) + 1
    x, v, out = 0.0, 0.0, []
    h = dt / 10

    def rates(x, v, w):
        return v, -w - 2 * zeta_g * omega_g * v - omega_g ** 2 * x

    for k in range(n):
        t = k * dt
        envelope = (t / t1) ** 2 if t < t1 else (1.0 if t < t2 else math.exp(-decay * (t - t2)))
        out.append(-(2 * zeta_g * omega_g * v + omega_g ** 2 * x) * envelope)
        w = rng.gauss(0.0, 1.0) / math.sqrt(dt)
        for _ in range(10):
            k1 = rates(x, v, w)
            k2 = rates(x + h / 2 * k1[0], v + h / 2 * k1[1], w)
            k3 = rates(x + h / 2 * k2[0], v + h / 2 * k2[1], w)
            k4 = rates(x + h * k3[0], v + h * k3[1], w)
            x += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            v += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    peak = max(abs(a) for a in out)
    return [pga * a / peak for a in out]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("output")
    p.add_argument("--seed", type=int, default=2026)
    p.add_argument("--pga", type=float, default=0.3, help="peak ground acceleration [g]")
    p.add_argument("--dt", type=float, default=0.01)
    p.add_argument("--duration", type=float, default=20.0)
    a = p.parse_args()
    values = record(a.seed, a.pga, a.dt, a.duration)
    with open(a.output, "w") as f:
        f.write("PEER-FORMAT SYNTHETIC RECORD: Kanai-Tajimi filtered white noise, seed %d\n" % a.seed)
        f.write("written by doc/scripts/synthetic_record.py (not a recorded earthquake), PGA %g g\n" % a.pga)
        f.write("ACCELERATION TIME SERIES IN UNITS OF G\n")
        f.write("NPTS=%7d, DT=%9.4f SEC\n" % (len(values), a.dt))
        for i in range(0, len(values), 5):
            f.write("".join("%15.7E" % v for v in values[i:i + 5]) + "\n")


if __name__ == "__main__":
    main()
