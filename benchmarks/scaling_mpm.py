#!/usr/bin/python3
"""The MPM's set-up and memory against the grid, the points and the MPI ranks.

    scaling_mpm.py BUILD_DIR [--repeats 3] [--out DIR] [--workdir DIR] [--quick]

Writes into OUT (doc/benchmarks by default):
  scaling_mpm_setup.md      set-up time per grid cell and per material point on one core
                            (the `set-up` timer of the run: grid, partition, points, conditions),
                            median of --repeats runs, and the peak memory of the process;
  scaling_mpm_weak.md       weak scaling of memory: 1, 2, 4 and 8 ranks, the grid and the points
                            growing with the ranks (a slab of 40 x 120 x 80 cells and 192,000
                            points per rank); peak memory of every rank (/usr/bin/time per rank);
  scaling_mpm_grid.md       a grid far larger than the body (a 0.3 m block of 216,000 points in 18
                            million cells) and a large scene (4.5 million points in the same grid):
                            the largest rank's peak memory on 2 ranks against 1 rank;
  scaling_mpm.csv           every run.
Ranks beyond the machine's cores are oversubscribed: fine for memory, not for time (the weak
scaling table gives no times). The peak memory includes the process's libraries (deal.II,
Trilinos, MPI: about 160 MB).
"""
import argparse
import csv
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")

