#!/usr/bin/python3
"""RBSN set-up under MPI: time and peak memory per rank, weak scaling and a 10^6-cell network.

Three series, each a static elastic network (k_t = k_n, nu = 0, the uniform-strain supports of
benchmarks/rbsn/plate_uniaxial.prm: rollers on the low faces, the x+ face moved; Linear
solver = cg, no VTU), of which only the set-up runs: the scene starts, and once hysteron
prints its set-up's peak memory (the last of the stage lines a large network prints, after
a reduction over the ranks, so that every rank has finished its set-up), the job is killed.

  weak 2D   a square plate of side sqrt(P n / 0.68) d, d = 0.005 m, n = 55,000 predicted
            points per rank (56,000 cells with the boundary rows), on P = 1, 2, 4, 8 ranks;
  weak 3D   a cube of side cbrt(P n / 0.70) d, d = 0.05 m, n = 11,000 predicted points per rank;
  10^6      the 2 m x 0.5 m plate at d = 0.000825 m (1.0e6 cells) on 1 and 2 ranks, with this
            build and, with --baseline BUILD, another one (before the block sampling), for
            which the peak memory is read from /proc when it prints its last set-up stage.

Columns: cells, the stage times hysteron prints (wall time of rank 0; nuclei: the sampling;
Voronoi: the tessellation; springs; pattern: the sparsity pattern and the distributed matrix;
rest: supports, loads, probes), their sum (set-up), the most CPU time of a rank up to the end
of the set-up (start-up included; fair on a loaded machine, but Open MPI's waits in
collectives count), and the least and the most of the ranks' peak resident memory (VmHWM, MB). More ranks than cores (the 2-core VM) give fair memory, not fair
times: the times of the oversubscribed runs are wall times of ranks that share the cores.
Prints Markdown tables; --csv FILE writes the rows too.

Usage: benchmarks/scaling_rbsn.py BUILD_DIR [--ranks 1,2,4,8] [--series weak2d,weak3d,large]
       [--baseline OTHER_BUILD_DIR] [--csv FILE]
"""
import argparse
import csv
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SCENE = """set Dimension = {dim}
set Method = rbsn
set Body names = body
set Boundary names = {names}
set Random seed = 3
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
{plane}end
subsection Body body
  set Shape = {shape}
{thickness}end
{boundaries}subsection RBSN
  set Analysis = static
  set Linear solver = cg
  set Minimum distance = {d}
  set Shear stiffness ratio = 1
  set Number of increments = 1
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def scene(dim, size, d):
    """The uniform-strain plate (2D, size = (L, H)) or box (3D, size = (L, H, W))."""
    names = ["x_low", "y_low"] + (["z_low"] if dim == 3 else []) + ["x_high"]
    boundaries = ""
    for n in names:
        face = n[0] + ("-" if n.endswith("low") else "+")
        if n == "x_high":
            disp = "1e-3*t; 0" + ("; 0" if dim == 3 else "")
            boundaries += (f"subsection Boundary {n}\n  set Type = displacement\n  set Faces = {face}\n"
                           f"  set Displacement = {disp}\n  set Components = x\nend\n")
        else:
            boundaries += f"subsection Boundary {n}\n  set Type = roller\n  set Faces = {face}\nend\n"
    shape = (f"rectangle(0, 0, {size[0]:.6g}, {size[1]:.6g})" if dim == 2 else
             f"box(0, 0, 0, {size[0]:.6g}, {size[1]:.6g}, {size[2]:.6g})")
    return SCENE.format(dim=dim, names=", ".join(names), shape=shape, d=d, boundaries=boundaries,
                        plane="  set Stress state = plane stress\n" if dim == 2 else "",
                        thickness="  set Thickness = 0.02\n" if dim == 2 else "")


def descendants(pid):
    """The pids of the processes below @p pid named hysteron."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
                children.setdefault(int(fields[1]), []).append(int(entry))
            except OSError:
                pass
    found, todo = [], [pid]
    while todo:
        p = todo.pop()
        for c in children.get(p, []):
            todo.append(c)
            try:
                if open(f"/proc/{c}/comm").read().strip() == "hysteron":
                    found.append(c)
            except OSError:
                pass
    return found


