#!/usr/bin/python3
"""RBSN in 3D: elastic and plastic networks from the parameter file to the results, on one core.

Two scenes at growing cell counts, each run --repeats times (median), pinned to one core
(taskset -c 1), Release build:

(a) Elastic box (benchmarks/rbsn/box_uniaxial_3d.prm): 1 m x 0.5 m x 0.5 m, k_s = k_n, nu = 0,
    the cells on the faces moved with the uniaxial strain eps = 5e-4 (rotations included); the
    exact solution is that uniform strain in every cell and facet. One static solve and the VTU
    output (at t = 0 and t = 1). Error: the reaction of the face x = 1 m against
    E eps H W = 125 kN (round-off for the direct solver, the iterative solver's tolerance for
    CG); second value: the largest cell rotation at four probe points, relative to eps (exact: 0).
    Solvers: `Linear solver = cg` (ML AMG with the 6 rigid-body modes per cell) at every size,
    the direct solver (UMFPACK) up to the largest size (--direct-max-cells). Target: 20,000
    cells in under 60 s.
(b) Plastic cantilever (benchmarks/rbsn/cantilever_plastic_3d.prm): 1 m x 0.1 m x 0.1 m steel,
    coupled Bouc-Wen facet springs, the tip moved 50 mm in 100 increments, Newton with the
    consistent tangent. Error: the load at 50 mm against P_u = sigma_y b h^2 / (4 L) = 60 kN
    (the clamp's restraint puts the 3D plateau about 10 % above it: doc/rbsn3d.md); second value:
    that load [N]. Solvers: the direct one (UMFPACK, exact Newton: the default) and GMRES + ML
    with the preconditioner kept over Newton iterations and increments (`Tangent reuse tolerance =
    0.05`; still exact Newton: GMRES solves with the current tangent).
    Target: about 5,000 cells in under 3 minutes.

The largest network of each scene and solver also runs on 2 MPI ranks (both cores, one run; the
direct solver gathers the matrix on rank 0: `Distributed direct solver = UMFPACK`); the speed-up
is the 1-rank median over the 2-rank time.

Time: the whole process (MPI start-up, set-up, steps, output), measured around the call, its CPU
time (user + system, all ranks; less sensitive to other work on a shared machine than the wall
time), and hysteron's own timer sections (set-up, steps, output) of the median run. Runs whose time
exceeds --long seconds run once. Memory: the peak resident set (/usr/bin/time); per cell, the
slope between the two largest 1-rank runs of a scene and solver (the libraries' fixed ~100 MB
drop out). Writes CSV, Markdown and a PNG (time and memory against cells, log-log) to --output
(default doc/benchmarks/rbsn_3d).

Usage: benchmarks/rbsn_3d.py BUILD_DIR [--repeats 3] [--quick] [--output PREFIX]
"""
import argparse
import csv
import math
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
from rbsn_run_time import rows_of, set_entry  # noqa: E402

EPS, REACTION = 5e-4, 1e9 * 5e-4 * 0.5 * 0.5     # the box: E eps H W = 125 kN
P_U = 240e6 * 0.1 * 0.1**2 / (4 * 1.0)           # the cantilever: 60 kN
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
LOADS = []   # the 1-minute load average before every run (the machine is shared)


def with_solver(text, solver):
    """`Linear solver` in the scene's RBSN section: direct, cg, gmres, or gmres-reuse (GMRES with
    `Tangent reuse tolerance = 0.05`: the ML hierarchy is kept while the tangent changes by at most
    5 %; every Newton iteration still solves with the current tangent)."""
    entries = f"  set Linear solver = {solver.split('-')[0]}\n"
    if solver.endswith("-reuse"):
        entries += "  set Tangent reuse tolerance = 0.05\n"
    return text.replace("subsection RBSN\n", "subsection RBSN\n" + entries, 1)


