#!/usr/bin/env python3
"""The RBSN's block sampling (doc/rbsn.md, MPI): a network of many sampling blocks (a small
`Sampling block size` on a small network) is the same on 1, 2 and 3 ranks, and it is a
saturated Poisson-disk set across the blocks' seams.

Scenes (Points on the boundary = false, so that every nucleus is a random one and the
distance rule holds between all of them):
  2D: a plate with a hole and a touching second body, d = 0.02 m, blocks of 0.1 m (about 50
      blocks of 20 points); and the same with a graded d = 0.015 + 0.02 x, blocks of 0.12 m;
  3D: a box 1 x 0.6 x 0.4 m, d = 0.07 m, blocks of 0.2 m (30 blocks).

Assertions, each from the construction, not from a recorded run:
  * identical networks: cells.csv (every cell's number, nucleus and body) is the same text on
    1, 2 and 3 ranks, and springs.csv the same cells a, b for every facet (the facets
    numbered in the order of (a, b) over the network on any number of ranks); the facets'
    geometry agrees to 1e-12 m (a cell is clipped from another set of nuclei on each rank
    count, the same bits in practice);
  * the distance rule: no two nuclei closer than min(d(p), d(q)) (1e-12 relative);
  * saturation: every point x of a grid of spacing d/4 whose disk of radius 2 d(x) lies in the
    bodies has a nucleus in that disk (a saturated set leaves no empty disk of radius d; 2 d
    is the brief's bound, which seams that the later block did not fill would break);
  * the density of the seams: the tiled network has at least 98 % of the nuclei of the
    one-block network of the same scene (another seed: the sampling's scatter is below 1 %),
    and at most the jamming limit of random sequential addition over the one-block density,
    plus 2 %. A block fills its part up to the points around it with the front and the darts;
    near its seams more of its points come from the darts, which pack towards the jamming
    limit (2D: 0.70 A / d^2 against 0.68 A / d^2 of the front with two levels of darts,
    doc/rbsn.md; 3D: 0.734 V / d^3 against 0.702 V / d^3, doc/rbsn/geometry_3d.md). Gaps at
    the seams (points missing) or blocks that overran their neighbours (points twice) would
    leave these bounds; these tiny blocks of 20 points are nearly all seam;
  * the cells tile the bodies: the areas (volumes) in cells.csv sum to the bodies' measure
    (polygonized hole: within 1e-3 of the exact one; a box exactly).

Usage: block_sampling.py HYSTERON MPIEXEC WORKDIR
"""
import csv
import math
import os
import shutil
import subprocess
import sys

hysteron, mpiexec, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
failures = []

SCENE_2D = """set Dimension = 2
set Method = rbsn
set Body names = left, right
set Boundary names = fix
set Random seed = {seed}
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
  set Stress state = plane stress
end
subsection Body left
  set Shape = rectangle(0, 0, 0.6, 0.5) - disk(0.3, 0.25, 0.1)
end
subsection Body right
  set Shape = rectangle(0.6, 0, 1, 0.5)
end
subsection Boundary fix
  set Type = fixed
  set Region = rectangle(-1, -1, 0.05, 2)
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {d}
  set Points on the boundary = false
  set Sampling block size = {block}
  set Number of increments = 1
  set Write cell table = true
  set Write spring table = true
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""

SCENE_3D = """set Dimension = 3
set Method = rbsn
set Body names = block
set Boundary names = fix
set Random seed = {seed}
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
end
subsection Body block
  set Shape = box(0, 0, 0, 1, 0.6, 0.4)
end
subsection Boundary fix
  set Type = fixed
  set Region = box(-1, -1, -1, 0.1, 2, 2)
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {d}
  set Points on the boundary = false
  set Sampling block size = {block}
  set Number of increments = 1
  set Write cell table = true
  set Write spring table = true
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def run(name, text, ranks):
    directory = os.path.join(work, f"{name}.np{ranks}")
    os.makedirs(directory)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    command = ([mpiexec, "-np", str(ranks)] if ranks > 1 else []) + [hysteron, "--quiet", "scene.prm"]
    p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True, timeout=900)
    if p.returncode != 0:
        sys.exit(f"{name} on {ranks} ranks: exit {p.returncode}: {p.stderr[-3000:]}")
    out = os.path.join(directory, "output")
    with open(os.path.join(out, "cells.csv")) as f:
        cells = list(csv.reader(f))
    with open(os.path.join(out, "springs.csv")) as f:
        springs = list(csv.reader(f))
    return cells, springs


