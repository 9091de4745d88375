#!/usr/bin/env python3
"""Write the damaged Gmsh meshes of the tests/fem_input/mesh_*.prm cases (ASCII format 2.2).

Every mesh is the bar [0, 1] x [0, 0.1] m (3D: x [0, 0.1] x [0, 0.01] m) of 10 x 2 cells,
with one defect:
  clockwise_triangle.msh       triangles; element 7 listed clockwise (repaired)
  clockwise_quadrilateral.msh  quadrilaterals; element 7 clockwise (repaired)
  inverted_hexahedron.msh      3D, 10 x 2 x 1 hexahedra; element 7 with its faces swapped (repaired)
  inverted_tetrahedron.msh     3D, each hexahedron as 6 tetrahedra; element 40 mirrored (repaired)
  bowtie_quadrilateral.msh     element 7 with two nodes swapped: a self-intersecting bow-tie
  bowtie_binary.msh            the same in Gmsh's binary format 2.2
  coincident_nodes.msh         element 7's fourth node is a second node at its third node's point
  sliver.msh                   triangles; the square [0.4, 0.5] x [0, 0.05] as four, one of them
                               (element 9) 1e-12 m high
  sliver_column.msh            a column of quadrilaterals 1e-12 m wide at x = 0.5
  comment_line.msh             a '#' line before $MeshFormat
  malformed_node.msh           a node line with 'abc' for a coordinate (line 8)
  truncated.msh                the file cut off in $Elements
Run: python3 make_damaged_meshes.py (writes into this folder)."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
NX, NY, L, H = 10, 2, 1.0, 0.1


def write(name, nodes, elements, before="", cut=None):
    lines = ([before] if before else []) + ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(nodes))]
    lines += [f"{k + 1} " + " ".join(repr(float(c)) for c in p) for k, p in enumerate(nodes)]
    lines += ["$EndNodes", "$Elements", str(len(elements))]
    lines += [f"{k + 1} {kind} 2 1 1 " + " ".join(map(str, v)) for k, (kind, v) in enumerate(elements)]
    lines.append("$EndElements")
    if cut is not None:
        lines = lines[:cut]
    with open(os.path.join(HERE, name), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_binary(name, nodes, elements):
    """Gmsh 2.2 binary (little-endian int32 and float64, one block per element type)."""
    data = b"$MeshFormat\n2.2 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n"
    data += b"$Nodes\n%d\n" % len(nodes)
    data += b"".join(struct.pack("<i3d", k + 1, *map(float, p)) for k, p in enumerate(nodes))
    data += b"\n$EndNodes\n$Elements\n%d\n" % len(elements)
    kind = elements[0][0]
    data += struct.pack("<3i", kind, len(elements), 2)
    data += b"".join(struct.pack("<%di" % (3 + len(v)), k + 1, 1, 1, *v) for k, (_, v) in enumerate(elements))
    data += b"\n$EndElements\n"
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def plane(xs):
    """Nodes on the columns xs x (0, H/2, H); quadrilaterals counter-clockwise."""
    nodes = [(x, H * j / NY, 0) for j in range(NY + 1) for x in xs]
    n = len(xs)
    quads = [[1 + j * n + i, 2 + j * n + i, 2 + (j + 1) * n + i, 1 + (j + 1) * n + i]
             for j in range(NY) for i in range(n - 1)]
    return nodes, quads


xs = [L * i / NX for i in range(NX + 1)]
nodes, quads = plane(xs)
QUAD, TRI, TET, HEX = 3, 2, 4, 5

elements = [(QUAD, q) for q in quads]
elements[6] = (QUAD, elements[6][1][::-1])
write("clockwise_quadrilateral.msh", nodes, elements)

triangles = []
for a, b, c, d in quads:
    triangles += [(TRI, [a, b, c]), (TRI, [a, c, d])]
triangles[6] = (TRI, triangles[6][1][::-1])
write("clockwise_triangle.msh", nodes, triangles)

elements = [(QUAD, q) for q in quads]
a, b, c, d = elements[6][1]
elements[6] = (QUAD, [a, b, d, c])
write("bowtie_quadrilateral.msh", nodes, elements)
write_binary("bowtie_binary.msh", nodes, elements)

elements = [(QUAD, q) for q in quads]
a, b, c, d = elements[6][1]
doubled = nodes + [nodes[c - 1]]
elements[6] = (QUAD, [a, b, c, len(doubled)])
write("coincident_nodes.msh", doubled, elements)

sliver_nodes, sliver_quads = plane(sorted(xs + [0.5 + 1e-12]))
write("sliver_column.msh", sliver_nodes, [(QUAD, q) for q in sliver_quads])

# The square (A, B, D, C) = [0.4, 0.5] x [0, 0.05] as four triangles around P = (0.45, 1e-12).
sliver = []
for a, b, c, d in quads:
    if nodes[a - 1][0] == 0.4 and nodes[a - 1][1] == 0.0:
        p = len(nodes) + 1
        sliver += [(TRI, [a, b, p]), (TRI, [a, p, d]), (TRI, [p, b, c]), (TRI, [d, p, c])]
    else:
        sliver += [(TRI, [a, b, c]), (TRI, [a, c, d])]
write("sliver.msh", nodes + [(0.45, 1e-12, 0)], sliver)

write("comment_line.msh", nodes, [(QUAD, q) for q in quads], before="# the bar, 10 x 2 cells")
write("truncated.msh", nodes, [(QUAD, q) for q in quads], cut=-8)
write("malformed_node.msh", nodes, [(QUAD, q) for q in quads])
with open(os.path.join(HERE, "malformed_node.msh")) as f:
    text = f.read().split("\n")
text[7] = text[7].replace(" 0.0 0.0", " abc 0.0", 1)  # node 3: y = abc
with open(os.path.join(HERE, "malformed_node.msh"), "w") as f:
    f.write("\n".join(text))

# 3D: the bar 0.1 x 0.01 thick (a cross-section of 1e-3 m^2, as the 2D bar of thickness 0.01).
NZ, T = 1, 0.01
nodes3 = [(L * i / NX, H * j / NY, T * k / NZ) for k in range(NZ + 1) for j in range(NY + 1) for i in range(NX + 1)]


def node3(i, j, k):
    return 1 + i + (NX + 1) * (j + (NY + 1) * k)


hexes = [[node3(i, j, 0), node3(i + 1, j, 0), node3(i + 1, j + 1, 0), node3(i, j + 1, 0),
          node3(i, j, 1), node3(i + 1, j, 1), node3(i + 1, j + 1, 1), node3(i, j + 1, 1)]
         for j in range(NY) for i in range(NX)]
elements = [(HEX, h) for h in hexes]
elements[6] = (HEX, elements[6][1][4:] + elements[6][1][:4])
write("inverted_hexahedron.msh", nodes3, elements)

tets = []
for v in hexes:  # six tetrahedra around the diagonal v0-v6, all positively oriented
    for a, b in ((1, 2), (2, 3), (3, 7), (7, 4), (4, 5), (5, 1)):
        tets.append((TET, [v[0], v[a], v[b], v[6]]))
tets[39] = (TET, [tets[39][1][1], tets[39][1][0]] + tets[39][1][2:])
write("inverted_tetrahedron.msh", nodes3, tets)