def run(hysteron, directory, text, ranks=1):
    """One run: wall time, peak RSS [MB], the summary's counts and the timer sections."""
    os.makedirs(directory, exist_ok=True)
    shutil.rmtree(os.path.join(directory, "output"), ignore_errors=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    timer = ["/usr/bin/time", "-f", "RSS %M CPU %U %S"]
    command = timer + [hysteron, "scene.prm"]
    if ranks > 1:
        # Both cores: the 2 ranks are not pinned (the machine has 2).
        command = timer + ["mpirun", "--oversubscribe", "-np", str(ranks), hysteron, "scene.prm"]
        command = ["taskset", "-c", f"0-{os.cpu_count() - 1}"] + command
    elif shutil.which("taskset"):
        command = ["taskset", "-c", "1"] + command
    load = float(open("/proc/loadavg").read().split()[0])
    start = time.perf_counter()
    p = subprocess.run(command, cwd=directory, env=ENV, capture_output=True, text=True)
    wall = time.perf_counter() - start
    LOADS.append(load)
    if p.returncode != 0:
        raise RuntimeError(f"{directory}: exit {p.returncode}\n{p.stderr[-3000:]}")
    m = re.search(r"finished in [0-9.eE+-]+ s \((\d+) cells, (\d+) facets, (\d+) steps, (\d+) Newton "
                  r"iterations, (\d+) factorizations", p.stdout)
    krylov = re.search(r"\((?:cg|gmres) \+ AMG, (\d+) iterations\)", p.stdout)
    names = {"set-up": "setup_s", "steps": "steps_s", "output": "output_s"}
    sections = dict(setup_s=0.0, steps_s=0.0, output_s=0.0)
    for name, seconds in re.findall(r"\|\s*(set-up|steps|output)\s*\|\s*\d+\s*\|\s*([0-9.]+)s", p.stdout):
        sections[names[name]] = float(seconds)
    usage = re.search(r"RSS (\d+) CPU ([0-9.]+) ([0-9.]+)", p.stderr)
    rss = float(usage.group(1)) / 1024
    return dict(wall=wall, rss=rss, cpu=float(usage.group(2)) + float(usage.group(3)), cells=int(m.group(1)), facets=int(m.group(2)), steps=int(m.group(3)),
                newton=int(m.group(4)), factorizations=int(m.group(5)),
                krylov=int(krylov.group(1)) if krylov else 0, **sections)


def median_run(hysteron, directory, text, repeats, long_run, ranks=1):
    """The median of `repeats` runs by wall time; a run longer than `long_run` seconds once."""
    runs = [run(hysteron, directory, text, ranks)]
    if runs[0]["wall"] <= long_run:
        runs += [run(hysteron, directory, text, ranks) for _ in range(repeats - 1)]
    runs.sort(key=lambda r: r["wall"])
    r = runs[len(runs) // 2]
    r["repeats"] = len(runs)
    return r


SOLVER_LABEL = {"direct": "UMFPACK", "cg": "CG + ML", "gmres": "GMRES + ML",
                "gmres-reuse": "GMRES + ML, kept (reuse 0.05)"}


def box(hysteron, work, d_m, solver, repeats, long_run, ranks=1):
    with open(os.path.join(ROOT, "benchmarks", "rbsn", "box_uniaxial_3d.prm")) as f:
        text = with_solver(set_entry(f.read(), "Minimum distance", d_m), solver)
    d = os.path.join(work, f"box_{d_m:g}_{solver}_{ranks}")
    r = median_run(hysteron, d, text, repeats, long_run, ranks)
    reaction = float(rows_of(os.path.join(d, "output", "reactions.csv"))[-1]["right_x"])
    rotation = 0.0
    for i in range(4):
        last = rows_of(os.path.join(d, "output", f"probe_{i}.csv"))[-1]
        rotation = max(rotation, *(abs(float(last[f"theta_{c}"])) for c in "xyz"))
    shutil.rmtree(os.path.join(d, "output"), ignore_errors=True)   # the VTU: 10 kB per cell
    return dict(scene="elastic box, uniform strain", d_m=d_m, ranks=ranks, solver=SOLVER_LABEL[solver],
                **r, error=abs(reaction / REACTION - 1), value=rotation / EPS,
                quantity="reaction error; max |theta| / eps at the probes")


def cantilever(hysteron, work, d_m, solver, repeats, long_run, ranks=1):
    with open(os.path.join(ROOT, "benchmarks", "rbsn", "cantilever_plastic_3d.prm")) as f:
        text = with_solver(set_entry(f.read(), "Minimum distance", d_m), solver)
    d = os.path.join(work, f"cantilever_{d_m:g}_{solver}_{ranks}")
    r = median_run(hysteron, d, text, repeats, long_run, ranks)
    load = abs(float(rows_of(os.path.join(d, "output", "reactions.csv"))[-1]["tip_y"]))
    return dict(scene="plastic cantilever, 100 increments", d_m=d_m, ranks=ranks, solver=SOLVER_LABEL[solver],
                **r, error=abs(load / P_U - 1), value=load, quantity="load at 50 mm [N]")


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.3))
    for k, key in enumerate(dict.fromkeys((r["scene"], r["solver"]) for r in rows)):
        one = [r for r in rows if (r["scene"], r["solver"]) == key and r["ranks"] == 1]
        two = [r for r in rows if (r["scene"], r["solver"]) == key and r["ranks"] == 2]
        marker = "o" if key[0].startswith("elastic") else "s"
        label = f"{key[0].split(',')[0]}, {key[1]}"
        ax.loglog([r["cells"] for r in one], [r["wall"] for r in one], marker + "-", color=f"C{k}", label=label)
        ax.loglog([r["cells"] for r in two], [r["wall"] for r in two], marker, color=f"C{k}", mfc="none", ms=9)
        bx.loglog([r["cells"] for r in one], [r["rss"] for r in one], marker + "-", color=f"C{k}", label=label)
    cells = [r["cells"] for r in rows]
    ax.loglog([min(cells), max(cells)], [60, 60], "k:", lw=1)
    ax.text(min(cells), 60, " 60 s", va="bottom", fontsize=8)
    ax.loglog([min(cells), max(cells)], [180, 180], "k--", lw=1)
    ax.text(min(cells), 180, " 180 s", va="bottom", fontsize=8)
    # Slopes for the eye: N^1 and N^2 through the first elastic point.
    ax.set_xlabel("cells")
    ax.set_ylabel("wall time, whole process [s]")
    ax.set_title("time (filled: 1 core, median; open: 2 ranks)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    bx.set_xlabel("cells")
    bx.set_ylabel("peak resident set [MB]")
    bx.set_title("memory (1 rank)", fontsize=10)
    bx.grid(True, which="both", alpha=0.3)
    bx.legend(fontsize=7)
    fig.suptitle("RBSN in 3D: elastic box (one static solve) and plastic cantilever (100 increments)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--long", type=float, default=60, help="runs longer than this [s] run once")
    parser.add_argument("--output", default=os.path.join(ROOT, "doc", "benchmarks", "rbsn_3d"))
    args = parser.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    if args.quick:
        box_cases = [(d, s) for s in ("cg", "direct") for d in (0.06, 0.05)]
        cantilever_cases = [(0.03, "direct"), (0.03, "gmres-reuse")]
        repeats = 1
    else:
        box_cases = [(d, s) for s in ("cg", "direct") for d in (0.05, 0.038, 0.03, 0.024, 0.021)]
        cantilever_cases = [(d, s) for s in ("direct", "gmres-reuse") for d in (0.025, 0.018, 0.0145, 0.012)]
        repeats = args.repeats
    rows = []
    with tempfile.TemporaryDirectory(prefix="rbsn_3d_") as work:
        for d_m, solver in box_cases:
            rows.append(box(hysteron, work, d_m, solver, repeats, args.long))
            print({k: rows[-1][k] for k in ("scene", "solver", "cells", "wall", "rss", "error")}, flush=True)
        for d_m, solver in cantilever_cases:
            rows.append(cantilever(hysteron, work, d_m, solver, repeats, args.long))
            print({k: rows[-1][k] for k in ("scene", "solver", "cells", "wall", "rss", "error")}, flush=True)
        # The largest of each scene and solver on 2 ranks (both cores, one run).
        for function, cases in ((box, box_cases), (cantilever, cantilever_cases)):
            for solver in dict.fromkeys(s for _, s in cases):
                d_m = min(d for d, s in cases if s == solver)
                rows.append(function(hysteron, work, d_m, solver, 1, 0, ranks=2))
                print({k: rows[-1][k] for k in ("scene", "solver", "ranks", "cells", "wall", "rss")}, flush=True)
    # Memory per cell and the 2-rank speed-up.
    for r in rows:
        r["kb_per_cell"], r["speedup"] = "", ""
    for key in dict.fromkeys((r["scene"], r["solver"]) for r in rows):
        one = sorted((r for r in rows if (r["scene"], r["solver"]) == key and r["ranks"] == 1),
                     key=lambda r: r["cells"])
        if len(one) >= 2:
            a, b = one[-2], one[-1]
            b["kb_per_cell"] = f"{1024 * (b['rss'] - a['rss']) / (b['cells'] - a['cells']):.1f}"
        for r in rows:
            if (r["scene"], r["solver"]) == key and r["ranks"] == 2:
                same = [o for o in one if o["d_m"] == r["d_m"]]
                if same:
                    r["speedup"] = f"{same[0]['wall'] / r['wall']:.2f}"
    columns = ["scene", "d_m", "ranks", "solver", "cells", "facets", "newton", "factorizations", "krylov",
               "repeats", "wall", "cpu", "setup_s", "steps_s", "output_s", "rss", "kb_per_cell", "speedup", "error",
               "value"]
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in r.items()})
    cpu = re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read())
    header = ("| scene | d_m [m] | ranks | solver | cells | facets | Newton iterations | factorizations | "
              "Krylov iterations | runs | total [s] | CPU [s] | set-up [s] | steps [s] | output [s] | peak RSS [MB] | "
              "memory per cell [kB] | speed-up on 2 ranks | error | second value |")
    lines = [f"`benchmarks/rbsn_3d.py build --repeats {repeats}`: {cpu.group(1).strip() if cpu else 'unknown CPU'}, "
             f"{os.cpu_count()} cores, Release; one core (taskset -c 1) for the 1-rank runs, both for the 2-rank "
             "ones; total = the whole process's wall time, median of the runs; CPU = its user + system time "
             "(all ranks). The columns are explained in the script's docstring.",
             "", f"1-minute load average before the runs (the machine is shared): median "
             f"{statistics.median(LOADS):.2f}, max {max(LOADS):.2f}.", "", header, "|" + "---|" * (header.count("|") - 1)]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['d_m']:g} | {r['ranks']} | {r['solver']} | {r['cells']:,} | "
                     f"{r['facets']:,} | {r['newton']} | {r['factorizations']} | {r['krylov'] or '–'} | "
                     f"{r['repeats']} | {r['wall']:.2f} | {r['cpu']:.2f} | {r['setup_s']:.2f} | {r['steps_s']:.2f} | "
                     f"{r['output_s']:.2f} | {r['rss']:.0f} | {r['kb_per_cell'] or '–'} | {r['speedup'] or '–'} | "
                     f"{r['error']:.2g} | {r['value']:.4g} |")
    with open(args.output + ".md", "w") as f:
        f.write("# RBSN in 3D: time and memory against cells\n\n" + "\n".join(lines) + "\n")
    plot(rows, args.output + ".png")
    write_summary(rows, args.output + "_summary.csv")
    print("\n".join(lines))