def columns(table, names):
    header = table[0]
    index = [header.index(n) for n in names]
    return [[row[i] for i in index] for row in table[1:]]


def nuclei(cells, dim):
    return [tuple(float(v) for v in row) for row in columns(cells, ["x", "y", "z"][:dim])]


def grid_of(points, h):
    grid = {}
    for k, p in enumerate(points):
        grid.setdefault(tuple(int(math.floor(c / h)) for c in p), []).append(k)
    return grid


def near(grid, h, x, reach):
    """Indices of the points within `reach` cells of x's cell."""
    key = tuple(int(math.floor(c / h)) for c in x)
    found = []
    ranges = [range(k - reach, k + reach + 1) for k in key]
    for cell in _product(ranges):
        found += grid.get(cell, [])
    return found


def _product(ranges):
    result = [()]
    for r in ranges:
        result = [c + (i,) for c in result for i in r]
    return result


def check_poisson_disk(name, points, d, d_max, inside_with_margin, box, step):
    """The distance rule between all pairs, and no empty disk of radius 2 d(x) in the bodies."""
    grid = grid_of(points, d_max)
    closest = float("inf")
    for k, p in enumerate(points):
        for j in near(grid, d_max, p, 1):
            if j < k:
                r = math.dist(p, points[j])
                closest = min(closest, r / min(d(p), d(points[j])))
    if closest < 1 - 1e-12:
        failures.append(f"{name}: two nuclei {closest:.6f} min(d(p), d(q)) apart")
    coarse = grid_of(points, 2 * d_max)
    worst, tested = 0.0, 0
    axes = [[box[0][i] + step * (k + 0.5) for k in range(int((box[1][i] - box[0][i]) / step))]
            for i in range(len(box[0]))]
    for x in _product_values(axes):
        radius = 2 * d(x)
        if not inside_with_margin(x, radius):
            continue
        tested += 1
        nearest = min((math.dist(x, points[j]) for j in near(coarse, 2 * d_max, x, 1)), default=float("inf"))
        worst = max(worst, nearest / d(x))
    if worst >= 2:
        failures.append(f"{name}: an empty disk of radius {worst:.3f} d(x) in the bodies")
    return closest, worst, tested


def _product_values(axes):
    result = [()]
    for a in axes:
        result = [c + (v,) for c in result for v in a]
    return result


def compare(name, runs, dim):
    """The same network on every rank count: cells exactly, facets' cells exactly, geometry to 1e-12."""
    (cells_1, springs_1), others = runs[0], runs[1:]
    keys = ["cell", "x", "y", "z"][:dim + 1] + ["body"]
    geometry = ["x", "y", "z"][:dim] + ["n_x", "n_y", "n_z"][:dim]
    for ranks, (cells, springs) in others:
        if columns(cells, keys) != columns(cells_1, keys):
            failures.append(f"{name}: cells.csv (number, nucleus, body) differs on {ranks} ranks")
        if columns(springs, ["a", "b"]) != columns(springs_1, ["a", "b"]):
            failures.append(f"{name}: the facets' cells differ on {ranks} ranks")
            continue
        error = max((abs(float(u) - float(v)) for r1, r2 in zip(columns(springs_1, geometry), columns(springs, geometry))
                     for u, v in zip(r1, r2)), default=0.0)
        if error > 1e-12:
            failures.append(f"{name}: the facets' geometry differs by {error:g} on {ranks} ranks")


