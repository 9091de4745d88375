#!/usr/bin/python3
"""RBSN plastic cantilever (dissertation §5.1): collapse load of the uncoupled and the coupled
facet springs against beam theory, over meshes and seeds, with run times.

Scene: L = 1 m, h = 0.1 m, t = 0.05 m, E = 210 GPa, nu = 0.3, plane stress, Bouc-Wen
sigma_y = 240 MPa, a = 0, n = 8, beta = gamma = 0.5, backward Euler; the cells whose nuclei lie
on x = 0 are fixed, the cells on x = 1 are moved down by 0.05 m (y only, 100 increments); the
nuclei on both ends are placed uniformly (spacing <= d_m), the rest are random (as in
tests/rbsn/cantilever_mesh_study.py). Beam theory: P_y = sigma_y t h^2 / (6 L) = 20 kN,
P_u = sigma_y t h^2 / (4 L) = 30 kN; the FEM (prm/fem_cantilever_plastic.prm, Q2) reaches
30.97 kN at 30 mm (the clamp's restraint).

Variants: `uncoupled` (three uniaxial laws, M_y = 0.25 sigma_y t l^2) and `coupled`
(eq. 3.38-3.42, doc/rbsn_coupled_springs.md) with the moment yield factor 1/4 (the facet's
plastic moment) and 1/6 (its elastic moment); F_y,n = sigma_y t l and F_y,t = F_y,n / sqrt(3)
throughout. Reported: the reaction at 30 mm and at 50 mm (the plateau: a = 0), Newton
iterations, and the run time ("finished in", i.e. set-up + steps, without process start), the
median of --repeats runs.

Writes OUT/rbsn_cantilever_plastic.md and .csv (OUT = doc/benchmarks; one CSV row per run, error =
|P(50 mm) - P_u| / P_u).

Usage: rbsn_cantilever_plastic.py HYSTERON [--workdir /tmp/rbsn_cantilever] [--repeats 3]
                                  [--out DIR] [--dm 0.05,0.03,0.02,0.015,0.01] [--seeds 1,2,3]
"""
import argparse
import csv
import math
import os
import platform
import re
import statistics
import subprocess

