#!/usr/bin/env python3
"""FEM convergence on the elastic cantilever with a known exact solution (issue 5).

The plane-stress cantilever of Timoshenko & Goodier (Theory of Elasticity, §21): length L,
depth D, thickness b, shear load P at x = L, I = b D^3 / 12. Its exact displacement field
(y measured from the mid-plane)

  u_x =  P y / (6 E I) [ (6 L - 3 x) x + (2 + nu) (y^2 - D^2 / 4) ]
  u_y = -P / (6 E I) [ 3 nu y^2 (L - x) + (4 + 5 nu) D^2 x / 4 + (3 L - x) x^2 ]

gives sigma_xx = P (L - x) y / I, sigma_yy = 0, sigma_xy = -P / (2 I) (D^2 / 4 - y^2): the
faces y = +-D/2 are free and the end x = L carries the parabolic shear of total -P. It is
prescribed on both ends (FEM displacement conditions as functions of x, y), so the discrete
problem converges to it with the rates of a smooth solution:
  * the tip force (the reaction of the end x = L, exactly -P): error O(h^2p) (energy-like);
  * the displacement at the quadrature points (quadrature_points.csv), RMS of |u_h - u| over
    them relative to the tip deflection: O(h^(p+1)) (a discrete L2 norm).
Assertions: the observed rates on the two finest pairs of meshes lie within the bands given in
RATES below; the finest errors are below stated bounds; and the exact tip deflection agrees with
Timoshenko beam theory with shear, PL^3/(3EI) + (4 + 5 nu) P L / (2 E b D), and lies within 1.5 %
of PL^3/(3EI) + P L / (kappa G A), kappa = 5/6 (the two beam theories differ in the end condition).

Usage: cantilever_convergence.py HYSTERON WORKDIR [--markdown FILE] [--plot FILE.png]
"""
import csv
import math
import os
import subprocess
import sys
import time

L, D, B = 1.0, 0.1, 0.05
E, NU, P = 210e9, 0.3, 1000.0
I = B * D**3 / 12
# The probe: an interior point that is a node of none of the meshes.
XP, YP = L / 3, D / 6

UX = f"{P}*y/(6*{E}*{I})*((6*{L}-3*x)*x+(2+{NU})*(y^2-{D}^2/4))*t"
UY = f"-{P}/(6*{E}*{I})*(3*{NU}*y^2*({L}-x)+(4+5*{NU})*{D}^2*x/4+(3*{L}-x)*x^2)*t"

SCENE = """set Dimension = 2
set Method = fem
set Body names = beam
set Boundary names = root, tip
subsection Material
  set Model = linear elastic
  set Young's modulus = {E}
  set Poisson's ratio = {NU}
  set Stress state = plane stress
end
subsection Body beam
  set Shape = rectangle(0, -{half}, {L}, {half})
  set Thickness = {B}
end
subsection Boundary root
  set Type = displacement
  set Faces = x-
  set Displacement = {UX}; {UY}
end
subsection Boundary tip
  set Type = displacement
  set Faces = x+
  set Displacement = {UX}; {UY}
end
subsection FEM
  set Degree = {p}
  set Number of increments = 1
  set Write quadrature point table = true
  subsection Mesh
    set Cell size = {h}
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = {xp}, {yp}
end
"""

# (p, which): accepted band of the observed convergence rate.
RATES = {(1, "force"): (1.9, 2.1), (2, "force"): (3.6, 4.3),
         (1, "displacement"): (1.9, 2.1), (2, "displacement"): (2.8, 3.2)}


def exact_ux(x, y):
    return P * y / (6 * E * I) * ((6 * L - 3 * x) * x + (2 + NU) * (y * y - D * D / 4))


def exact_uy(x, y):
    return -P / (6 * E * I) * (3 * NU * y * y * (L - x) + (4 + 5 * NU) * D * D * x / 4 + (3 * L - x) * x * x)