SCENE = """set Dimension = 3
set Method = mpm
set Body names = block
subsection Material
  set Model = bouc-wen
  set Young's modulus = 1e7
  set Poisson's ratio = 0.3
  set Density = 1000
  subsection Bouc-Wen
    set Yield stress = 1e5
  end
end
subsection Body block
  set Shape = box({body})
  set Particles per cell = {ppc}
  set Initial velocity = 0; 0; -1
end
subsection MPM
  set Basis = {basis}
  subsection Grid
    set Lower corner = 0, 0, 0
    set Upper corner = {upper}
    set Cell size = {h}
  end
end
subsection Time
  set End time = {end}
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def run_scene(hysteron, workdir, name, ranks=1, **scene):
    """Set-up seconds (rank 0's timer), points, cells and the peak RSS [MB] of every rank."""
    directory = os.path.join(workdir, name)
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(**scene))
    timed = ["/usr/bin/time", "-f", "peak-rss-kB %M"]
    if ranks > 1:
        command = ["mpirun", "-np", str(ranks)] + timed + [hysteron, "scene.prm"]
    else:
        command = ["taskset", "-c", "0"] + timed + [hysteron, "scene.prm"]
    p = subprocess.run(command, cwd=directory, env=ENV, capture_output=True, text=True, timeout=3600)
    if p.returncode != 0:
        sys.exit(f"{name} on {ranks} rank(s) failed:\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    setup = float(re.search(r"\|\s*set-up\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s", p.stdout).group(1))
    m = re.search(r"mpm: (\d+) material points, grid of (\d+) x (\d+) x (\d+) cells", p.stdout)
    points, cells = int(m.group(1)), int(m.group(2)) * int(m.group(3)) * int(m.group(4))
    peaks = [int(x) / 1024 for x in re.findall(r"peak-rss-kB (\d+)", p.stderr)]
    return setup, points, cells, peaks


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ROOT, "doc", "benchmarks"))
    ap.add_argument("--workdir", default="/tmp/hysteron_scaling_mpm")
    ap.add_argument("--quick", action="store_true", help="smaller grids, one repeat")
    args = ap.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    os.makedirs(args.out, exist_ok=True)
    repeats = 1 if args.quick else args.repeats
    records = []

    # 1. Set-up per grid cell and per material point, one core.
    small_block = "0.6, 0.6, 0.35, 0.9, 0.9, 0.65"
    cases = [("block in 60 x 60 x 40 cells", dict(body=small_block, ppc=1, basis="linear",
                                                   upper="1.5, 1.5, 1.0", h=0.025, end=1e-4)),
             ("block in 120 x 120 x 80 cells", dict(body=small_block, ppc=1, basis="linear",
                                                     upper="1.5, 1.5, 1.0", h=0.0125, end=1e-4)),
             ("1e6 points in 60^3 cells", dict(body="0.1, 0.1, 0.1, 1.1, 1.1, 1.1", ppc=2,
                                               basis="cubic B-spline", upper="1.2, 1.2, 1.2",
                                               h=0.02, end=1e-5))]
    if args.quick:
        cases = cases[:1]
    lines = ["| scene | grid cells | material points | set-up [s] | per grid cell [us] | "
             "per point [us] | peak memory [MB] |", "|---|---|---|---|---|---|---|"]
    for label, scene in cases:
        runs = [run_scene(hysteron, args.workdir, "setup", **scene) for _ in range(repeats)]
        setup = statistics.median(r[0] for r in runs)
        _, points, cells, peaks = runs[0]
        lines.append(f"| {label} | {cells:,} | {points:,} | {setup:.3f} | {1e6 * setup / cells:.3f} | "
                     f"{1e6 * setup / points:.3f} | {max(peaks):.0f} |")
        records.append(dict(study="setup", scene=label, ranks=1, cells=cells, points=points,
                            setup_s=setup, peak_mb=max(peaks)))
    with open(os.path.join(args.out, "scaling_mpm_setup.md"), "w") as f:
        f.write("\n".join(lines) + "\n")

    # 2. Weak scaling of memory: a slab of 40 x 120 x 80 cells and 192,000 points per rank.
    h = 0.0125
    lines = ["| ranks | grid cells | material points | peak memory per rank [MB]: max / min | "
             "max against 1 rank |", "|---|---|---|---|---|"]
    base = None
    for ranks in ([1, 2] if args.quick else [1, 2, 4, 8]):
        nx = 40 * ranks
        scene = dict(body=f"0, 0, 0, {nx * h}, {120 * h}, {40 * h}", ppc=1, basis="cubic B-spline",
                     upper=f"{nx * h}, {120 * h}, {80 * h}", h=h, end=2e-5)
        _, points, cells, peaks = run_scene(hysteron, args.workdir, f"weak_{ranks}", ranks, **scene)
        base = base or max(peaks)
        lines.append(f"| {ranks} | {cells:,} | {points:,} | {max(peaks):.0f} / {min(peaks):.0f} | "
                     f"{max(peaks) / base:.3f} |")
        records.append(dict(study="weak", scene=f"slab x{ranks}", ranks=ranks, cells=cells, points=points,
                            setup_s="", peak_mb=max(peaks)))
    with open(os.path.join(args.out, "scaling_mpm_weak.md"), "w") as f:
        f.write("\n".join(lines) + "\n")

    # 3. A grid far larger than the body, and a large scene, on 1 and 2 ranks. Every process
    # holds the libraries (deal.II, Trilinos, MPI), the same on every rank: the memory the
    # scene adds is the peak above that of a tiny scene on as many ranks.
    empty = {}
    for ranks in (1, 2):
        empty[ranks] = max(run_scene(hysteron, args.workdir, f"empty_{ranks}", ranks, body="0, 0, 0, 0.1, 0.1, 0.1",
                                     ppc=1, basis="linear", upper="1.5, 1.5, 1.0", h=0.1, end=1e-6)[3])
    lines = ["| scene | ranks | grid cells | material points | set-up [s] | largest rank's peak memory "
             "[MB] | against 1 rank | above a tiny scene's [MB] | against 1 rank |",
             "|---|---|---|---|---|---|---|---|---|"]
    h = 0.0125 if args.quick else 0.005
    scenes = [("0.3 m block in a 1.5 x 1.5 x 1 m grid", small_block),
              ("a quarter of the grid filled", "0, 0, 0, 0.75, 1.5, 0.5")]
    for label, body in scenes:
        base = None
        scene = dict(body=body, ppc=1, basis="linear", upper="1.5, 1.5, 1.0", h=h, end=1e-6)
        for ranks in (1, 2):
            setup, points, cells, peaks = run_scene(hysteron, args.workdir, f"grid_{ranks}", ranks, **scene)
            base = base or (max(peaks), max(peaks) - empty[1])
            added = max(peaks) - empty[ranks]
            lines.append(f"| {label} | {ranks} | {cells:,} | {points:,} | {setup:.2f} | {max(peaks):.0f} | "
                         f"{max(peaks) / base[0]:.3f} | {added:.0f} | {added / base[1]:.3f} |")
            records.append(dict(study="grid", scene=label, ranks=ranks, cells=cells, points=points,
                                setup_s=setup, peak_mb=max(peaks)))
    lines.append(f"\nA tiny scene (1,000 points, 2,250 cells) peaks at {empty[1]:.0f} MB on 1 rank and "
                 f"{empty[2]:.0f} MB per rank on 2.")
    with open(os.path.join(args.out, "scaling_mpm_grid.md"), "w") as f:
        f.write("\n".join(lines) + "\n")

    with open(os.path.join(args.out, "scaling_mpm.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(records[0]))
        w.writeheader()
        w.writerows(records)
    for name in ("scaling_mpm_setup.md", "scaling_mpm_weak.md", "scaling_mpm_grid.md"):
        print(open(os.path.join(args.out, name)).read())


if __name__ == "__main__":
    main()
