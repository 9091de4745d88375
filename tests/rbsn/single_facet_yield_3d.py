#!/usr/bin/env python3
"""One facet between two cells in 3D reaches the yield values of FacetSprings<3>::yield_values
under each spring law, in tension, shear, bending and torsion.

Two cells of a 1 m x 0.5 m x 0.5 m bar (nuclei at (0.25, 0.25, 0.25) and (0.75, 0.25, 0.25):
two 0.5 m cubes and one 0.5 x 0.5 m facet at x = 0.5; S235, E = 210 GPa, nu = 0.3,
sigma_y = 235 MPa, Bouc-Wen n = 8, beta = gamma = 0.5, a = 0, backward Euler). The left cell
is fixed; the right one is moved rigidly (`Components = all`: its translation and, from the
field's curl, its rotation) by one deformation mode, monotonically to 10 times the elastic
limit of its spring, so that the spring deforms alone:
  tension  u = (d(t), 0, 0)                      delta_n = d
  shear    u = (0, d(t), 0)                      delta_1 or delta_2 = d (the square's axes)
  bending  rotation th(t) about y about P        phi_1 or phi_2 = th
  torsion  rotation th(t) about x about P        phi_n = th
(P = (0.5, 0.25, 0.25), the facet's centroid: a rotation of the cell about its nucleus would
move P and shear the facet too.)
The yield values (FacetSprings<3>::yield_values, A = 0.25 m^2, I_1 = I_2 = 0.5^4 / 12,
Moment yield factor f = 1/4):
  N_y = sigma_y A = 58.75 MN, V_y = N_y / sqrt(3) = 33.919 MN,
  M_y = f sigma_y A sqrt(12 I / A) = 7.34375 MN m,
  T_y = f sigma_y / sqrt(3) A sqrt(12 (I_1 + I_2) / A) = 5.9964 MN m.
Assertions, for the laws uncoupled, coupled and elastic-perfectly-plastic:
  * the loaded spring's force at the end is its yield value within 1 % (measured: the Bouc-Wen
    laws 1e-9 below it, a = 0 and z -> 1; the elastic-perfectly-plastic law exactly);
  * it never exceeds the yield value (1e-9);
  * the elastic start: the first increment's secant stiffness is k (0.5 %: the Bouc-Wen laws
    are already slightly soft at 0.1 of the elastic limit);
  * the other five springs carry nothing (1e-9 of the loaded one's yield value);
  * the energy balance holds to 1e-8 of the work done (every DoF is prescribed: Newton has
    nothing to solve; the networks of the plasticity_*_3d tests exercise it);
  * the coupled law under proportional tension and torsion saturates at the analytic
    interaction value N / N_y = T / T_y = 1 / sqrt(2) (1e-4), never beyond Phi = 1 + 1e-6.

Usage: single_facet_yield_3d.py HYSTERON WORKDIR
"""
import csv
import math
import os
import subprocess
import sys

E, NU, SIGMA_Y = 210e9, 0.3, 235e6
A, I = 0.25, 0.5 ** 4 / 12
H = 0.5
YIELD = {"f_n": SIGMA_Y * A, "f_1": SIGMA_Y * A / math.sqrt(3), "f_2": SIGMA_Y * A / math.sqrt(3),
         "m_1": 0.25 * SIGMA_Y * A * math.sqrt(12 * I / A), "m_2": 0.25 * SIGMA_Y * A * math.sqrt(12 * I / A),
         "m_t": 0.25 * SIGMA_Y / math.sqrt(3) * A * math.sqrt(12 * 2 * I / A)}
P_WAVE = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
G = E / (2 * (1 + NU))
STIFFNESS = {"f_n": P_WAVE * A / H, "f_1": G * A / H, "f_2": G * A / H,
             "m_1": P_WAVE * I / H, "m_2": P_WAVE * I / H, "m_t": G * 2 * I / H}
DEFORMATION = {"f_n": "delta_n", "f_1": "delta_1", "f_2": "delta_2", "m_1": "phi_1", "m_2": "phi_2",
               "m_t": "phi_n"}

SCENE = """set Dimension = 3
set Method = rbsn
set Body names = bar
set Boundary names = fix, move
subsection Material
  set Model = bouc-wen
  set Young's modulus = {E}
  set Poisson's ratio = {NU}
  set Density = 7850
  subsection Bouc-Wen
    set Yield stress = {SIGMA_Y}
    set Post-yield stiffness ratio = 0
    set Smoothness n = 8
    set Beta = 0.5
    set Gamma = 0.5
    set Integrator = backward euler
  end
end
subsection Body bar
  set Shape = box(0, 0, 0, 1, 0.5, 0.5)
end
subsection Boundary fix
  set Type = fixed
  set Region = sphere(0.25, 0.25, 0.25, 0.01)
end
subsection Boundary move
  set Type = displacement
  set Region = sphere(0.75, 0.25, 0.25, 0.01)
  set Displacement = {motion}
end
subsection RBSN
  set Analysis = quasi-static
  set Spring law = {law}
  set Minimum distance = 2
  set Points on the boundary = false
  set Additional points = 0.25, 0.25, 0.25; 0.75, 0.25, 0.25
  set Number of increments = 100
  set Write spring table = true
end
subsection Time
  set End time = 1
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = 0.5, 0.25, 0.25
end
"""

