#!/usr/bin/python3
"""A large 3D FEM run: the perforated aluminium plate of prm/fem_perforated_plate.prm made
three-dimensional, quasi-static Bouc-Wen plasticity to collapse, on 1 and 2 MPI ranks.

    fem_plate_3d.py --hysteron build/hysteron [--cells 40,40,13] [--degree 2] [--b-bar]
                    [--ranks 1,2] [--increments 20] [--linear-tolerance 1e-10]
                    [--workdir DIR] [--out FILE.md] [--mesh-only]

Geometry (a quarter of the plate and half of its thickness, symmetric about x = 0, y = 0 and
z = 0): x in [0, 0.25] m, y in [0, 0.45] m, z in [0, 0.05] m, a hole of radius 0.125 m about the
z axis. The mesh is an O-grid of hexahedra written as a Gmsh file (format 2.2): n_theta cells
around the quarter hole, n_r cells from the hole to the outer edges (graded towards the hole,
s = (k / n_r)^1.5) and n_z layers. A ray at angle theta from the hole's centre meets the outer
boundary on x = 0.25 m (theta below atan(0.45 / 0.25)) or on y = 0.45 m; the cell lines blend the
circle into that boundary along the rays. Q2 on 40 x 40 x 13 cells has 531,441 DoFs, and so has
Q1 on 80 x 80 x 26 cells (--degree 1 --b-bar: the mean-dilatation element, which does not lock
in the isochoric plastic flow of the collapse).

Conditions: rollers on x = 0, y = 0 and z = 0 (the planes of symmetry), u_y = 4 mm on y = 0.45 m
(about 3.4 times the displacement at the limit load of the plane-stress plate) in --increments
equal increments. Material: the scene's aluminium (E = 72 GPa, nu = 0.22, sigma_y = 262 MPa,
a = 0.002, n = 8, isotropic, backward Euler). The tangent is not symmetric: GMRES with ML
aggregated on the rigid-body modes (the `automatic` solver above 100,000 DoFs).

Reported per rank count: the wall time of the whole run and of its timer sections, Newton and
Krylov iterations, the peak resident memory of each rank (GNU time), the force at 4 mm (the
collapse plateau), the force over the net-section limit sigma_y (W - R) T of the ligament in
uniaxial stress, and the force's change over the last quarter. Writes WORKDIR/results.json and,
with --out, a markdown table of the runs (doc/benchmarks/fem_plate_3d_*.md).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

W, HGT, T, R = 0.25, 0.45, 0.05, 0.125


def outer_point(theta):
    """Where the ray at angle theta meets the outer boundary x = W or y = HGT."""
    if math.tan(theta) * W <= HGT:
        return W, W * math.tan(theta)
    return HGT / math.tan(theta), HGT


def write_mesh(path, n_theta, n_r, n_z):
    def node(i, j, k):
        return 1 + i + (n_theta + 1) * (j + (n_r + 1) * k)

    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str((n_theta + 1) * (n_r + 1) * (n_z + 1))]
    for k in range(n_z + 1):
        z = T * k / n_z
        for j in range(n_r + 1):
            s = (j / n_r) ** 1.5
            for i in range(n_theta + 1):
                theta = 0.5 * math.pi * i / n_theta
                xo, yo = outer_point(theta)
                if i == n_theta:  # the ray along the y axis: exactly x = 0
                    xo = 0.0
                x = (1 - s) * R * math.cos(theta) + s * xo
                y = (1 - s) * R * math.sin(theta) + s * yo
                if i == n_theta:
                    x = 0.0
                if i == 0:
                    y = 0.0
                lines.append(f"{node(i, j, k)} {x!r} {y!r} {z!r}")
    lines.append("$EndNodes")
    elements = []
    for k in range(n_z):
        for j in range(n_r):
            for i in range(n_theta):
                # radial, then around (e_r x e_theta = +z), bottom face then top face
                bottom = [node(i, j, k), node(i, j + 1, k), node(i + 1, j + 1, k), node(i + 1, j, k)]
                top = [n + (n_theta + 1) * (n_r + 1) for n in bottom]
                elements.append("5 2 1 1 " + " ".join(map(str, bottom + top)))
    lines += ["$Elements", str(len(elements))]
    lines += [f"{e + 1} {text}" for e, text in enumerate(elements)]
    lines.append("$EndElements")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def scene(degree, increments, b_bar, linear_tolerance):
    return f"""set Dimension = 3
set Method = fem
set Body names = plate
set Boundary names = top, left, bottom, back
subsection Body plate
  set Shape = all
end
subsection Boundary top
  set Type = displacement
  set Faces = y+
  set Components = y
  set Displacement = 0; 4e-3 * t; 0
end
subsection Boundary left
  set Type = roller
  set Faces = x-
end
subsection Boundary bottom
  set Type = roller
  set Faces = y-
end
subsection Boundary back
  set Type = roller
  set Faces = z-
end
subsection Material
  set Model = bouc-wen
  set Young's modulus = 72e9
  set Poisson's ratio = 0.22
  subsection Bouc-Wen
    set Yield stress = 262e6
    set Post-yield stiffness ratio = 0.002
    set Smoothness n = 8
    set Beta = 0.5
    set Gamma = 0.5
    set Isotropic hardening fraction = 1
    set Integrator = backward euler
  end