def write_summary(rows, path):
    """The values doc/benchmarks.md quotes, by key, for the largest network of each scene and
    solver (so that the report reads the same keys after a --quick run): cells, wall time,
    peak RSS [GB], error, the load and Newton counts of the cantilever, the growth exponent of
    the time over the two largest 1-rank runs, and the 2-rank speed-up."""
    summary = []
    keys = {("elastic box, uniform strain", "CG + ML"): "box_cg",
            ("elastic box, uniform strain", "UMFPACK"): "box_direct",
            ("plastic cantilever, 100 increments", "UMFPACK"): "cantilever_direct",
            ("plastic cantilever, 100 increments", "GMRES + ML, kept (reuse 0.05)"): "cantilever_reuse"}
    for (scene, solver), key in keys.items():
        one = sorted((r for r in rows if r["scene"] == scene and r["solver"] == solver and r["ranks"] == 1),
                     key=lambda r: r["cells"])
        if not one:
            continue
        last = one[-1]
        summary += [(f"{key}_cells", last["cells"]), (f"{key}_wall", last["wall"]), (f"{key}_cpu", last["cpu"]),
                    (f"{key}_rss_gb", last["rss"] / 1024), (f"{key}_error", last["error"]),
                    (f"{key}_value", last["value"]), (f"{key}_newton", last["newton"]),
                    (f"{key}_factorizations", last["factorizations"]), (f"{key}_d_m", last["d_m"])]
        if len(one) >= 2:
            a = one[-2]
            summary.append((f"{key}_exponent", math.log(last["wall"] / a["wall"]) / math.log(last["cells"] / a["cells"])))
        two = [r for r in rows if r["scene"] == scene and r["solver"] == solver and r["ranks"] == 2]
        if two and two[0]["speedup"]:
            summary.append((f"{key}_speedup", float(two[0]["speedup"])))
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["key", "value"])
        for k, v in summary:
            w.writerow([k, f"{v:.6g}" if isinstance(v, float) else v])


if __name__ == "__main__":
    main()
