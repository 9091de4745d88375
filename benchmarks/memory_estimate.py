#!/usr/bin/env python3
"""The constants of the memory estimate (hysteron/base/memory.h and its callers): the peak
resident set of one-rank runs of each method at 2 or 3 sizes, and the slope per item.

    memory_estimate.py --hysteron build/hysteron [--workdir DIR] [--only mpm2,mpm3,...]

Each run is `/usr/bin/time -v hysteron scene.prm`; "Maximum resident set size" is its peak.
The slope between the two largest runs of a series is the bytes per item (material point,
grid cell, RBSN cell, FEM quadrature point) that the code uses, rounded up. Scenes:
  mpm2, mpm3     a box that fills the grid, 2 points per cell and direction, linear elastic,
                 a few explicit steps: bytes per material point (with its share of the nodes)
  mpmgrid3       a 0.1 m cube in a grid of n^3 cells: bytes per grid cell (points subtracted)
  rbsn2, rbsn3   a unit square / cube, linear static, one solve by cg + ML (the direct
                 solver's fill: doc/benchmarks.md, the RBSN tables, UMFPACK against CG)
  fem2, fem3     the box of benchmarks/scaling_fem.py, Q1 and Q2, one quasi-static increment
                 solved by CG + ML (the path of meshes beyond the direct solver's limit)
"""
import argparse
import os
import re
import subprocess

MPM = """set Dimension = {dim}
set Method = mpm
set Body names = block
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e6
  set Poisson's ratio = 0.3
  set Density = 1000
end
subsection Body block
  set Shape = {shape}
  set Particles per cell = 2
  set Initial velocity = {velocity}
end
subsection MPM
  subsection Grid
    set Lower corner = {lower}
    set Upper corner = {upper}
    set Cell size = {h}
  end
end
subsection Time
  set End time = {end}
  set CFL factor = 0.5
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""

RBSN = """set Dimension = {dim}
set Method = rbsn
set Body names = block
set Boundary names = fixed
set Load names = pull
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
end
subsection Body block
  set Shape = {shape}
end
subsection Boundary fixed
  set Type = fixed
  set Faces = x-
end
subsection Load pull
  set Type = traction
  set Region = {face}
  set Value = {value}
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {d}
  set Number of increments = 1
  set Linear solver = {solver}
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""

FEM = """set Dimension = {dim}
set Method = fem
set Body names = block
set Boundary names = clamp, pull
subsection Material
  set Model = linear elastic
  set Young's modulus = 210e9
  set Poisson's ratio = 0.3
end
subsection Body block
  set Shape = {shape}
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Boundary pull
  set Type = displacement
  set Faces = x+
  set Components = x
  set Displacement = {displacement}
end
subsection FEM
  set Degree = {degree}
  set Number of increments = 1
  subsection Linear solver
    set Type = cg
    set Tolerance = 1e-8
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


def scenes():
    """(series, size label, items, scene text)"""
    for n in (100, 200, 400):
        yield "mpm2", n, 4 * n * n, MPM.format(dim=2, shape="rectangle(0, 0, 1, 1)", velocity="0.01*x; 0",
                                               lower="0, 0", upper="1, 1", h=1 / n, end=3e-3 / n)
    for n in (16, 24, 32):
        yield "mpm3", n, 8 * n ** 3, MPM.format(dim=3, shape="box(0, 0, 0, 1, 1, 1)", velocity="0.01*x; 0; 0",
                                                lower="0, 0, 0", upper="1, 1, 1", h=1 / n, end=3e-3 / n)
    for n in (50, 75, 100):
        yield "mpmgrid3", n, n ** 3, MPM.format(dim=3, shape="box(0, 0, 0, 0.1, 0.1, 0.1)",
                                                velocity="0.01*x; 0; 0", lower="0, 0, 0", upper="1, 1, 1",
                                                h=1 / n, end=3e-3 / n)
    for solver in ("cg",):
        for d in (0.01, 0.005, 0.0035):
            yield "rbsn2-" + solver, d, 0.68 / d ** 2, RBSN.format(
                dim=2, shape="rectangle(0, 0, 1, 1)", face="rectangle(0.9999, -1, 2, 2)", value="1e6; 0",
                d=d, solver=solver)
        for d in (0.06, 0.045, 0.035):
            yield "rbsn3-" + solver, d, 0.70 / d ** 3, RBSN.format(
                dim=3, shape="box(0, 0, 0, 1, 1, 1)", face="box(0.9999, -1, -1, 2, 2, 2)", value="1e6; 0; 0",
                d=d, solver=solver)
    for degree, sizes in ((1, (64, 128, 256)), (2, (32, 64, 128))):
        for n in sizes:
            yield f"fem2-Q{degree}", n, n * n * (degree + 1) ** 2, FEM.format(
                dim=2, shape="rectangle(0, 0, 1, 1)", displacement="1e-3 * t; 0", degree=degree, h=1 / n)
    for degree, sizes in ((1, (12, 16, 20)), (2, (6, 8, 10))):
        for n in sizes:
            yield f"fem3-Q{degree}", n, n ** 3 * (degree + 1) ** 3, FEM.format(
                dim=3, shape="box(0, 0, 0, 1, 1, 1)", displacement="1e-3 * t; 0; 0", degree=degree, h=1 / n)


def peak_rss(hysteron, directory, text):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    run = subprocess.run(["/usr/bin/time", "-v", os.path.abspath(hysteron), "scene.prm"], cwd=directory,
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"{directory}: exit {run.returncode}: {run.stderr[-800:]}")
    return 1024 * int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr).group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--workdir", default="memory_estimate")
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    only = [x for x in args.only.split(",") if x]
    results = {}
    for series, size, items, text in scenes():
        if only and not any(series.startswith(o) for o in only):
            continue
        rss = peak_rss(args.hysteron, os.path.join(args.workdir, f"{series}_{size}"), text)
        results.setdefault(series, []).append((items, rss))
        print(f"{series:14s} size {size:<8} items {items:12.4g} peak RSS {rss / 1e6:9.1f} MB", flush=True)
    for series, rows in results.items():
        (n1, m1), (n2, m2) = rows[-2], rows[-1]
        print(f"{series}: {(m2 - m1) / (n2 - n1):.0f} B per item (slope of the two largest runs), "
              f"intercept {(m1 - (m2 - m1) / (n2 - n1) * n1) / 1e6:.0f} MB")


if __name__ == "__main__":
    main()
