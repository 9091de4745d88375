#!/usr/bin/python3
"""RBSN: large networks, from the parameter file to the results, on one core.

Two scenes at growing cell counts, each run --repeats times (median), pinned to one core:

(1) Elastic plate (benchmarks/rbsn/plate_uniaxial.prm): 2 m x 0.5 m, k_t = k_n, nu = 0, rollers
    and an end displacement; the exact solution is the uniform strain eps = 5e-4. One static
    solve and the VTU output. Error: the reaction against E eps t H = 5 kN (the network's
    solution is exact but for the boundary cells, whose rotations the rollers and the end leave
    free: a support acts at the nucleus, not at the centroid of the cell's boundary piece);
    second value: the largest |u_x - eps x| at four probe points against eps L (a probe reads the
    rigid motion of its cell: the O(d_m) error of piecewise-rigid cells). Target: 100,000 cells
    in under 20 s.
(2) Plastic cantilever of §5.1 (prm/rbsn_cantilever_plastic.prm: the tip moved 50 mm in 100
    increments, coupled Bouc-Wen springs, backward Euler, Newton), uniform nuclei on both ends.
    Error: the load at 50 mm against P_u = 30 kN. Target: 10,000 cells in under 60 s.

The largest network of each scene also runs on 2 MPI ranks (both cores, not pinned; one run), with
each distributed solver (UMFPACK gathered on rank 0, Amesos KLU and MUMPS), and on 1 and 2 ranks
with the iterative solvers (cg for the plate, gmres for the cantilever, with algebraic multigrid),
which show the memory of the distributed network per rank; the other 1-rank runs use UMFPACK.

Time: the whole process (MPI start-up, set-up, steps, output), measured around the call, and
hysteron's own timer sections (set-up, steps, output) of the median run. Memory: the peak
resident set of each rank (/usr/bin/time inside mpirun); per cell, the slope between the two largest runs of a scene (the
libraries' fixed ~100 MB drop out). Writes CSV and Markdown to --output (default
doc/benchmarks/rbsn_large).

Usage: benchmarks/rbsn_large.py BUILD_DIR [--repeats 3] [--quick] [--output PREFIX]
"""
import argparse
import csv
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from rbsn_run_time import end_points, rows_of, set_entry, P_U  # noqa: E402

EPS, LENGTH, REACTION = 5e-4, 2.0, 1e9 * 5e-4 * 0.02 * 0.5