SCENE = """set Dimension = 2
set Method = rbsn
set Body names = beam
set Boundary names = clamp, tip
set Random seed = {seed}
subsection Material
  set Model = bouc-wen
  set Young's modulus = 210e9
  set Poisson's ratio = 0.3
  set Density = 7850
  set Stress state = plane stress
  subsection Bouc-Wen
    set Yield stress = 240e6
    set Post-yield stiffness ratio = 0
    set Smoothness n = 8
    set Beta = 0.5
    set Gamma = 0.5
    set Integrator = backward euler
  end
end
subsection Body beam
  set Shape = rectangle(0, 0, 1, 0.1)
  set Thickness = 0.05
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Boundary tip
  set Type = displacement
  set Region = rectangle(0.999, -1, 1.001, 1)
  set Components = y
  set Displacement = 0; -0.05*t
end
subsection RBSN
  set Minimum distance = {d_m}
  set Points on the boundary = false
  set Additional points = {points}
  set Number of increments = 100
  set Spring law = {law}
  set Moment yield factor = {factor}
end
subsection Time
  set End time = 1
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""

VARIANTS = [("uncoupled", 0.25, "uncoupled, M_y = sigma_y t l^2 / 4"),
            ("coupled", 0.25, "coupled, M_y = sigma_y t l^2 / 4"),
            ("coupled", 1 / 6, "coupled, M_y = sigma_y t l^2 / 6")]


def end_points(d_m):
    n = max(1, math.ceil(0.1 / d_m - 1e-9))
    return "; ".join(f"{x}, {j * 0.1 / n:.12g}" for x in (0, 1) for j in range(n + 1))


def run_case(hysteron, workdir, d_m, seed, law, factor, repeats):
    directory = os.path.join(workdir, f"{law}_{factor:.4f}_dm{d_m:g}_seed{seed}")
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(seed=seed, d_m=d_m, points=end_points(d_m), law=law, factor=factor))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    times = []
    for _ in range(repeats):
        p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=env, check=True,
                           capture_output=True, text=True)
        m = re.search(r"finished in ([0-9.e+-]+) s \((\d+) cells, (\d+) facets, (\d+) steps, (\d+) Newton", p.stdout)
        times.append(float(m.group(1)))
    cells, facets, newton = int(m.group(2)), int(m.group(3)), int(m.group(5))
    with open(os.path.join(directory, "output", "reactions.csv")) as f:
        rows = list(csv.DictReader(f))
    at30 = min(rows, key=lambda r: abs(float(r["time"]) - 0.6))
    return {"cells": cells, "facets": facets, "newton": newton, "time": statistics.median(times),
            "P30": -float(at30["tip_y"]), "P50": -float(rows[-1]["tip_y"])}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("hysteron")
    parser.add_argument("--workdir", default="/tmp/rbsn_cantilever")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "doc", "benchmarks"))
    parser.add_argument("--dm", default="0.05,0.03,0.02,0.015,0.01")
    parser.add_argument("--seeds", default="1,2,3")
    args = parser.parse_args()
    hysteron = os.path.abspath(args.hysteron)
    d_ms = [float(x) for x in args.dm.split(",")]
    seeds = [int(x) for x in args.seeds.split(",")]

    lines = ["| springs | d_m [m] | seed | cells | facets | P(30 mm) [kN] | P(50 mm) [kN] | P(50 mm) / 30 kN | Newton iterations | run time [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    summary = ["| springs | d_m [m] | mean P(50 mm) [kN] | min - max [kN] | mean / 30 kN | median run time [s] |",
               "|---|---|---|---|---|---|"]
    csv_rows = []
    for law, factor, label in VARIANTS:
        for d_m in d_ms:
            results = [run_case(hysteron, args.workdir, d_m, s, law, factor, args.repeats) for s in seeds]
            for s, r in zip(seeds, results):
                csv_rows.append({"springs": label, "law": law, "moment_factor": f"{factor:.6g}",
                                 "d_m": d_m, "seed": s, "cells": r["cells"], "facets": r["facets"],
                                 "newton": r["newton"], "time": r["time"], "P30": r["P30"],
                                 "P50": r["P50"], "error": abs(r["P50"] - 30e3) / 30e3})
                lines.append(f"| {label} | {d_m:g} | {s} | {r['cells']} | {r['facets']} | {r['P30'] / 1e3:.2f} | "
                             f"{r['P50'] / 1e3:.2f} | {r['P50'] / 30e3:.3f} | {r['newton']} | {r['time']:.3f} |")
            P = [r["P50"] / 1e3 for r in results]
            summary.append(f"| {label} | {d_m:g} | {statistics.mean(P):.2f} | {min(P):.2f} - {max(P):.2f} | "
                           f"{statistics.mean(P) / 30:.3f} | {statistics.median(r['time'] for r in results):.3f} |")
            print(summary[-1], flush=True)

    machine = f"{platform.machine()}, {os.cpu_count()} cores, {platform.processor() or 'unknown CPU'}"
    text = ("# RBSN plastic cantilever (§5.1): uncoupled vs coupled facet springs\n\n"
            "Generated by `benchmarks/rbsn_cantilever_plastic.py` (see its docstring for the scene). "
            f"Beam theory P_u = 30 kN; FEM Q2 30.97 kN at 30 mm. Run time: hysteron's \"finished in\" "
            f"(set-up + 100 steps), median of {args.repeats} runs, Release build, {machine}, "
            "shared machine (timings are indicative).\n\n## Summary (mean over the seeds)\n\n"
            + "\n".join(summary) + "\n\n## All runs\n\n" + "\n".join(lines) + "\n")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "rbsn_cantilever_plastic.md"), "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "rbsn_cantilever_plastic.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(csv_rows[0]))
        writer.writeheader()
        writer.writerows(csv_rows)
    print(text)


if __name__ == "__main__":
    main()