end
subsection FEM
  set Degree = {degree}
  set B-bar = {'true' if b_bar else 'false'}
  set Number of increments = {increments}
  subsection Linear solver
    set Tolerance = {linear_tolerance!r}
  end
  subsection Mesh
    set Generator = file
    set Mesh file = plate.msh
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--hysteron", required=True)
    parser.add_argument("--cells", default="40,40,13", help="n_theta,n_r,n_z")
    parser.add_argument("--degree", type=int, default=2)
    parser.add_argument("--b-bar", action="store_true", help="the B-bar element (with --degree 1)")
    parser.add_argument("--linear-tolerance", type=float, default=1e-10,
                        help="FEM/Linear solver/Tolerance: the Krylov solver's relative residual reduction")
    parser.add_argument("--ranks", default="1,2")
    parser.add_argument("--increments", type=int, default=20)
    parser.add_argument("--workdir", default="/tmp/fem_plate_3d")
    parser.add_argument("--mesh-only", action="store_true")
    parser.add_argument("--out", help="write the markdown table of the runs here")
    args = parser.parse_args()
    n_theta, n_r, n_z = map(int, args.cells.split(","))
    os.makedirs(args.workdir, exist_ok=True)
    mesh = os.path.join(args.workdir, "plate.msh")
    write_mesh(mesh, n_theta, n_r, n_z)
    n_nodes = (args.degree * n_theta + 1) * (args.degree * n_r + 1) * (args.degree * n_z + 1)
    print(f"{n_theta * n_r * n_z} cells, {3 * n_nodes} DoFs with Q{args.degree}: {mesh}", flush=True)
    if args.mesh_only:
        return
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    results = []
    for ranks in map(int, args.ranks.split(",")):
        directory = os.path.join(args.workdir, f"np{ranks}")
        shutil.rmtree(directory, ignore_errors=True)
        os.makedirs(directory)
        shutil.copy(mesh, directory)
        with open(os.path.join(directory, "scene.prm"), "w") as f:
            f.write(scene(args.degree, args.increments, args.b_bar, args.linear_tolerance))
        # GNU time around each rank: its peak resident set.
        # (appended to one file: the ranks' reports would interleave on stderr)
        rss_file = os.path.join(directory, "peak_rss.txt")
        command = ["mpirun", "-np", str(ranks), "/usr/bin/time", "-a", "-o", rss_file, "-f", "peak_rss_kb %M",
                   os.path.abspath(args.hysteron), "scene.prm"]
        start = time.monotonic()
        p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
        wall = time.monotonic() - start
        log = p.stdout + p.stderr
        with open(os.path.join(directory, "run.log"), "w") as f:
            f.write(log)
        if p.returncode != 0:
            sys.exit(f"{' '.join(command)} failed ({p.returncode}); see {directory}/run.log")
        sections = {m.group(1).strip(): float(m.group(3)) for m in
                    re.finditer(r"\| ([A-Za-z -]+?)\s+\|\s+(\d+) \|\s+([0-9.e+-]+)s \|", log)}
        summary = re.search(r"\((\d+) steps, (\d+) Newton iterations.*?(\d+) DoFs", log)
        linear = re.search(r"(\d+) linear iterations", log)
        rss = [int(v) for v in re.findall(r"peak_rss_kb (\d+)", open(rss_file).read())]
        with open(os.path.join(directory, "output", "reactions.csv")) as f:
            rows = [line.strip().split(",") for line in f if line.strip()]
        column = rows[0].index("top_y")
        force = [float(r[column]) for r in rows[1:]]
        # The net-section limit: the ligament (W - R) x T yields at sigma_y in uniaxial stress.
        net_section = 262e6 * (W - R) * T
        results.append(dict(ranks=ranks, wall=wall, sections=sections,
                            force_over_net_section=force[-1] / net_section,
                            newton=int(summary.group(2)) if summary else None,
                            dofs=int(summary.group(3)) if summary else None,
                            linear_iterations=int(linear.group(1)) if linear else None,
                            peak_rss_mb=[v / 1024 for v in rss], force=force[-1],
                            last_quarter=force[-1] / force[(3 * len(force)) // 4] - 1))
        print(json.dumps(results[-1]), flush=True)
    with open(os.path.join(args.workdir, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    if len(results) > 1:
        print(f"speed-up on {results[-1]['ranks']} ranks: {results[0]['wall'] / results[-1]['wall']:.2f}")
    if args.out:
        element = f"Q{args.degree}" + (" + B-bar" if args.b_bar else "")
        model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                      if line.startswith("model name")), "?")
        lines = [f"{element}, {n_theta} x {n_r} x {n_z} cells, {3 * n_nodes:,} DoFs, {args.increments} increments "
                 f"to u_y = 4 mm, GMRES + ML on the rigid-body modes, Krylov tolerance {args.linear_tolerance:g}; "
                 f"machine: {os.cpu_count()} cores, {model}; the build of --hysteron (Release for timings); one run per rank count; command: "
                 f"`benchmarks/fem_plate_3d.py --hysteron build/hysteron --cells {args.cells} --degree {args.degree}"
                 f"{' --b-bar' if args.b_bar else ''} --ranks {args.ranks} --increments {args.increments} "
                 f"--linear-tolerance {args.linear_tolerance:g}`", "",
                 "| ranks | wall [s] | assembly [s] | linear solve [s] | Newton iterations | Krylov iterations | "
                 "peak memory per rank [MB] | F at 4 mm / net-section limit | change over the last quarter | speed-up |",
                 "|---|---|---|---|---|---|---|---|---|---|"]
        for r in results:
            speed_up = f"{results[0]['wall'] / r['wall']:.2f}" if results[0]["ranks"] == 1 else "—"
            lines.append(f"| {r['ranks']} | {r['wall']:.1f} | {r['sections'].get('FEM assembly', float('nan')):.1f} | "
                         f"{r['sections'].get('FEM linear solve', float('nan')):.1f} | {r['newton']} | "
                         f"{r['linear_iterations']} | {', '.join(f'{m:.0f}' for m in r['peak_rss_mb'])} | "
                         f"{r['force_over_net_section']:.4f} | {100 * r['last_quarter']:+.2f} % | {speed_up} |")
        with open(args.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
