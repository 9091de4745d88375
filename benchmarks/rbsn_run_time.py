#!/usr/bin/python3
"""RBSN: run time and error against the number of cells, over full load histories (issue 6).

Three scenes, each at several minimum distances d_m, run to their end time:

(1) The elastic cantilever study of §3.7.1 (Table 3-2; the scene of
    tests/rbsn/cantilever_mesh_study.py: 1 m x 0.1 m, E = 400 kPa, P = 1 N, one static
    solve), seed 1. Error: the tip deflection against the dissertation's Table 3-2 mean for
    that d_m (the lattice's own mesh dependency makes beam theory, 0.01 m, the wrong yardstick
    for a single mesh) and, for scale, against beam theory.
(2) The plastic cantilever of §5.1 (prm/rbsn_cantilever_plastic.prm: displacement control of
    the tip to 50 mm in 100 increments, coupled Bouc-Wen facet springs with backward Euler and
    Newton), seed 1; benchmarks/rbsn_cantilever_plastic.py compares the spring laws and seeds.
    Error: the load at the end against the plastic collapse load P_u = sigma_y t h^2 / (4 L) =
    30 kN.
(3) The titanium plate of §5.3 (prm/rbsn_titanium_plate.prm: 300 increments, plasticity and
    fracture until the plate separates). Error: the elastic stiffness against the FEM of the
    same scene (7.957e7 N/m); the peak load is listed (the dissertation's curves are figures).

The time is hysteron's own 'finished in' wall time (set-up, all steps, tables; process start
excluded), the median of --repeats runs, pinned to one core with taskset when available. No
VTU output. Writes CSV, Markdown and a PNG (time against cells) to --output (default
doc/benchmarks/rbsn_run_time).

Usage: benchmarks/rbsn_run_time.py BUILD_DIR [--repeats 3] [--quick] [--output PREFIX]
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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "rbsn"))
import cantilever_mesh_study as study  # noqa: E402  (the Table 3-2 scene and reference)

P_U = 240e6 * 0.05 * 0.1**2 / 4  # 30 kN
K_TITANIUM_FEM = 7.957e7  # N/m, FEM Q2 of prm/rbsn_titanium_plate.prm (see its header)


def set_entry(text, name, value):
    """Replace `set name = ...` (first occurrence) in a prm text."""
    new, n = re.subn(rf"(?m)^(\s*set {re.escape(name)}\s*=).*$", rf"\g<1> {value}", text, count=1)
    if n != 1:
        raise RuntimeError(f"no entry '{name}' in the scene")
    return new


def end_points(d_m, y0, y1):
    """Uniform nuclei (spacing <= d_m) on the clamped and the loaded end, as in §3.7.1."""
    n = max(1, math.ceil((y1 - y0) / d_m - 1e-9))
    return "; ".join(f"{x}, {y0 + j * (y1 - y0) / n:.12g}" for x in (0, 1) for j in range(n + 1))


def run(hysteron, directory, text):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    command = [hysteron, "scene.prm"]
    if shutil.which("taskset"):
        command = ["taskset", "-c", "1"] + command
    p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{directory}: exit {p.returncode}\n{p.stderr}")
    m = re.search(r"finished in ([0-9.eE+-]+) s \((\d+) cells, (\d+) facets, (\d+) steps", p.stdout)
    return float(m.group(1)), int(m.group(2)), int(m.group(3)), int(m.group(4))


def rows_of(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def cantilever_elastic(hysteron, work, d_m, repeats):
    text = study.SCENE.format(seed=1, d_m=d_m, points=study.end_points(d_m), vtu="false")
    d = os.path.join(work, f"elastic_{d_m:g}")
    times = []
    for _ in range(repeats):
        seconds, cells, facets, steps = run(hysteron, d, text)
        times.append(seconds)
    deflection = -float(rows_of(os.path.join(d, "output", "probe_0.csv"))[-1]["u_y"])
    reference = statistics.mean(c[0] for c in study.TABLE[d_m])
    return dict(scene="elastic cantilever (Table 3-2)", d_m=d_m, cells=cells, facets=facets, steps=steps,
                seconds=statistics.median(times), quantity="tip deflection [m]", value=deflection,
                reference=reference, error=abs(deflection / reference - 1),
                note=f"beam theory 0.01 m: {100 * (deflection / 0.01 - 1):+.1f} %")


def cantilever_plastic(hysteron, work, d_m, repeats):
    with open(os.path.join(ROOT, "prm", "rbsn_cantilever_plastic.prm")) as f:
        text = f.read()
    text = set_entry(text, "Minimum distance", d_m)
    text = set_entry(text, "Additional points", end_points(d_m, 0, 0.1))
    text = set_entry(text, "Write VTU", "false")
    d = os.path.join(work, f"plastic_{d_m:g}")
    times = []
    for _ in range(repeats):
        seconds, cells, facets, steps = run(hysteron, d, text)
        times.append(seconds)
    reactions = rows_of(os.path.join(d, "output", "reactions.csv"))
    load = abs(float(reactions[-1]["tip_y"]))
    return dict(scene="plastic cantilever (§5.1)", d_m=d_m, cells=cells, facets=facets, steps=steps,
                seconds=statistics.median(times), quantity="load at 50 mm [N]", value=load, reference=P_U,
                error=abs(load / P_U - 1), note="P_u = 30 kN")


def titanium(hysteron, work, d_m, repeats):
    with open(os.path.join(ROOT, "prm", "rbsn_titanium_plate.prm")) as f:
        text = f.read()
    text = set_entry(text, "Minimum distance", d_m)
    text = set_entry(text, "Write VTU", "false")
    d = os.path.join(work, f"titanium_{d_m:g}")
    times = []
    for _ in range(repeats):
        seconds, cells, facets, steps = run(hysteron, d, text)
        times.append(seconds)
    reactions = rows_of(os.path.join(d, "output", "reactions.csv"))
    stiffness = float(reactions[1]["top_y"]) / (float(reactions[1]["time"]) * 1.5e-3)
    peak = max(float(r["top_y"]) for r in reactions)
    broken = len(rows_of(os.path.join(d, "output", "fracture.csv")))
    return dict(scene="titanium plate (§5.3)", d_m=d_m, cells=cells, facets=facets, steps=steps,
                seconds=statistics.median(times), quantity="elastic stiffness [N/m]", value=stiffness,
                reference=K_TITANIUM_FEM, error=abs(stiffness / K_TITANIUM_FEM - 1),
                note=f"peak {peak / 1e3:.1f} kN, {broken} broken facets")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="the coarsest meshes only, one run each")
    parser.add_argument("--output", default=os.path.join(ROOT, "doc", "benchmarks", "rbsn_run_time"))
    args = parser.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    repeats = 1 if args.quick else args.repeats

    cases = [(cantilever_elastic, d) for d in (0.05, 0.03, 0.02, 0.01, 0.005)]
    cases += [(cantilever_plastic, d) for d in (0.05, 0.03, 0.02, 0.01, 0.005)]
    cases += [(titanium, d) for d in (0.003, 0.0015, 0.0009)]
    if args.quick:
        cases = [c for c in cases if c[1] in (0.05, 0.003)]

    work = tempfile.mkdtemp(prefix="rbsn_run_time_")
    results = []
    for function, d_m in cases:
        r = function(hysteron, work, d_m, repeats)
        print(f"{r['scene']}, d_m = {d_m:g}: {r['cells']} cells, {r['seconds']:.2f} s, "
              f"{r['quantity']} {r['value']:.5g} (error {100 * r['error']:.2f} %; {r['note']})", flush=True)
        results.append(r)
    shutil.rmtree(work, ignore_errors=True)

    keys = ["scene", "d_m", "cells", "facets", "steps", "seconds", "quantity", "value", "reference", "error", "note"]
    with open(args.output + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(results)
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    with open(args.output + ".md", "w") as f:
        f.write("# RBSN: run time and error against the number of cells\n\n")
        f.write(f"`benchmarks/rbsn_run_time.py build --repeats {repeats}`: {cpu}, one core, Release; the "
                "time is hysteron's 'finished in' wall time (median of the repeats, whole load history, "
                "no VTU). The error columns are explained in the script's docstring.\n\n")
        f.write("| scene | d_m [m] | cells | facets | steps | time [s] | quantity | value | reference | error | note |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in results:
            f.write(f"| {r['scene']} | {r['d_m']:g} | {r['cells']} | {r['facets']} | {r['steps']} | "
                    f"{r['seconds']:.2f} | {r['quantity']} | {r['value']:.5g} | {r['reference']:.5g} | "
                    f"{100 * r['error']:.2f} % | {r['note']} |\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    for scene, marker in zip(dict.fromkeys(r["scene"] for r in results), "osd"):
        rs = [r for r in results if r["scene"] == scene]
        ax.loglog([r["cells"] for r in rs], [r["seconds"] for r in rs], marker + "-", label=scene)
        bx.loglog([r["seconds"] for r in rs], [max(r["error"], 1e-5) for r in rs], marker + "-", label=scene)
    cells = [r["cells"] for r in results]
    ax.loglog([min(cells), max(cells)], [30, 30], "k:", label="target 30 s")
    ax.set_xlabel("cells")
    ax.set_ylabel("wall time, whole history [s]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    bx.set_xlabel("wall time [s]")
    bx.set_ylabel("relative error (see the table)")
    bx.grid(True, which="both", alpha=0.3)
    fig.suptitle("RBSN run time (one core)")
    fig.tight_layout()
    fig.savefig(args.output + ".png", dpi=110)
    print(f"wrote {args.output}.csv, .md, .png")


if __name__ == "__main__":
    main()
