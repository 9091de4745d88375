#!/usr/bin/env python3
"""Write bar_groups.msh: the bar [0, 1] x [0, 0.1] m as 20 x 2 quadrilaterals in Gmsh's
ASCII format 2.2, with named physical groups (what Gmsh writes for a .geo with
Physical Curve("left") = ...; Physical Surface("bar") = ...):
  1 "left"  (dimension 1): the edge x = 0      2 "right" (dimension 1): the edge x = 1
  4 "top"   (dimension 1): the edge y = 0.1    3 "bar"   (dimension 2): every cell
With --triangles, bar_groups_triangles.msh: each square split into two triangles along
alternating diagonals (80 triangles), the same nodes and groups.
Run: python3 make_bar_groups.py > bar_groups.msh
     python3 make_bar_groups.py --triangles > bar_groups_triangles.msh"""
import sys

nx, ny, L, H = 20, 2, 1.0, 0.1
triangles = "--triangles" in sys.argv[1:]


def node(i, j):
    return 1 + j * (nx + 1) + i


lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "4",
         '1 1 "left"', '1 2 "right"', '2 3 "bar"', '1 4 "top"', "$EndPhysicalNames", "$Nodes",
         str((nx + 1) * (ny + 1))]
for j in range(ny + 1):
    for i in range(nx + 1):
        lines.append(f"{node(i, j)} {repr(L * i / nx)} {repr(H * j / ny)} 0")
lines.append("$EndNodes")
elements = []
for j in range(ny):  # left edge (physical 1, elementary 4), right edge (2, 2)
    elements.append(f"1 2 1 4 {node(0, j)} {node(0, j + 1)}")
    elements.append(f"1 2 2 2 {node(nx, j)} {node(nx, j + 1)}")
for i in range(nx):  # top edge (physical 4, elementary 3)
    elements.append(f"1 2 4 3 {node(i, ny)} {node(i + 1, ny)}")
for j in range(ny):
    for i in range(nx):
        a, b, c, d = node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)
        if not triangles:
            elements.append(f"3 2 3 1 {a} {b} {c} {d}")
        elif (i + j) % 2 == 0:  # diagonal a-c
            elements += [f"2 2 3 1 {a} {b} {c}", f"2 2 3 1 {a} {c} {d}"]
        else:  # diagonal b-d
            elements += [f"2 2 3 1 {a} {b} {d}", f"2 2 3 1 {b} {c} {d}"]
lines += ["$Elements", str(len(elements))]
lines += [f"{k + 1} {e}" for k, e in enumerate(elements)]
lines.append("$EndElements")
print("\n".join(lines))