def check_density(name, n_blocks, n_single, jamming):
    ratio = n_blocks / n_single
    if not 0.98 <= ratio <= jamming * 1.02:
        failures.append(f"{name}: {n_blocks} nuclei in blocks, {n_single} in one block (ratio {ratio:.4f})")


def measure(cells, dim):
    return sum(float(v[0]) for v in columns(cells, ["area" if dim == 2 else "volume"]))


# 2D, constant d.
d_2d = 0.02
text = SCENE_2D.format(seed=3, d=d_2d, block=0.1)
runs_2d = [run("plate", text, 1)] + [(r, run("plate", text, r)) for r in (2, 3)]
compare("2D", [runs_2d[0]] + runs_2d[1:], 2)
points = nuclei(runs_2d[0][0], 2)
hole = ((0.3, 0.25), 0.1)
inside_2d = lambda x, r: (r <= x[0] <= 1 - r and r <= x[1] <= 0.5 - r and math.dist(x, hole[0]) >= hole[1] + r)
closest, worst, tested = check_poisson_disk("2D", points, lambda p: d_2d, d_2d, inside_2d, ((0, 0), (1, 0.5)), d_2d / 4)
single, _ = run("plate_one_block", SCENE_2D.format(seed=4, d=d_2d, block=0), 1)
check_density("2D", len(points), len(single) - 1, 0.70 / 0.68)
area = 0.5 - math.pi * 0.1 ** 2
if abs(measure(runs_2d[0][0], 2) / area - 1) > 1e-3:
    failures.append(f"2D: the cells' areas sum to {measure(runs_2d[0][0], 2)}, the bodies' to {area}")
print(f"2D: {len(points)} nuclei in blocks ({len(single) - 1} in one block), closest pair "
      f"{closest:.4f} d, largest empty disk {worst:.3f} d over {tested} points")

# 2D, graded d.
graded = lambda p: 0.015 + 0.02 * p[0]
text = SCENE_2D.format(seed=5, d="0.015 + 0.02 * x", block=0.12)
runs_graded = [run("graded", text, 1), (3, run("graded", text, 3))]
compare("2D graded", runs_graded, 2)
points = nuclei(runs_graded[0][0], 2)
closest, worst, tested = check_poisson_disk("2D graded", points, graded, 0.035, inside_2d, ((0, 0), (1, 0.5)), 0.005)
single, _ = run("graded_one_block", SCENE_2D.format(seed=6, d="0.015 + 0.02 * x", block=0), 1)
check_density("2D graded", len(points), len(single) - 1, 0.70 / 0.68)
print(f"2D graded: {len(points)} nuclei ({len(single) - 1} in one block), closest pair {closest:.4f} "
      f"min(d(p), d(q)), largest empty disk {worst:.3f} d(x) over {tested} points")

# 3D.
d_3d = 0.07
text = SCENE_3D.format(seed=7, d=d_3d, block=0.2)
runs_3d = [run("box", text, 1)] + [(r, run("box", text, r)) for r in (2, 3)]
compare("3D", [runs_3d[0]] + runs_3d[1:], 3)
points = nuclei(runs_3d[0][0], 3)
inside_3d = lambda x, r: all(r <= x[i] <= s - r for i, s in enumerate((1, 0.6, 0.4)))
closest, worst, tested = check_poisson_disk("3D", points, lambda p: d_3d, d_3d, inside_3d, ((0, 0, 0), (1, 0.6, 0.4)),
                                            d_3d / 3)
single, _ = run("box_one_block", SCENE_3D.format(seed=8, d=d_3d, block=0), 1)
check_density("3D", len(points), len(single) - 1, 0.734 / 0.702)
if abs(measure(runs_3d[0][0], 3) / 0.24 - 1) > 1e-12:
    failures.append(f"3D: the cells' volumes sum to {measure(runs_3d[0][0], 3)}, the box's to 0.24")
print(f"3D: {len(points)} nuclei in blocks ({len(single) - 1} in one block), closest pair {closest:.4f} d, "
      f"largest empty ball {worst:.3f} d over {tested} points")

if failures:
    sys.exit("FAILED:\n  " + "\n  ".join(failures))
print("passed")
