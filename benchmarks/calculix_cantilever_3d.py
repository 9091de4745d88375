#!/usr/bin/python3
"""The 3D FEM against CalculiX on the same plastic cantilever, at equal meshes.

    taskset -c 1 calculix_cantilever_3d.py --hysteron build/hysteron [--ccx ccx] [--workdir DIR]
        [--out DIR] [--repeats 3] [--meshes 20x2x1,40x4x2] [--reference 80x8x4]

The problem: a steel cantilever 1 m x 0.1 m x 0.05 m (x along the beam, y the depth, z the
width), clamped at x = 0 (every node), its end face x = 1 m moved down by u_y = 30 mm in 20
equal increments (displacement control past the plastic hinge, the 3D form of the §5.1
cantilever). E = 210 GPa, nu = 0.3, von Mises with sigma_y = 240 MPa and linear isotropic
hardening of 5 % of E after yield (H = a E / (1 - a), a = 0.05).

  hysteron: Q2 hexahedra (27 Gauss points), the Bouc-Wen law with n = 32, beta = gamma = 0.5,
            isotropic (the smooth form of the same bilinear law), backward Euler, the default
            solver (MUMPS in 3D), 20 increments; Newton to 1e-8 of the force level (the
            default) and to 1e-3 (still tighter than CalculiX's default criterion).
  CalculiX: C3D20 (20-node hexahedra, 27 Gauss points: the same order as Q2 in the bending
            direction), *PLASTIC with the same hardening line, *STATIC, DIRECT with 20
            increments, its default solver (SPOOLES in Debian's calculix-ccx 2.20).

Quantities: the end force F_y at the first increment (elastic: both codes model the same
material, so its difference is the discretisation's) and at 30 mm (the plastic plateau; the
smooth Bouc-Wen knee and the bilinear one differ a little there). The reference of the elastic
force is hysteron's Q2 on the finest mesh (--reference); error = |F - F_ref| / F_ref.
Time = the wall time of the whole process (set-up, solve, output), one thread each
(OMP_NUM_THREADS=1 and CalculiX's CCX_NPROC_* = 1; run the script under taskset to pin both to
one core, as benchmarks/make_report.py does), the median of --repeats runs. Writes
WORKDIR/results.json, and the Markdown table to OUT/calculix_cantilever_3d.md (doc/benchmarks.md,
"FEM against CalculiX") and to the standard output.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

L, D, B = 1.0, 0.1, 0.05           # length, depth (y), width (z) [m]
E, NU, SIGMA_Y, A = 210e9, 0.3, 240e6, 0.05
H = A * E / (1 - A)                # isotropic hardening modulus after yield
U_TIP, INCREMENTS = 0.03, 20


def hysteron_scene(nx, tolerance):
    h = L / nx
    return f"""set Dimension = 3
set Method = fem
set Body names = beam
set Boundary names = clamp, tip
subsection Material
  set Model = bouc-wen
  set Young's modulus = {E}
  set Poisson's ratio = {NU}
  subsection Bouc-Wen
    set Yield stress = {SIGMA_Y}
    set Post-yield stiffness ratio = {A}
    set Smoothness n = 32
    set Beta = 0.5
    set Gamma = 0.5
    set Isotropic hardening fraction = 1
    set Integrator = backward euler
  end
end
subsection Body beam
  set Shape = box(0, {-D / 2}, 0, {L}, {D / 2}, {B})
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Boundary tip
  set Type = displacement
  set Faces = x+
  set Components = y
  set Displacement = 0; {-U_TIP} * t; 0
end
subsection FEM
  set Degree = 2
  set Number of increments = {INCREMENTS}
  subsection Newton
    set Tolerance = {tolerance}
  end
  subsection Mesh
    set Cell size = {h}
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def calculix_deck(nx, ny, nz):
    """C3D20 on the nx x ny x nz grid: nodes on the half-step lattice where at most one index
    is odd (corners and edge midpoints), Abaqus/CalculiX node order."""
    ids = {}
    lines = ["*HEADING", f"hysteron benchmark: plastic cantilever, C3D20 {nx}x{ny}x{nz}", "*NODE"]
    for k in range(2 * nz + 1):
        for j in range(2 * ny + 1):
            for i in range(2 * nx + 1):
                if (i % 2) + (j % 2) + (k % 2) <= 1:
                    ids[(i, j, k)] = len(ids) + 1
                    lines.append(f"{ids[(i, j, k)]}, {L * i / (2 * nx)!r}, {-D / 2 + D * j / (2 * ny)!r}, "
                                 f"{B * k / (2 * nz)!r}")
    corners = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2)]
    edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
    lines.append("*ELEMENT, TYPE=C3D20, ELSET=BEAM")
    e = 0
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                base = (2 * i, 2 * j, 2 * k)
                local = [tuple(b + c for b, c in zip(base, corner)) for corner in corners]
                local += [tuple((p + q) // 2 for p, q in zip(local[a], local[b])) for a, b in edges]
                e += 1
                nodes = [ids[p] for p in local]
                # at most 16 entries per line
                lines.append(f"{e}, " + ", ".join(map(str, nodes[:15])) + ",")
                lines.append(", ".join(map(str, nodes[15:])))
    clamp = [n for (i, j, k), n in ids.items() if i == 0]
    tip = [n for (i, j, k), n in ids.items() if i == 2 * nx]
    for name, nodes in (("CLAMP", clamp), ("TIP", tip)):
        lines.append(f"*NSET, NSET={name}")
        lines += [", ".join(map(str, nodes[s:s + 16])) for s in range(0, len(nodes), 16)]
    lines += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E}, {NU}", "*PLASTIC",
              f"{SIGMA_Y}, 0.0", f"{SIGMA_Y + H}, 1.0",
              "*SOLID SECTION, ELSET=BEAM, MATERIAL=STEEL",
              "*BOUNDARY", "CLAMP, 1, 3",
              "*STEP, NLGEOM=NO, INC=1000", "*STATIC, DIRECT", f"{1.0 / INCREMENTS}, 1.0",
              "*BOUNDARY", f"TIP, 2, 2, {-U_TIP}",
              "*NODE PRINT, NSET=TIP, TOTALS=ONLY", "RF", "*END STEP"]
    return "\n".join(lines) + "\n"