def run_case(hysteron, workdir, p, h):
    directory = os.path.join(workdir, f"p{p}_h{h:g}")
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(E=E, NU=NU, L=L, B=B, half=D / 2, UX=UX, UY=UY, p=p, h=h, xp=XP, yp=YP))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.perf_counter()
    subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=directory, env=env, check=True)
    seconds = time.perf_counter() - start
    with open(os.path.join(directory, "output", "reactions.csv")) as f:
        last = list(csv.DictReader(f))[-1]
    force_error = abs(float(last["tip_y"]) + P) / P
    squares, count = 0.0, 0
    with open(os.path.join(directory, "output", "quadrature_points.csv")) as f:
        for row in csv.DictReader(f):
            x = float(row["x_x"]) - float(row["u_x"])
            y = float(row["x_y"]) - float(row["u_y"])
            squares += (float(row["u_x"]) - exact_ux(x, y)) ** 2 + (float(row["u_y"]) - exact_uy(x, y)) ** 2
            count += 1
    displacement_error = math.sqrt(squares / count) / abs(exact_uy(L, 0.0))
    return force_error, displacement_error, seconds


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    markdown = sys.argv[sys.argv.index("--markdown") + 1] if "--markdown" in sys.argv else None
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    sizes = {1: [D / 2, D / 4, D / 8, D / 16], 2: [D / 1, D / 2, D / 4, D / 8]}
    results = {(p, h): run_case(hysteron, workdir, p, h) for p in sizes for h in sizes[p]}

    failures = []
    lines = ["| p | h [m] | cells | tip force error | rate | displacement error (RMS at quadrature points) | rate | run time [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for p in sizes:
        previous = None
        for h in sizes[p]:
            force, displacement, seconds = results[(p, h)]
            rates = ["", ""]
            if previous:
                rates = [f"{math.log(previous[k] / (force, displacement)[k]) / math.log(2):.2f}" for k in (0, 1)]
            cells = round(L / h) * round(D / h)
            lines.append(f"| {p} | {h:g} | {cells} | {force:.3e} | {rates[0]} | {displacement:.3e} | {rates[1]} | {seconds:.2f} |")
            previous = (force, displacement)
        for k, which in ((0, "force"), (1, "displacement")):
            low, high = RATES[(p, which)]
            for coarse, fine in zip(sizes[p][1:-1], sizes[p][2:]):
                rate = math.log(results[(p, coarse)][k] / results[(p, fine)][k]) / math.log(2)
                print(f"p = {p}: {which} error rate h = {coarse:g} -> {fine:g}: {rate:.3f}")
                if not low <= rate <= high:
                    failures.append(f"p = {p}: {which} rate {rate:.3f} outside [{low}, {high}]")
    table = "\n".join(lines)
    print(table)
    # The finest meshes are accurate in absolute terms too.
    for p, bound in ((1, 2e-3), (2, 1e-5)):
        force = results[(p, sizes[p][-1])][0]
        if not force < bound:
            failures.append(f"p = {p}: finest tip force error {force:.3e} not below {bound}")

    # Beam theory: the exact tip deflection is PL^3/(3EI) + (4 + 5 nu) P L / (2 E b D); the
    # Timoshenko beam with kappa = 5/6 differs only in the shear term of the end condition.
    G = E / (2 * (1 + NU))
    bending = P * L**3 / (3 * E * I)
    exact_tip = -exact_uy(L, 0.0)
    goodier = bending + (4 + 5 * NU) * P * L / (2 * E * B * D)
    timoshenko = bending + P * L / (5.0 / 6.0 * G * B * D)
    print(f"tip deflection: exact {exact_tip:.6e}, T&G formula {goodier:.6e}, Timoshenko beam "
          f"(kappa 5/6) {timoshenko:.6e}, Euler-Bernoulli {bending:.6e}")
    if abs(exact_tip / goodier - 1) > 1e-12:
        failures.append("exact tip deflection differs from the Timoshenko-Goodier formula")
    if abs(exact_tip / timoshenko - 1) > 0.015:
        failures.append(f"exact tip deflection {exact_tip:.6e} not within 1.5 % of Timoshenko beam theory")

    if markdown:
        with open(markdown, "w") as f:
            f.write(table + "\n\n" + f"Tip deflection: exact (Timoshenko-Goodier) {exact_tip:.6e} m, "
                    f"Timoshenko beam (kappa = 5/6) {timoshenko:.6e} m, Euler-Bernoulli {bending:.6e} m.\n")
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, k, title in ((axes[0], 0, "tip force (reaction at x = L)"),
                             (axes[1], 1, "displacement, RMS over the quadrature points")):
            for p, marker in ((1, "o-"), (2, "s-")):
                ax.loglog(sizes[p], [results[(p, h)][k] for h in sizes[p]], marker, label=f"Q{p}")
            ax.set_xlabel("cell size h [m]")
            ax.set_ylabel("relative error")
            ax.set_title(title)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend()
        fig.suptitle("FEM, elastic cantilever against the exact solution (Timoshenko-Goodier)")
        fig.tight_layout()
        fig.savefig(plot, dpi=110)

    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("cantilever convergence: all assertions hold")


if __name__ == "__main__":
    main()