# mode -> (the displacement field of the right cell as functions of t, the loaded spring's
# candidates: the square's principal axes are a deterministic choice among equals)
MODES = {
    "tension": ("{d}*t; 0; 0", ["f_n"]),
    "shear": ("0; {d}*t; 0", ["f_1", "f_2"]),
    # a rotation th t about the y axis through the facet's centroid (0.5, 0.25, 0.25):
    # u = th t e_y x (x - P) (about the nucleus it would shear the facet too)
    "bending": ("{d}*t*(z - 0.25); 0; -{d}*t*(x - 0.5)", ["m_1", "m_2"]),
    # ... about the x axis (through the centroid and the nuclei)
    "torsion": ("0; -{d}*t*(z - 0.25); {d}*t*(y - 0.25)", ["m_t"]),
}


def run(hysteron, workdir, law, mode):
    motion, candidates = MODES[mode]
    spring = candidates[0]
    limit = YIELD[spring] / STIFFNESS[spring]  # the elastic limit of the deformation
    directory = os.path.join(workdir, f"{law.replace(' ', '_')}_{mode}")
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(E=E, NU=NU, SIGMA_Y=SIGMA_Y, law=law, motion=motion.format(d=repr(10 * limit))))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        return [f"{law}, {mode}: exit {p.returncode}: {p.stderr[-1500:]}"], None

    def table(name):
        with open(os.path.join(directory, "output", name)) as f:
            return list(csv.DictReader(f))
    springs, probe, energy, newton = table("springs.csv"), table("probe_0.csv"), table("energy.csv"), table("newton.csv")
    failures = []
    last = springs[-1]
    # The loaded spring: the candidate with the largest force (the square's axes).
    spring = max(candidates, key=lambda c: abs(float(last[c])))
    yield_value = YIELD[spring]
    force = abs(float(last[spring]))
    if abs(force / yield_value - 1) > 0.01:
        failures.append(f"{law}, {mode}: {spring} = {force:.6g} against the yield value {yield_value:.6g}")
    peak = max(abs(float(r[spring])) for r in probe)
    if peak > yield_value * (1 + 1e-9):
        failures.append(f"{law}, {mode}: {spring} reaches {peak:.9g} > {yield_value:.9g}")
    first = probe[1]
    secant = float(first[spring]) / float(last[DEFORMATION[spring]]) * 100  # the deformation is linear in t
    if abs(secant / STIFFNESS[spring] - 1) > 5e-3:
        failures.append(f"{law}, {mode}: first secant stiffness {secant:.6g} against k = {STIFFNESS[spring]:.6g}")
    others = max(abs(float(last[c])) / YIELD[c] for c in YIELD if c != spring)
    if others > 1e-9:
        failures.append(f"{law}, {mode}: the other springs carry {others:.3g} of their yield values")
    iterations = max(int(r["iteration"]) for r in newton)
    work = max(abs(float(r["boundary_work"])) for r in energy)
    balance = max(abs(float(r["balance"])) for r in energy)
    if balance > 1e-8 * work:
        failures.append(f"{law}, {mode}: energy balance {balance:.3g} J of {work:.6g} J")
    line = (f"{law:26s} {mode:8s} {spring}: {force:.9g} = {force / yield_value:.9f} of {yield_value:.6g}; first "
            f"secant {secant / STIFFNESS[spring]:.6f} k; others {others:.1e}; <= {iterations} iterations; "
            f"balance {balance / max(work, 1e-300):.1e} of {work:.4g} J")
    return failures, line


def interaction(hysteron, workdir):
    """The coupled law under proportional tension and torsion, delta_n / phi_n = T_y / N_y:
    the hysteretic forces saturate on Phi = 1 where its gradient (F_i / F_y,i^2) is along the
    deformation rate, N / N_y = T / T_y = 1 / sqrt(2) (doc/rbsn_coupled_springs.md; the uncoupled
    springs would give Phi = sqrt(2))."""
    d = 10 * YIELD["f_n"] / STIFFNESS["f_n"]
    theta = d * YIELD["f_n"] / YIELD["m_t"]
    directory = os.path.join(workdir, "coupled_tension_torsion")
    os.makedirs(directory, exist_ok=True)
    motion = f"{d!r}*t; -{theta!r}*t*(z - 0.25); {theta!r}*t*(y - 0.25)"
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(E=E, NU=NU, SIGMA_Y=SIGMA_Y, law="coupled", motion=motion))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        return [f"coupled, tension + torsion: exit {p.returncode}: {p.stderr[-1500:]}"]
    with open(os.path.join(directory, "output", "probe_0.csv")) as f:
        probe = list(csv.DictReader(f))
    failures = []
    phi = [math.sqrt(sum((float(r[c]) / YIELD[c]) ** 2 for c in YIELD)) for r in probe]
    n, t = float(probe[-1]["f_n"]) / YIELD["f_n"], float(probe[-1]["m_t"]) / YIELD["m_t"]
    print(f"coupled, tension + torsion: N / N_y = {n:.7f}, T / T_y = {t:.7f} (1 / sqrt(2) = "
          f"{1 / math.sqrt(2):.7f}), largest Phi {max(phi):.9f}")
    if abs(n - 1 / math.sqrt(2)) > 1e-4 or abs(t - 1 / math.sqrt(2)) > 1e-4:
        failures.append(f"coupled, tension + torsion: N / N_y = {n:.6f}, T / T_y = {t:.6f}")
    if max(phi) > 1 + 1e-6:
        failures.append(f"coupled, tension + torsion: Phi = {max(phi):.9f} > 1")
    return failures


def main():
    hysteron, workdir = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    failures = interaction(hysteron, workdir)
    for law in ("uncoupled", "coupled", "elastic-perfectly-plastic"):
        for mode in MODES:
            f, line = run(hysteron, workdir, law, mode)
            failures += f
            if line:
                print(line)
    if failures:
        sys.exit("FAILED:\n  " + "\n  ".join(failures))
    print("passed: every spring of the facet reaches its yield value under every law")


if __name__ == "__main__":
    main()
