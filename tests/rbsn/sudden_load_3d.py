#!/usr/bin/env python3
"""A suddenly applied load on a small elastic 3D network: Newmark against IDA, and the
dynamic overshoot.

A random network of a 0.4 x 0.1 x 0.1 m steel cantilever (67 cells, d_m = 0.05 m; E = 210 GPa,
nu = 0.2, rho = 7850 kg/m^3, k_s from G), clamped at x = 0 (`Faces = x-`), a tip load
P = 1e5 N along -y on the cells at x = 0.4 from t = 0, no damping. The deflection is the
mean u_y of the tip cells' nuclei (`Average regions`). Three runs of the same network:
  static             the static deflection u_s;
  implicit dynamics  Newmark (average acceleration), dt = 5e-6 s;
  variable order     SUNDIALS IDA, Relative tolerance = 1e-6, output every 5e-6 s.
Assertions (measured values in parentheses):
  * the two dynamic histories agree to 0.5 % of their peak at every output (0.15 %; with
    Newmark's step 1e-5 s it is 0.33 %, with 2.5e-6 s 0.11 % (IDA at 1e-6): Newmark's period
    error on the network's higher modes);
  * the first peak is about twice the static deflection: 1.95 < max|u| / u_s <= 2 (1.9902 and
    1.9903;
    the undamped response of a cantilever to a step load is dominated by its first mode, whose
    peak is exactly 2 u_s; the higher modes' share is out of phase there);
  * the peaks agree within 0.1 % (7e-5) and occur within one output of each other (1.015 and
    1.020 ms);
  * Newmark conserves the energy of the linear undamped network: |balance| < 1e-9 of the
    external work (5e-12 J of 164 J); IDA's balance < 1e-4 of it (3.6e-4 J, 2e-6: the work
    quadratures are part of IDA's error-controlled state).

Usage: sudden_load_3d.py HYSTERON WORKDIR
"""
import csv
import os
import subprocess
import sys

SCENE = """set Dimension = 3
set Method = rbsn
set Body names = beam
set Boundary names = clamp
set Load names = tip
set Random seed = 5
subsection Material
  set Model = linear elastic
  set Young's modulus = 210e9
  set Poisson's ratio = 0.2
  set Density = 7850
end
subsection Body beam
  set Shape = box(0, 0, 0, 0.4, 0.1, 0.1)
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Load tip
  set Type = force
  set Region = box(0.399, -1, -1, 0.401, 1, 1)
  set Value = 0; -1e5; 0
end
subsection RBSN
  set Analysis = {analysis}
  set Minimum distance = 0.05
  set Time step = 5e-6
  subsection Variable order
    set Relative tolerance = 1e-6
  end
end
subsection Time
  set End time = {end}
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = 0.4, 0.05, 0.05
  set Average regions = box(0.399, -1, -1, 0.401, 1, 1)
end
"""


def run(hysteron, workdir, name, analysis, end):
    directory = os.path.join(workdir, name)
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(analysis=analysis, end=end))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{name}: exit {p.returncode}: {p.stderr[-2000:]}")

    def table(file):
        with open(os.path.join(directory, "output", file)) as f:
            return list(csv.DictReader(f))
    return table("average_0.csv"), table("energy.csv")


def main():
    hysteron, workdir = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    static, _ = run(hysteron, workdir, "static", "static", "1e-5")
    newmark, newmark_energy = run(hysteron, workdir, "newmark", "implicit dynamics", "1.5e-3")
    ida, ida_energy = run(hysteron, workdir, "ida", "variable order", "1.5e-3")
    u_s = -float(static[-1]["u_y"])
    failures = []
    u_n = [-float(r["u_y"]) for r in newmark]
    u_i = [-float(r["u_y"]) for r in ida]
    t_n = [float(r["time"]) for r in newmark]
    t_i = [float(r["time"]) for r in ida]
    if len(t_n) != len(t_i) or max(abs(a - b) for a, b in zip(t_n, t_i)) > 1e-12:
        failures.append(f"the output times differ ({len(t_n)} and {len(t_i)} rows)")
    peak_n, peak_i = max(u_n), max(u_i)
    difference = max(abs(a - b) for a, b in zip(u_n, u_i)) / peak_n
    at_n, at_i = t_n[u_n.index(peak_n)], t_i[u_i.index(peak_i)]
    print(f"static deflection {u_s:.6e} m; peaks: Newmark {peak_n:.6e} m = {peak_n / u_s:.5f} u_s at "
          f"{at_n:.6g} s, IDA {peak_i:.6e} m = {peak_i / u_s:.5f} u_s at {at_i:.6g} s; largest "
          f"difference {100 * difference:.3f} % of the peak")
    if not difference < 5e-3:
        failures.append(f"Newmark and IDA differ by {100 * difference:.3f} % of the peak")
    for name, peak in (("Newmark", peak_n), ("IDA", peak_i)):
        if not 1.95 < peak / u_s <= 2.0:
            failures.append(f"{name}: peak {peak / u_s:.5f} u_s")
    if abs(peak_n / peak_i - 1) > 1e-3 or abs(at_n - at_i) > 5e-6 + 1e-12:
        failures.append(f"the peaks differ: {peak_n:.6e} at {at_n} s and {peak_i:.6e} at {at_i} s")
    for name, energy, tolerance in (("Newmark", newmark_energy, 1e-9), ("IDA", ida_energy, 1e-4)):
        worst = max(abs(float(r["balance"])) for r in energy)
        work = float(energy[-1]["external_work"])
        print(f"{name}: |balance| <= {worst:.3e} J, external work {work:.6g} J")
        if not worst < tolerance * work:
            failures.append(f"{name}: energy balance {worst:.3e} J against {tolerance} of {work:.6g} J")
    if failures:
        sys.exit("FAILED:\n  " + "\n  ".join(failures))
    print("passed: Newmark and IDA agree, the sudden load's peak is twice the static deflection")


if __name__ == "__main__":
    main()
