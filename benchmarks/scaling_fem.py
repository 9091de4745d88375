#!/usr/bin/python3
"""Weak scaling of the FEM's meshes: set-up time and peak memory per MPI rank for a 3D mesh
that grows with the ranks, from a structured mesh and from a Gmsh file.

    scaling_fem.py --hysteron build/hysteron [--ranks 1,2,4,8] [--cells 32] [--meshes structured,gmsh]
                   [--workdir DIR] [--out FILE.md] [--mpiexec mpirun]

The body is the box [0, P] x [0, 1] x [0, 1] m on P ranks, meshed with cells of h = 1 / --cells:
(cells^3 cells per rank, Q1: about 3 cells^3 DoFs per rank). `structured` is the FEM's own
generator (a coarse mesh of P cells on every rank, refined log2(cells) times by p4est);
`gmsh` is the same cells written by this script as a Gmsh file (format 2.2, ASCII), which rank 0
reads whole and partitions (parallel::fullydistributed). The scene: steel (E = 210 GPa,
nu = 0.3, linear elastic), clamped on x = 0, pulled by 1 mm on x = P, one quasi-static
increment solved by CG with ML (the iterative path of meshes beyond the direct solver's
limit), no VTU output.

Each rank runs under GNU time (`/usr/bin/time -f %M`), which gives its peak resident memory;
the set-up time is the timer's `set-up` section (mesh, DoFs, sparsity pattern, history,
conditions). The table lists per run the cells, the DoFs, the set-up and total wall times,
the peak memory of rank 0 and the largest of the other ranks, and the largest peak over the
1-rank run's peak (the target: within 1.15). Oversubscribed ranks on a small machine measure
memory faithfully, not time.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time

SCENE = """set Dimension = 3
set Method = fem
set Body names = box
set Boundary names = clamp, pull
subsection Material
  set Model = linear elastic
  set Young's modulus = 210e9
  set Poisson's ratio = 0.3
end
subsection Body box
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
  set Displacement = 1e-3 * t; 0; 0
end
subsection FEM
  set Number of increments = 1
  subsection Linear solver
    set Type = cg
    set Tolerance = 1e-8
  end
  subsection Mesh
{mesh}
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def write_gmsh(path, nx, n):
    """The box [0, nx / n] x [0, 1] x [0, 1] as nx x n x n hexahedra (Gmsh 2.2 ASCII)."""
    def node(i, j, k):
        return 1 + i + (nx + 1) * (j + (n + 1) * k)

    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % ((nx + 1) * (n + 1) ** 2))
        for k in range(n + 1):
            for j in range(n + 1):
                f.write("".join("%d %r %r %r\n" % (node(i, j, k), i / n, j / n, k / n) for i in range(nx + 1)))
        f.write("$EndNodes\n$Elements\n%d\n" % (nx * n * n))
        e = 0
        for k in range(n):
            for j in range(n):
                rows = []
                for i in range(nx):
                    e += 1
                    v = [node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k)]
                    v += [x + (nx + 1) * (n + 1) for x in v]
                    rows.append("%d 5 2 1 1 %s\n" % (e, " ".join(map(str, v))))
                f.write("".join(rows))
        f.write("$EndElements\n")


def run(args, mesh, ranks):
    directory = os.path.join(args.workdir, f"{mesh}_np{ranks}")
    shutil.rmtree(directory, ignore_errors=True)
    os.makedirs(directory)
    n = args.cells
    if mesh == "structured":
        shape, mesh_lines = f"box(0, 0, 0, {ranks}, 1, 1)", f"    set Cell size = {1 / n!r}"
    else:
        write_gmsh(os.path.join(directory, "box.msh"), ranks * n, n)
        shape, mesh_lines = "all", "    set Generator = file\n    set Mesh file = box.msh"
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(SCENE.format(shape=shape, mesh=mesh_lines))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    timed = ["sh", "-c", 'exec /usr/bin/time -f %M -o "peak.${OMPI_COMM_WORLD_RANK:-0}" "$0" scene.prm',
             os.path.abspath(args.hysteron)]
    command = ([args.mpiexec, "-np", str(ranks)] if ranks > 1 else []) + timed
    start = time.time()
    p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
    wall = time.time() - start
    if p.returncode != 0:
        sys.exit(f"{mesh} on {ranks} ranks failed ({p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    peaks = [int(open(os.path.join(directory, f"peak.{r}")).read().split()[-1]) / 1024 for r in range(ranks)]
    setup = re.search(r"\|\s*set-up\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s", p.stdout)
    cells = re.search(r"fem: (\d+) cells, (\d+) DoFs", p.stdout)
    return {"mesh": mesh, "ranks": ranks, "cells": int(cells.group(1)), "dofs": int(cells.group(2)),
            "setup": float(setup.group(1)), "wall": wall, "root": peaks[0],
            "others": max(peaks[1:]) if ranks > 1 else None}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--ranks", default="1,2,4,8")
    ap.add_argument("--cells", type=int, default=32, help="cells per metre (per rank: cells^3)")
    ap.add_argument("--meshes", default="structured,gmsh")
    ap.add_argument("--workdir", default="scaling_fem")
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--out")
    args = ap.parse_args()
    results = []
    for mesh in args.meshes.split(","):
        for ranks in (int(r) for r in args.ranks.split(",")):
            results.append(run(args, mesh, ranks))
            r = results[-1]
            print(f"{mesh} np={ranks}: {r['cells']} cells, set-up {r['setup']:.2f} s, "
                  f"peak rank 0 {r['root']:.0f} MB, others {r['others'] or 0:.0f} MB", file=sys.stderr)

    lines = ["| mesh | ranks | cells | DoFs | set-up [s] | run [s] | peak rank 0 [MB] | "
             "peak other ranks [MB] | largest peak / 1 rank |", "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        one = next(x for x in results if x["mesh"] == r["mesh"] and x["ranks"] == 1) \
            if any(x["mesh"] == r["mesh"] and x["ranks"] == 1 for x in results) else None
        largest = max(r["root"], r["others"] or 0)
        ratio = f"{largest / one['root']:.3f}" if one else "—"
        others = f"{r['others']:.0f}" if r["others"] is not None else "—"
        lines.append(f"| {r['mesh']} | {r['ranks']} | {r['cells']} | {r['dofs']} | {r['setup']:.2f} | "
                     f"{r['wall']:.1f} | {r['root']:.0f} | {others} | {ratio} |")
    table = "\n".join(lines)
    print(table)
    if args.out:
        with open(args.out, "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
