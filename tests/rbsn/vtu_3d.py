#!/usr/bin/env python3
"""The RBSN's 3D VTU on 1 and 2 ranks: the cells as closed polyhedra that fill the body, the
facets as polygons, each once, the arrays complete.

The scene: a box 1 x 0.6 x 0.4 m with a bore (cylinder r = 0.12 m along z, the cells clipped to
its inscribed 32-gon prism), d_m = 0.1 m, every cell moved by a small rigid motion
u = a + w x x (a = (1e-3, -2e-3, 5e-4) m, w = (1e-4, -2e-4, 1.5e-4) rad; `Region = all`,
Components = all), static, springs.csv written. It runs on 1 rank (one .vtu per output) and on
2 ranks (a .pvtu and one piece per rank). For the last output of each run:
  * every VTK_POLYHEDRON (type 42) is closed: the area vectors of its faces (read from the
    "faces" stream through "faceoffsets") add up to zero (1e-12 of its area), and is
    oriented outwards (its volume by the divergence theorem is positive); it is watertight
    for VTK: its faces share their points' ids, every edge belongs to exactly two faces, in
    opposite directions (before the fix in output.cc every face had its own copies of its
    points, a polygon soup to VTK); its "connectivity" lists the points its faces use, once
    each;
  * the polyhedra's volumes add up to the body's volume, 0.24 - 16 r^2 sin(pi/16) 0.4 =
    0.2220204759 m^3 (1e-12), and their cell numbers are 0 ... n - 1, every cell at least once
    (a cell cut by the bore has several convex pieces), each in one piece only;
  * every facet (VTK_POLYGON, facet >= 0) appears in one piece only, the facet numbers are
    0 ... m - 1 (springs.csv's rows), and each facet's polygons add up to its area in springs.csv
    (1e-12);
  * the point data "displacement" is the rigid motion a + w x p at every point of every cell
    and facet (1e-15 m), and the cells' "rotation" is w (1e-15 rad);
  * the arrays the .pvtu declares exist in every piece, with its number of components and one
    tuple per cell (per point for "displacement");
  * the 1- and 2-rank runs hold the same cells (the same volume per cell number, 1e-12) and
    facets.

Usage: vtu_3d.py HYSTERON MPIEXEC WORKDIR
"""
import base64
import csv
import math
import os
import re
import shutil
import struct
import subprocess
import sys

SCENE = """set Dimension = 3
set Method = rbsn
set Body names = block
set Boundary names = all
set Random seed = 4
subsection Material
  set Model = linear elastic
  set Young's modulus = 1e9
  set Poisson's ratio = 0
end
subsection Body block
  set Shape = box(0, 0, 0, 1, 0.6, 0.4) - cylinder(0.5, 0.3, -1, 0.5, 0.3, 1, 0.12)
end
subsection Boundary all
  set Type = displacement
  set Region = all
  set Displacement = (1e-3 - 2e-4*z - 1.5e-4*y)*t; (-2e-3 + 1.5e-4*x - 1e-4*z)*t; (5e-4 + 1e-4*y + 2e-4*x)*t
end
subsection RBSN
  set Analysis = static
  set Minimum distance = 0.1
  set Number of increments = 1
  set Write spring table = true
end
subsection Output
  set Directory = output
  set Write VTU = true
end
"""
A, W = (1e-3, -2e-3, 5e-4), (1e-4, -2e-4, 1.5e-4)
VOLUME = 0.24 - 16 * 0.12 ** 2 * math.sin(math.pi / 16) * 0.4