def run_timed(command, cwd, env):
    start = time.monotonic()
    p = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    elapsed = time.monotonic() - start
    if p.returncode != 0:
        sys.exit(f"{' '.join(command)} failed in {cwd} ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    return elapsed


def hysteron_forces(directory):
    with open(os.path.join(directory, "output", "reactions.csv")) as f:
        rows = [line.strip().split(",") for line in f if line.strip()]
    column = rows[0].index("tip_y")
    values = [(float(r[0]), -float(r[column])) for r in rows[1:]]
    return values[1][1] if values[0][0] == 0 else values[0][1], values[-1][1]


def calculix_forces(directory):
    text = open(os.path.join(directory, "cantilever.dat")).read()
    totals = re.findall(r"total force \(fx,fy,fz\) for set TIP and time\s+(\S+)\s*\n\s*(\S+)\s+(\S+)\s+(\S+)", text)
    if not totals:
        sys.exit(f"no TIP totals in {directory}/cantilever.dat")
    # F_y on the end face = the force that holds it at u_y (the reaction, with its sign).
    return -float(totals[0][2]), -float(totals[-1][2])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--hysteron", required=True)
    parser.add_argument("--ccx", default="ccx")
    parser.add_argument("--workdir", default="/tmp/calculix_bench")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--meshes", default="20x2x1,40x4x2")
    parser.add_argument("--reference", default="80x8x4")
    parser.add_argument("--out", default=None, help="directory of calculix_cantilever_3d.md")
    args = parser.parse_args()
    if shutil.which(args.ccx) is None:
        sys.exit(f"'{args.ccx}' not found: CalculiX is Debian's calculix-ccx (scripts/setup.sh installs it)")
    hysteron = os.path.abspath(args.hysteron)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1",
               CCX_NPROC_STIFFNESS="1", CCX_NPROC_RESULTS="1")
    meshes = [tuple(map(int, m.split("x"))) for m in args.meshes.split(",")]
    reference = tuple(map(int, args.reference.split("x")))
    results = []
    # hysteron at its default Newton tolerance (1e-8 of the force level) and at 1e-3, still
    # tighter than CalculiX's default (a residual below 0.5 % of the mean nodal force).
    variants = [("hysteron", 1e-8), ("hysteron", 1e-3), ("calculix", None)]
    for code, tolerance in variants:
        for mesh in meshes + ([reference] if (code, tolerance) == ("hysteron", 1e-8) else []):
            directory = os.path.join(args.workdir, f"{code}_{tolerance}_{'x'.join(map(str, mesh))}")
            shutil.rmtree(directory, ignore_errors=True)
            os.makedirs(directory)
            if code == "hysteron":
                with open(os.path.join(directory, "scene.prm"), "w") as f:
                    f.write(hysteron_scene(mesh[0], tolerance))
                command = [hysteron, "--quiet", "scene.prm"]
            else:
                with open(os.path.join(directory, "cantilever.inp"), "w") as f:
                    f.write(calculix_deck(*mesh))
                command = [args.ccx, "-i", "cantilever"]
            repeats = 1 if mesh == reference else args.repeats
            times = [run_timed(command, directory, env) for _ in range(repeats)]
            first, last = (hysteron_forces if code == "hysteron" else calculix_forces)(directory)
            results.append(dict(code=code, tolerance=tolerance, mesh="x".join(map(str, mesh)),
                                time=statistics.median(times),
                                times=times, elastic_force=first, plastic_force=last))
            print(f"{code:9s} {tolerance or '':6} {results[-1]['mesh']:8s} {results[-1]['time']:8.2f} s  "
                  f"F(1.5 mm) = {first:.6e} N  F(30 mm) = {last:.6e} N", flush=True)
    ref = next(r for r in results if r["code"] == "hysteron" and r["tolerance"] == 1e-8 and
               r["mesh"] == "x".join(map(str, reference)))
    with open(os.path.join(args.workdir, "results.json"), "w") as f:
        json.dump(dict(results=results, reference=ref["mesh"], affinity=sorted(os.sched_getaffinity(0))), f,
                  indent=1)
    lines = [f"reference: hysteron Q2 {ref['mesh']}, F(1.5 mm) = {ref['elastic_force']:.6e} N; cores "
             f"{sorted(os.sched_getaffinity(0))}; median of {args.repeats} runs", "",
             "| code, element | Newton tolerance | mesh | run time [s] | F at 1.5 mm [N] | error | F at 30 mm [N] |",
             "|---|---|---|---:|---:|---:|---:|"]
    for r in results:
        element = "hysteron, Q2 + Bouc-Wen (n = 32)" if r["code"] == "hysteron" else "CalculiX 2.20, C3D20 + *PLASTIC"
        criterion = f"{r['tolerance']:g} of the force level" if r["tolerance"] else "default (0.5 % of the mean force)"
        error = abs(r["elastic_force"] - ref["elastic_force"]) / ref["elastic_force"]
        lines.append(f"| {element} | {criterion} | {r['mesh']} | {r['time']:.2f} | {r['elastic_force']:.6g} | "
                     f"{'reference' if r is ref else f'{error:.2e}'} | {r['plastic_force']:.6g} |")
    print("\n" + "\n".join(lines))
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "calculix_cantilever_3d.md"), "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