def run(hysteron, directory, text, ranks=1):
    """One run: wall time, peak RSS [MB], the summary's counts and the timer sections."""
    os.makedirs(directory, exist_ok=True)
    shutil.rmtree(os.path.join(directory, "output"), ignore_errors=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    rss_file = os.path.join(directory, "peak_rss.txt")
    if os.path.exists(rss_file):
        os.remove(rss_file)
    # GNU time inside mpirun: one peak resident set per rank.
    command = ["/usr/bin/time", "-a", "-o", rss_file, "-f", "RSS %M", hysteron, "scene.prm"]
    if ranks > 1:
        command = ["mpirun", "-np", str(ranks)] + command
    elif shutil.which("taskset"):
        command = ["taskset", "-c", "1"] + command
    start = time.perf_counter()
    p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        raise RuntimeError(f"{directory}: exit {p.returncode}\n{p.stderr}")
    m = re.search(r"finished in [0-9.eE+-]+ s \((\d+) cells, (\d+) facets, (\d+) steps, (\d+) Newton "
                  r"iterations, (\d+) factorizations", p.stdout)
    names = {"set-up": "setup_s", "steps": "steps_s", "output": "output_s"}
    sections = dict(setup_s=0.0, steps_s=0.0, output_s=0.0)
    for name, seconds in re.findall(r"\|\s*(set-up|steps|output)\s*\|\s*\d+\s*\|\s*([0-9.]+)s", p.stdout):
        sections[names[name]] = float(seconds)
    per_rank = [float(v) / 1024 for v in re.findall(r"RSS (\d+)", open(rss_file).read())]
    return dict(wall=wall, rss=max(per_rank), rss_per_rank=per_rank, cells=int(m.group(1)), facets=int(m.group(2)), steps=int(m.group(3)),
                newton=int(m.group(4)), factorizations=int(m.group(5)), **sections)


def median_run(hysteron, directory, text, repeats, ranks=1):
    runs = sorted((run(hysteron, directory, text, ranks) for _ in range(repeats)), key=lambda r: r["wall"])
    return runs[len(runs) // 2]


def label(ranks, solver):
    """The solver column: UMFPACK on one rank; under MPI the distributed solver; cg / gmres + AMG."""
    if solver in ("cg", "gmres"):
        return solver + " + AMG"
    if ranks == 1:
        return "UMFPACK"
    return "UMFPACK on rank 0" if solver == "UMFPACK" else solver


def solver_entries(solver):
    """The RBSN entries that choose @p solver."""
    if solver in ("cg", "gmres"):
        return f"  set Linear solver = {solver}"
    return f"  set Distributed direct solver = {solver}"


def plate(hysteron, work, d_m, repeats, ranks=1, solver="UMFPACK"):
    with open(os.path.join(ROOT, "benchmarks", "rbsn", "plate_uniaxial.prm")) as f:
        text = set_entry(f.read(), "Minimum distance", d_m)
    text = text.replace("  set Analysis = static", "  set Analysis = static\n" + solver_entries(solver))
    d = os.path.join(work, f"plate_{d_m:g}_{ranks}_{solver}")
    r = median_run(hysteron, d, text, repeats, ranks)
    error = 0.0
    for i in range(4):
        last = rows_of(os.path.join(d, "output", f"probe_{i}.csv"))[-1]
        x = float(last["x_x"]) - float(last["u_x"])
        error = max(error, abs(float(last["u_x"]) - EPS * x) / (EPS * LENGTH))
    reaction = float(rows_of(os.path.join(d, "output", "reactions.csv"))[-1]["right_x"])
    # The network's solution is exact up to a boundary layer; a probe reads the rigid motion of
    # its cell, eps x_nucleus, so |u_x - eps x| at a point is the O(d_m) piecewise-rigid error.
    return dict(scene="elastic plate, uniform strain", d_m=d_m, ranks=ranks,
                solver=label(ranks, solver), **r,
                quantity="reaction error; max |u_x - eps x| / (eps L) at the probes", value=error,
                error=abs(reaction / REACTION - 1))


def cantilever(hysteron, work, d_m, repeats, ranks=1, solver="UMFPACK"):
    with open(os.path.join(ROOT, "prm", "rbsn_cantilever_plastic.prm")) as f:
        text = f.read()
    text = set_entry(text, "Minimum distance", d_m)
    text = text.replace("  set Spring law = coupled", "  set Spring law = coupled\n" + solver_entries(solver))
    text = set_entry(text, "Additional points", end_points(d_m, 0, 0.1))
    text = set_entry(text, "Write VTU", "false")
    d = os.path.join(work, f"cantilever_{d_m:g}_{ranks}_{solver}")
    r = median_run(hysteron, d, text, repeats, ranks)
    load = abs(float(rows_of(os.path.join(d, "output", "reactions.csv"))[-1]["tip_y"]))
    return dict(scene="plastic cantilever (§5.1), 100 increments", d_m=d_m, ranks=ranks,
                solver=label(ranks, solver), **r,
                quantity="load at 50 mm [N]", value=load, error=abs(load / P_U - 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--output", default=os.path.join(ROOT, "doc", "benchmarks", "rbsn_large"))
    args = parser.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    plate_dm = [0.0104, 0.0052] if args.quick else [0.0104, 0.0052, 0.0026]
    cantilever_dm = [0.01] if args.quick else [0.0052, 0.0026]
    repeats = 1 if args.quick else args.repeats
    rows = []
    with tempfile.TemporaryDirectory(prefix="rbsn_large_") as work:
        for d_m in plate_dm:
            rows.append(plate(hysteron, work, d_m, repeats))
            print(rows[-1], flush=True)
        for d_m in cantilever_dm:
            rows.append(cantilever(hysteron, work, d_m, repeats))
            print(rows[-1], flush=True)
        # The largest of each on 2 ranks (both cores; no pinning), with both Amesos solvers,
        # one run each (the 2-rank cantilever takes minutes).
        for solver in ("UMFPACK", "Amesos_Klu", "Amesos_Mumps"):
            rows.append(plate(hysteron, work, plate_dm[-1], 1, 2, solver))
            print(rows[-1], flush=True)
            rows.append(cantilever(hysteron, work, cantilever_dm[-1], 1, 2, solver))
            print(rows[-1], flush=True)
        # The distributed network with the distributed iterative solvers: the memory per rank.
        for ranks in (1, 2):
            rows.append(plate(hysteron, work, plate_dm[-1], 1, ranks, "cg"))
            print(rows[-1], flush=True)
            rows.append(cantilever(hysteron, work, cantilever_dm[-1], 1, ranks, "gmres"))
            print(rows[-1], flush=True)
    # Memory per cell: the slope of the peak RSS between the two largest runs of each scene.
    for r in rows:
        r["kb_per_cell"] = ""
    for scene in dict.fromkeys(r["scene"] for r in rows):
        runs = [r for r in rows if r["scene"] == scene and r["ranks"] == 1 and r["solver"] == "UMFPACK"]
        for r in runs:
            r["kb_per_cell"] = ""
        if len(runs) >= 2:
            a, b = runs[-2], runs[-1]
            b["kb_per_cell"] = f"{1024 * (b['rss'] - a['rss']) / (b['cells'] - a['cells']):.2f}"
    columns = ["scene", "d_m", "ranks", "solver", "cells", "facets", "newton", "factorizations", "wall", "setup_s", "steps_s",
               "output_s", "rss", "kb_per_cell", "value", "error"]
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in r.items()})
    header = ("| scene | d_m [m] | ranks | solver | cells | facets | Newton iterations | factorizations | total [s] | set-up [s] "
              "| steps [s] | output [s] | peak RSS per rank [MB] | memory per cell [kB] | error | second value |")
    lines = [header, "|" + "---|" * (header.count("|") - 1)]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['d_m']:g} | {r['ranks']} | {r['solver']} | {r['cells']:,} | {r['facets']:,} | {r['newton']} | "
                     f"{r['factorizations']} | {r['wall']:.2f} | {r['setup_s']:.2f} | {r['steps_s']:.2f} | "
                     f"{r['output_s']:.2f} | {', '.join(f'{m:.0f}' for m in r['rss_per_rank'])} | {r['kb_per_cell'] or '–'} | {r['error']:.2g} | "
                     f"{r['value']:.4g} |")
    with open(args.output + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))

if __name__ == "__main__":
    main()
