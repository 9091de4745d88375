#!/usr/bin/python3
"""RBSN: incremental assembly of the tangent against assembly from zero, on one core.

Each scene runs with `RBSN/Incremental assembly = true` and `false`, --repeats times each
(median of hysteron's `steps` timer section, pinned to one core):

(1) Rupture of the double-notched bar (tests/rbsn/rupture_displacement.prm, quasi-static, linear
    springs with brittle fracture) with finer cells: only the breaking facets change the tangent.
(2) The §5.1 plastic cantilever (prm/rbsn_cantilever_plastic.prm, coupled Bouc-Wen springs, 100
    increments): springs that yield change their tangent in every iteration, the elastic ones
    only where they move.
(3) The bar of (1) in implicit dynamics (HHT alpha = -0.1, Rayleigh damping): the mass and damping
    parts stay in the matrix.

Columns: the share of the facets' matrices the incremental runs wrote (from the summary), the
factorizations, the steps' time of both and their ratio, and the largest difference of the
reaction tables between the two, relative to the largest reaction. Writes CSV and Markdown to
--output (default doc/benchmarks/rbsn_incremental_assembly).

Usage: benchmarks/rbsn_incremental_assembly.py BUILD_DIR [--repeats 3] [--quick] [--output PREFIX]
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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from rbsn_run_time import end_points, rows_of, set_entry  # noqa: E402


def run(hysteron, directory, text, incremental):
    """One run: the steps' time [s], the summary's counts and the share of facets written."""
    shutil.rmtree(directory, ignore_errors=True)
    os.makedirs(directory)
    text = text.replace("subsection RBSN\n", "subsection RBSN\n  set Incremental assembly = "
                        + ("true" if incremental else "false") + "\n", 1)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    command = [hysteron, "scene.prm"]
    if shutil.which("taskset"):
        command = ["taskset", "-c", "1"] + command
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{directory}: exit {p.returncode}\n{p.stderr}")
    m = re.search(r"\((\d+) cells, (\d+) facets, (\d+) steps, (\d+) Newton iterations, (\d+) factorizations",
                  p.stdout)
    steps = float(re.search(r"\|\s*steps\s*\|\s*\d+\s*\|\s*([0-9.]+)s", p.stdout).group(1))
    written = re.search(r"([0-9.]+) % of the facets' matrices", p.stdout)
    return dict(cells=int(m.group(1)), newton=int(m.group(4)), factorizations=int(m.group(5)), steps=steps,
                written=float(written.group(1)) if written else 100.0)


def reaction_difference(a, b):
    """max |R_a - R_b| over reactions.csv, relative to the largest |R|."""
    ra, rb = rows_of(os.path.join(a, "output", "reactions.csv")), rows_of(os.path.join(b, "output", "reactions.csv"))
    columns = [c for c in ra[0] if c != "time"]
    scale = max(abs(float(r[c])) for r in ra for c in columns) or 1.0
    return max(abs(float(x[c]) - float(y[c])) for x, y in zip(ra, rb) for c in columns) / scale


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--output", default=os.path.join(ROOT, "doc", "benchmarks", "rbsn_incremental_assembly"))
    args = parser.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    repeats = 1 if args.quick else args.repeats
    bar = open(os.path.join(ROOT, "tests", "rbsn", "rupture_displacement.prm")).read()
    cantilever = open(os.path.join(ROOT, "prm", "rbsn_cantilever_plastic.prm")).read()
    d_bar, d_cantilever = (0.005, 0.01) if args.quick else (0.0025, 0.0052)
    bar = set_entry(bar, "Minimum distance", d_bar)
    cantilever = set_entry(cantilever, "Minimum distance", d_cantilever)
    cantilever = set_entry(cantilever, "Additional points", end_points(d_cantilever, 0, 0.1))
    cantilever = set_entry(cantilever, "Write VTU", "false")
    dynamic = bar.replace("subsection RBSN\n", "subsection RBSN\n  set Analysis = implicit dynamics\n"
                          "  subsection Dynamics\n    set HHT alpha = -0.1\n"
                          "    set Rayleigh mass coefficient = 5\n"
                          "    set Rayleigh stiffness coefficient = 1e-5\n  end\n", 1)
    scenes = [("bar to rupture, linear springs", d_bar, bar),
              ("plastic cantilever (§5.1), coupled springs", d_cantilever, cantilever),
              ("bar to rupture, HHT dynamics", d_bar, dynamic)]
    rows = []
    with tempfile.TemporaryDirectory(prefix="rbsn_incremental_") as work:
        for k, (scene, d_m, text) in enumerate(scenes):
            result = {}
            for incremental in (True, False):
                d = os.path.join(work, f"{k}_{incremental}")
                runs = [run(hysteron, d, text, incremental) for _ in range(repeats)]
                result[incremental] = dict(runs[0], steps=statistics.median(r["steps"] for r in runs))
            difference = reaction_difference(os.path.join(work, f"{k}_True"), os.path.join(work, f"{k}_False"))
            on, off = result[True], result[False]
            rows.append({"scene": scene, "d_m [m]": f"{d_m:g}", "cells": f"{on['cells']:,}",
                         "Newton iterations": on["newton"],
                         "factorizations (incremental / from zero)": f"{on['factorizations']} / {off['factorizations']}",
                         "facets' matrices written [%]": f"{on['written']:.1f}",
                         "steps, incremental [s]": f"{on['steps']:.2f}",
                         "steps, from zero [s]": f"{off['steps']:.2f}",
                         "speed-up": f"{off['steps'] / on['steps']:.2f}",
                         "reaction difference": f"{difference:.1e}"})
            print(rows[-1], flush=True)
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output + ".csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    with open(args.output + ".md", "w") as f:
        f.write("# RBSN: incremental assembly of the tangent\n\n")
        f.write(f"`benchmarks/rbsn_incremental_assembly.py` (median of {repeats} runs of the `steps` "
                "timer section, one core of the machine in the table at the top of doc/benchmarks.md, "
                "Release build).\n\n")
        f.write("| " + " | ".join(rows[0]) + " |\n|" + "---|" * len(rows[0]) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(v) for v in r.values()) + " |\n")


if __name__ == "__main__":
    main()