def vm_hwm(pids):
    values = []
    for p in pids:
        try:
            for line in open(f"/proc/{p}/status"):
                if line.startswith("VmHWM:"):
                    values.append(int(line.split()[1]) / 1024)
        except OSError:
            pass
    return values


def cpu_seconds(pids):
    """utime + stime of each process [s]."""
    values = []
    for p in pids:
        try:
            with open(f"/proc/{p}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            values.append((int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK"))
        except OSError:
            pass
    return values


def setup_run(build, directory, text, ranks):
    """Start the scene, read its stage lines, kill it after the set-up; the measurements."""
    os.makedirs(directory, exist_ok=True)
    shutil.rmtree(os.path.join(directory, "output"), ignore_errors=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", LD_LIBRARY_PATH=build)
    command = ["mpirun", "-np", str(ranks), os.path.join(build, "hysteron"), "scene.prm"]
    start = time.perf_counter()
    p = subprocess.Popen(command, cwd=directory, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, start_new_session=True)
    result = dict(ranks=ranks, nuclei=0.0, cells_s=0.0, springs=0.0, pattern=0.0, rest=0.0)
    stages = {"nuclei": "nuclei", "Voronoi cells": "cells_s", "facets' springs": "springs",
              "sparsity pattern": "pattern", "supports, loads and probes": "rest"}
    log = []
    for line in p.stdout:
        log.append(line)
        m = re.match(r"rbsn: (.*) in ([0-9.]+) s$", line.strip())
        if m:
            for key, column in stages.items():
                if key in m.group(1):
                    result[column] = float(m.group(2))
            if "nuclei" in m.group(1):
                result["cells"] = int(m.group(1).split()[0].replace(",", ""))
                blocks = re.search(r"in (\d+) blocks", m.group(1))
                result["blocks"] = int(blocks.group(1)) if blocks else 1
            if "supports" in m.group(1) and not has_memory_line(build):
                # A build without the memory line: the ranks' VmHWM now.
                pids = descendants(p.pid)
                memory = vm_hwm(pids)
                result["rss_min"], result["rss_max"], result["rss_source"] = min(memory), max(memory), "/proc"
                result["cpu"] = max(cpu_seconds(pids))
                break
        m = re.match(r"rbsn: set-up peak memory per rank ([0-9.]+) \.\.\. ([0-9.]+) MB", line.strip())
        if m:
            result["rss_min"], result["rss_max"], result["rss_source"] = float(m.group(1)), float(m.group(2)), "hysteron"
            result["cpu"] = max(cpu_seconds(descendants(p.pid)))
            break
    result["wall"] = time.perf_counter() - start
    try:
        os.killpg(p.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    p.wait()
    if "rss_min" not in result:
        raise RuntimeError(f"{directory}: no set-up lines\n{''.join(log[-30:])}")
    result["setup"] = sum(result[k] for k in ("nuclei", "cells_s", "springs", "pattern", "rest"))
    return result


_memory_line = {}


def has_memory_line(build):
    """Whether the build prints its set-up's peak memory (this branch does)."""
    if build not in _memory_line:
        library = os.path.join(build, "libhysteron.so")
        _memory_line[build] = b"set-up peak memory per rank" in open(os.path.realpath(library), "rb").read()
    return _memory_line[build]


def table(title, rows, extra=""):
    print(f"\n### {title}\n")
    if extra:
        print(extra + "\n")
    print("| build | ranks | cells | blocks | cells per rank | nuclei [s] | Voronoi [s] | springs [s] | pattern [s] | "
          "rest [s] | set-up [s] | CPU per rank [s] | peak memory per rank [MB] | vs 1 rank |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    base = {}
    for r in rows:
        key = r["build"]
        if r["ranks"] == min(x["ranks"] for x in rows if x["build"] == key):
            base[key] = r["rss_max"]
        print(f"| {r['build']} | {r['ranks']} | {r['cells']:,} | {r['blocks']} | {r['cells'] // r['ranks']:,} | {r['nuclei']:.1f} | "
              f"{r['cells_s']:.1f} | {r['springs']:.1f} | {r['pattern']:.1f} | {r['rest']:.1f} | {r['setup']:.1f} | "
              f"{r['cpu']:.1f} | "
              f"{r['rss_min']:.0f} ... {r['rss_max']:.0f} | {100 * (r['rss_max'] / base[key] - 1):+.1f} % |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build")
    parser.add_argument("--ranks", default="1,2,4,8")
    parser.add_argument("--series", default="weak2d,weak3d,large")
    parser.add_argument("--baseline", help="another build directory for the 10^6-cell set-up (before)")
    parser.add_argument("--csv")
    args = parser.parse_args()
    build = os.path.abspath(args.build)
    ranks = [int(r) for r in args.ranks.split(",")]
    work = tempfile.mkdtemp(prefix="scaling_rbsn_")
    series = args.series.split(",")
    rows = []
    load = os.getloadavg()
    print(f"Load average at the start: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} ({os.cpu_count()} cores)")
    if "weak2d" in series:
        d, n = 0.005, 55000
        weak = []
        for p in ranks:
            side = math.sqrt(p * n / 0.68) * d
            r = setup_run(build, os.path.join(work, f"weak2d_{p}"), scene(2, (side, side), d), p)
            r.update(build="this", series="weak 2D")
            weak.append(r)
            print(f"  weak 2D, {p} ranks: {r['cells']} cells, set-up {r['setup']:.1f} s, "
                  f"{r['rss_min']:.0f} ... {r['rss_max']:.0f} MB", file=sys.stderr)
        table("Weak scaling, 2D: about 56,000 cells per rank", weak)
        rows += weak
    if "weak3d" in series:
        d, n = 0.05, 11000
        weak = []
        for p in ranks:
            side = (p * n / 0.70) ** (1 / 3) * d
            r = setup_run(build, os.path.join(work, f"weak3d_{p}"), scene(3, (side, side, side), d), p)
            r.update(build="this", series="weak 3D")
            weak.append(r)
            print(f"  weak 3D, {p} ranks: {r['cells']} cells, set-up {r['setup']:.1f} s, "
                  f"{r['rss_min']:.0f} ... {r['rss_max']:.0f} MB", file=sys.stderr)
        table("Weak scaling, 3D: about 12,000 cells per rank", weak)
        rows += weak
    if "large" in series:
        large = []
        builds = [("this", build)] + ([("baseline", os.path.abspath(args.baseline))] if args.baseline else [])
        for name, b in builds:
            for p in (1, 2):
                r = setup_run(b, os.path.join(work, f"large_{name}_{p}"), scene(2, (2.0, 0.5), 0.000825), p)
                r.update(build=name, series="10^6 cells")
                large.append(r)
                print(f"  10^6 cells, {name}, {p} ranks: set-up {r['setup']:.1f} s, "
                      f"{r['rss_min']:.0f} ... {r['rss_max']:.0f} MB ({r['rss_source']})", file=sys.stderr)
        table("A 2 m x 0.5 m plate at d = 0.000825 m", large,
              "baseline: the memory read from /proc when it prints its last set-up stage")
        rows += large
    load = os.getloadavg()
    print(f"\nLoad average at the end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["series", "build", "ranks", "cells", "blocks", "nuclei", "cells_s", "springs",
                                              "pattern", "rest", "setup", "cpu", "rss_min", "rss_max", "rss_source", "wall"])
            w.writeheader()
            for r in rows:
                w.writerow({k: r.get(k) for k in w.fieldnames})
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