def arrays(path):
    """name -> (values, components) of every DataArray (binary, UInt64 header); the points'
    coordinates under "points"."""
    codes = {"Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B"}
    result = {}
    text = open(path).read()
    for m in re.finditer(r'<DataArray type="(\w+)"( Name="([^"]*)")? NumberOfComponents="(\d+)" '
                         r'format="binary">\s*(.*?)\s*</DataArray>', text, re.S):
        raw = base64.b64decode(m.group(5))
        n = struct.unpack("<Q", raw[:8])[0]
        code = codes[m.group(1)]
        values = struct.unpack("<%d%s" % (n // struct.calcsize(code), code), raw[8:8 + n])
        result[m.group(3) or "points"] = (values, int(m.group(4)))
    cells = int(re.search(r'NumberOfCells="(\d+)"', text).group(1))
    points = int(re.search(r'NumberOfPoints="(\d+)"', text).group(1))
    return result, cells, points


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def area_vector(points):
    v = [0.0, 0.0, 0.0]
    for k in range(1, len(points) - 1):
        c = cross(sub(points[k], points[0]), sub(points[k + 1], points[0]))
        v = [v[i] + 0.5 * c[i] for i in range(3)]
    return v


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def check_piece(path, failures):
    """The polyhedra (cell number, volume) and the facets (number, area) of one piece."""
    a, n_cells, n_points = arrays(path)
    xyz = a["points"][0]
    P = [xyz[3 * k:3 * k + 3] for k in range(n_points)]
    conn, offsets, types = a["connectivity"][0], a["offsets"][0], a["types"][0]
    faces, face_offsets = a["faces"][0], a["faceoffsets"][0]
    cell, facet = a["cell"][0], a["facet"][0]
    disp, rotation = a["displacement"][0], a["rotation"][0]
    name = os.path.basename(path)
    if len(types) != n_cells or len(offsets) != n_cells or len(face_offsets) != n_cells:
        failures.append(f"{name}: {len(types)} types, {len(offsets)} offsets, {len(face_offsets)} "
                        f"face offsets for {n_cells} cells")
    for key, (values, components) in a.items():
        per = n_points if key in ("points", "displacement") else n_cells
        if key in ("connectivity", "offsets", "faces", "faceoffsets", "types"):
            continue
        if len(values) != per * components:
            failures.append(f"{name}: {key} has {len(values)} values for {per} tuples of {components}")
    # The rigid motion at every point.
    worst = 0
    for k, p in enumerate(P):
        expected = [A[i] + c for i, c in enumerate(cross(W, p))]
        worst = max(worst, max(abs(disp[3 * k + i] - expected[i]) for i in range(3)))
    if worst > 1e-15:
        failures.append(f"{name}: the displacement differs from a + w x p by {worst:.3g} m")
    polyhedra, polygons = [], []
    open_edges = [0]
    start, face_start = 0, 0
    for k in range(n_cells):
        ids = conn[start:offsets[k]]
        start = offsets[k]
        if types[k] == 42:
            stream = faces[face_start:face_offsets[k]]
            face_start = face_offsets[k]
            loops, i = [], 1
            for _ in range(stream[0]):
                m = stream[i]
                loops.append(list(stream[i + 1:i + 1 + m]))
                i += 1 + m
            if i != len(stream):
                failures.append(f"{name}: cell {k}: its face stream has {len(stream)} entries, the faces use {i}")
            used = sorted({q for loop in loops for q in loop})
            if used != sorted(ids):
                failures.append(f"{name}: cell {k}: its connectivity does not list the points its faces "
                                f"use, each once")
            # Watertight and consistently oriented: every edge (a, b) of a face is the edge
            # (b, a) of exactly one other face (the faces share their points' ids).
            edges = {}
            for loop in loops:
                for j in range(len(loop)):
                    edge = (loop[j], loop[(j + 1) % len(loop)])
                    edges[edge] = edges.get(edge, 0) + 1
            if any(n != 1 or edges.get((b, a), 0) != 1 for (a, b), n in edges.items()):
                open_edges[0] += 1
            vectors = [area_vector([P[q] for q in loop]) for loop in loops]
            total = [sum(v[i] for v in vectors) for i in range(3)]
            surface = sum(norm(v) for v in vectors)
            volume = sum(sum(P[loop[0]][i] * v[i] for i in range(3)) for loop, v in zip(loops, vectors)) / 3
            if norm(total) > 1e-12 * surface:
                failures.append(f"{name}: polyhedron {k} (cell {cell[k]}) is not closed: "
                                f"|sum of area vectors| = {norm(total):.3g} of {surface:.3g}")
            if not volume > 0:
                failures.append(f"{name}: polyhedron {k} (cell {cell[k]}) has volume {volume:.3g}")
            if cell[k] < 0 or facet[k] != -1:
                failures.append(f"{name}: polyhedron {k} has cell {cell[k]}, facet {facet[k]}")
            if max(abs(rotation[3 * k + i] - W[i]) for i in range(3)) > 1e-15:
                failures.append(f"{name}: cell {cell[k]} rotates by {rotation[3 * k:3 * k + 3]}")
            polyhedra.append((cell[k], volume))
        elif types[k] == 7:
            if facet[k] < 0 or cell[k] != -1:
                failures.append(f"{name}: polygon {k} has cell {cell[k]}, facet {facet[k]}")
            if face_offsets[k] != -1:
                failures.append(f"{name}: polygon {k} has face offset {face_offsets[k]}")
            polygons.append((facet[k], norm(area_vector([P[q] for q in ids]))))
        else:
            failures.append(f"{name}: cell {k} has VTK type {types[k]}")
    if open_edges[0]:
        failures.append(f"{name}: {open_edges[0]} of {len(polyhedra)} polyhedra are not watertight (an edge "
                        f"not shared by exactly two faces in opposite directions)")
    return polyhedra, polygons


def summarise(label, pieces, springs, failures):
    """Check the pieces of one output together; return volume per cell and area per facet."""
    polyhedra, polygons, owner_cell, owner_facet = [], [], {}, {}
    for piece in pieces:
        p, q = check_piece(piece, failures)
        for c, _ in p:
            if owner_cell.setdefault(c, piece) != piece:
                failures.append(f"{label}: cell {c} in two pieces")
        for e, _ in q:
            if owner_facet.setdefault(e, piece) != piece:
                failures.append(f"{label}: facet {e} in two pieces")
        polyhedra += p
        polygons += q
    volume = sum(v for _, v in polyhedra)
    if abs(volume / VOLUME - 1) > 1e-12:
        failures.append(f"{label}: the polyhedra hold {volume!r} m^3, the body {VOLUME!r}")
    per_cell, per_facet = {}, {}
    for c, v in polyhedra:
        per_cell[c] = per_cell.get(c, 0) + v
    for e, s in polygons:
        per_facet[e] = per_facet.get(e, 0) + s
    if sorted(per_cell) != list(range(len(per_cell))):
        failures.append(f"{label}: the cell numbers are not 0 ... {len(per_cell) - 1}")
    if sorted(per_facet) != list(range(len(springs))):
        failures.append(f"{label}: {len(per_facet)} facets in the VTU, {len(springs)} in springs.csv")
    worst = max(abs(per_facet.get(e, 0) - float(r["area"])) / float(r["area"]) for e, r in enumerate(springs))
    if worst > 1e-12:
        failures.append(f"{label}: the facets' polygons differ from springs.csv's areas by {worst:.3g}")
    print(f"{label}: {len(pieces)} piece(s), {len(polyhedra)} polyhedra of {len(per_cell)} cells, volume "
          f"{volume:.13f} m^3 ({volume / VOLUME - 1:+.1e}), {len(polygons)} polygons of {len(per_facet)} "
          f"facets (areas within {worst:.1e})")
    return per_cell, per_facet


def main():
    hysteron, mpiexec, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    failures, results = [], {}
    for ranks in (1, 2):
        directory = os.path.join(work, f"np{ranks}")
        os.makedirs(directory)
        with open(os.path.join(directory, "scene.prm"), "w") as f:
            f.write(SCENE)
        command = ([mpiexec, "-np", str(ranks)] if ranks > 1 else []) + [hysteron, "--quiet", "scene.prm"]
        p = subprocess.run(command, cwd=directory, env=env, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"{ranks} rank(s): exit {p.returncode}: {p.stderr[-2000:]}")
        out = os.path.join(directory, "output")
        with open(os.path.join(out, "springs.csv")) as f:
            springs = list(csv.DictReader(f))
        records = re.findall(r'file="([^"]+)"', open(os.path.join(out, "rbsn.pvd")).read())
        last = os.path.join(out, records[-1])
        if ranks == 1:
            if records != ["rbsn-00000.vtu", "rbsn-00001.vtu"]:
                failures.append(f"1 rank: the PVD names {records}")
            pieces = [last]
        else:
            if records != ["rbsn-00000.pvtu", "rbsn-00001.pvtu"]:
                failures.append(f"2 ranks: the PVD names {records}")
            text = open(last).read()
            sources = re.findall(r'<Piece Source="([^"]+)"', text)
            if sources != ["rbsn-00001.0000.vtu", "rbsn-00001.0001.vtu"]:
                failures.append(f"2 ranks: the record names the pieces {sources}")
            pieces = [os.path.join(out, s) for s in sources]
            declared = re.findall(r'<PDataArray type="(\w+)" Name="([^"]+)" NumberOfComponents="(\d+)"', text)
            for piece in pieces:
                a, _, _ = arrays(piece)
                body = open(piece).read()
                for kind, name, components in declared:
                    if name not in a:
                        failures.append(f"{os.path.basename(piece)} has no array {name}")
                    elif a[name][1] != int(components) or \
                            f'<DataArray type="{kind}" Name="{name}"' not in body:
                        failures.append(f"{os.path.basename(piece)}: {name} is not {kind} x {components}")
            if len(declared) != 17:
                failures.append(f"the record declares {len(declared)} arrays, not 17")
        results[ranks] = summarise(f"{ranks} rank(s)", pieces, springs, failures)
    cells_1, facets_1 = results[1]
    cells_2, facets_2 = results[2]
    if sorted(cells_1) != sorted(cells_2) or \
            max(abs(cells_1[c] - cells_2.get(c, 0)) for c in cells_1) > 1e-12 * VOLUME:
        failures.append("the cells' volumes differ between 1 and 2 ranks")
    if sorted(facets_1) != sorted(facets_2) or \
            max(abs(facets_1[e] - facets_2.get(e, 0)) / facets_1[e] for e in facets_1) > 1e-12:
        failures.append("the facets' areas differ between 1 and 2 ranks")
    if failures:
        sys.exit("FAILED:\n  " + "\n  ".join(failures[:40]))
    print("passed: closed polyhedra fill the body, every facet once, the arrays complete, on 1 and 2 ranks")


if __name__ == "__main__":
    main()
