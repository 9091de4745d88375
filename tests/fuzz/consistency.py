"""Inputs that parse but are physically inconsistent, for tests/fuzz/fuzz.py.

  conflict     a new boundary condition on the faces or region of a condition that
               prescribes motion (fixed, roller, velocity, displacement), a displacement of
               1 mm/s in the same components; listed after it and before it
  locking      Poisson's ratio 0.4999 in every material of a scene that the FEM runs
  memory       a size entry (cell size, minimum distance, particles per cell, refinements)
               that makes the run far too large for the machine's memory
  mesh         a Gmsh mesh of a scene that reads one, with one defect: an element listed
               clockwise, two nodes of an element swapped (a bow-tie), a node moved onto
               another of its element, a node moved to 1e-13 m of the opposite side (a
               sliver), a '#' line before $MeshFormat, a coordinate that is not a number

Each kind has its rule (expectation()); a run that breaks it is a rule violation beside the
general rules of fuzz.py (no crash, no hang, exit 1 names a path and writes nothing).
"""
import os
import re

MOTION = ("fixed", "roller", "velocity", "displacement")
SIZE_FACTORS = {"Cell size": 1e-4, "Minimum distance": 1e-4, "Particles per cell": None,
                "Refinements": None}
MESH_DEFECTS = ["clockwise", "bow-tie", "coincident", "sliver", "comment", "not a number"]


def top(scene, key, default=""):
    return next((v for _, section, k, v in scene.entries if section == "" and k == key), default)


def dimension(scene):
    return int(top(scene, "Dimension", "2") or 2)


def output_directory(scene):
    return next((v for _, section, key, v in scene.entries
                 if section == "Output" and key == "Directory"), "output") or "output"


def boundary_sections(scene):
    """(name, {key: value}) of every Boundary subsection, in file order."""
    out = {}
    for _, section, key, value in scene.entries:
        m = re.fullmatch(r"Boundary (.+)", section)
        if m:
            out.setdefault(m.group(1), {})[key] = value
    return list(out.items())


def runs_fem(scene):
    method = top(scene, "Method")
    if method == "fem":
        return True
    methods = next((v for _, s, k, v in scene.entries if s == "Compare" and k == "Methods"), "mpm, fem")
    return method == "compare" and "fem" in methods


def mutations(s, scene, mesh_scene=False):
    """The mutations of this module for scene index @p s: (s, kind, detail)."""
    out = []
    if mesh_scene:
        for defect in MESH_DEFECTS:
            for element in range(3):
                out.append((s, "mesh", [defect, element]))
        return out
    for b, (name, entries) in enumerate(boundary_sections(scene)):
        if entries.get("Type", "").strip() in MOTION:
            out.append((s, "conflict", [b, "after"]))
            out.append((s, "conflict", [b, "before"]))
    if runs_fem(scene) and any(k == "Poisson's ratio" for _, _, k, _ in scene.entries):
        out.append((s, "locking", []))
    for i, (_, section, key, value) in enumerate(scene.entries):
        if key in SIZE_FACTORS and value.strip():
            out.append((s, "memory", [i]))
    return out


def _replace_entry(lines, scene, i, new):
    line, section, key, value = scene.entries[i]
    indent = lines[line][:len(lines[line]) - len(lines[line].lstrip())]
    lines[line] = f"{indent}set {key} = {new}"


def build(scene, kind, detail, lines, workdir):
    """Apply the mutation to @p lines (the scene's) in place; a label. Mesh defects write the
    damaged mesh into @p workdir under the scene's mesh file name."""
    if kind == "conflict":
        b, where = detail
        name, entries = boundary_sections(scene)[b]
        dim = dimension(scene)
        components = entries.get("Components", "all")
        block = ["subsection Boundary fuzz_conflict", "  set Type = displacement"]
        for key, value in entries.items():
            if key not in ("Type", "Components", "Velocity", "Displacement"):
                block.append(f"  set {key} = {value}")
        block.append(f"  set Components = {components}")
        block.append("  set Displacement = " + "; ".join(["1e-3*t"] * dim))
        block.append("end")
        names_line = next(l for l, section, key, _ in scene.entries
                          if section == "" and key == "Boundary names")
        old = [n.strip() for n in lines[names_line].split("=", 1)[1].split(",")]
        new = old + ["fuzz_conflict"] if where == "after" else ["fuzz_conflict"] + old
        lines[names_line] = "set Boundary names = " + ", ".join(new)
        lines.extend(block)
        return f"Boundary fuzz_conflict driven on the nodes of Boundary {name} ({where} it)"
    if kind == "locking":
        for i, (_, section, key, value) in enumerate(scene.entries):
            if key == "Poisson's ratio":
                _replace_entry(lines, scene, i, "0.4999")
        return "Poisson's ratio = 0.4999 (FEM)"
    if kind == "memory":
        i = detail[0]
        _, section, key, value = scene.entries[i]
        dim = dimension(scene)
        if key == "Particles per cell":
            new = "100000"
        elif key == "Refinements":
            new = str(int(float(value)) + (12 if dim == 2 else 8))
        else:
            new = repr(float(value) * (1e-4 if dim == 2 else 1e-3))
        _replace_entry(lines, scene, i, new)
        return f"{section}/{key} = {new} (memory)"
    if kind == "mesh":
        defect, element = detail
        name = scene.inputs[0]
        with open(os.path.join(os.path.dirname(scene.path), name)) as f:
            text = f.read()
        damaged, what = damage_mesh(text, defect, element)
        target = os.path.join(workdir, name)
        os.makedirs(os.path.dirname(target) or workdir, exist_ok=True)
        with open(target, "w") as f:
            f.write(damaged)
        return f"{name}: {what}"
    raise ValueError(kind)


def damage_mesh(text, defect, pick):
    """A Gmsh 2.2 ASCII mesh with one defect in the @p pick-th cell of the highest dimension
    (spread over the mesh); the text and a description."""
    lines = text.split("\n")
    n0 = lines.index("$Nodes")
    n_nodes = int(lines[n0 + 1])
    nodes = {}
    for k in range(n_nodes):
        words = lines[n0 + 2 + k].split()
        nodes[int(words[0])] = (n0 + 2 + k, [float(w) for w in words[1:4]])
    e0 = lines.index("$Elements")
    n_elements = int(lines[e0 + 1])
    cells = []  # (line, type, node ids, number of tags)
    # Gmsh 2.2 element types: 2 triangle, 3 quadrilateral, 4 tetrahedron, 5 hexahedron.
    for k in range(n_elements):
        words = lines[e0 + 2 + k].split()
        kind, n_tags = int(words[1]), int(words[2])
        if kind in (2, 3, 4, 5):
            cells.append((e0 + 2 + k, kind, [int(w) for w in words[3 + n_tags:]], n_tags))
    highest = max(c[1] in (4, 5) for c in cells)
    cells = [c for c in cells if (c[1] in (4, 5)) == highest]
    line, kind, ids, n_tags = cells[(pick * 7 + 3) % len(cells)]
    number = lines[line].split()[0]

    def set_cell(new_ids):
        words = lines[line].split()
        lines[line] = " ".join(words[:3 + n_tags] + [str(i) for i in new_ids])

    def set_node(i, p):
        words = lines[nodes[i][0]].split()
        lines[nodes[i][0]] = " ".join([words[0]] + [repr(c) for c in p])

    if defect == "clockwise":
        # Reversed orientation: the mirrored vertex order (2D: clockwise).
        if kind in (2, 3):
            set_cell(list(reversed(ids)))
        elif kind == 4:
            set_cell([ids[1], ids[0]] + ids[2:])
        else:
            set_cell(ids[4:] + ids[:4])
        what = f"element {number} with the mirrored vertex order"
    elif defect == "bow-tie":
        # Two neighbouring vertices swapped: a quadrilateral crosses itself; a triangle or
        # tetrahedron is only mirrored by it.
        set_cell([ids[1], ids[0]] + ids[2:] if kind in (2, 4) else [ids[0], ids[2], ids[1]] + ids[3:])
        what = f"element {number} with two vertices swapped"
    elif defect == "coincident":
        set_node(ids[1], nodes[ids[0]][1])
        what = f"node {ids[1]} of element {number} moved onto node {ids[0]}"
    elif defect == "sliver":
        # The first vertex to 1e-13 m of the line (plane) through its next two.
        a, b, c = (nodes[i][1] for i in ids[:3])
        p = [(b[d] + c[d]) / 2 + (1e-13 if d == 0 else 0.0) for d in range(3)]
        set_node(ids[0], p)
        what = f"node {ids[0]} of element {number} moved to 1e-13 m of the side opposite"
    elif defect == "comment":
        lines.insert(0, "# a comment line before $MeshFormat")
        what = "a '#' line before $MeshFormat"
    else:
        words = lines[nodes[ids[0]][0]].split()
        lines[nodes[ids[0]][0]] = " ".join(words[:2] + ["abc"] + words[3:])
        what = f"node {ids[0]} with 'abc' for its y coordinate"
    return "\n".join(lines), what


def _read_table(path):
    with open(path) as f:
        rows = [l.split(",") for l in f.read().split("\n") if l]
    return [c.strip() for c in rows[0]], [[float(v) for v in r] for r in rows[1:]]


def same_tables(directory, reference, tolerance=1e-6):
    """Differences between the CSV tables under @p directory and @p reference beyond
    @p tolerance of each column's scale (a list of descriptions): a repaired cell's
    vertices come in another order, which changes sums at round-off, and Newton's
    iterates within its tolerance (1e-10 of the forces). The scale of a
    column is that of its quantity in all tables (the x and y of a vector, the reaction of
    every set: u_y of a bar in tension, the reaction of an interior set are round-off);
    a column of the size of the solver's tolerance in its table (the dissipation of an
    elastic run, the energy balance) is not compared."""
    tables = {}
    for root, dirs, files in os.walk(reference):
        for name in files:
            if name.endswith(".csv"):
                ref_path = os.path.join(root, name)
                tables[os.path.relpath(ref_path, reference)] = _read_table(ref_path)
    quantity = lambda c: re.sub(r"_(x|y|z|xx|yy|zz|xy|xz|yz|zx)$", "", c)
    largest = {}
    for header, rows in tables.values():
        for column, c in enumerate(header):
            m = max((abs(r[column]) for r in rows), default=0.0)
            largest[quantity(c)] = max(largest.get(quantity(c), 0.0), m)
    out = []
    for name, (header, a) in sorted(tables.items()):
        path = os.path.join(directory, name)
        if not os.path.isfile(path):
            out.append(f"{name} missing")
            continue
        _, b = _read_table(path)
        if len(a) != len(b):
            out.append(f"{name}: {len(b)} rows, not {len(a)}")
            continue
        floor = 1e-9 * max((abs(v) for r in a for v in r), default=0.0)
        for column, c in enumerate(header):
            if name.startswith("probe") and re.match(r"(s|eps)_|von_mises", c):
                continue  # a probe on a face between cells may take either cell's stress
            worst = max((abs(u[column] - v[column]) for u, v in zip(a, b)), default=0.0)
            scale = largest[quantity(c)] or 1.0
            if worst > tolerance * scale and worst > floor:
                out.append(f"{name} column {c} differs by {worst / scale:.1e} of its scale")
                break
    return out


def expectation(scene, kind, detail, status, err, seconds):
    """The kind's rule: a list of problems (empty when it holds)."""
    problems = []
    if status is None or status < 0 or status == 3:
        return problems  # the general rules report it
    if kind == "conflict":
        name = boundary_sections(scene)[detail[0]][0]
        if status in (0, 4):
            problems.append("two conditions prescribing a node differently were accepted")
        elif status == 1 and not ("Boundary fuzz_conflict" in err and "differently" in err and
                                  len(set(re.findall(r"Boundary ([\w-]+)/", err))) >= 2):
            # (Another condition that shares the nodes may be the one named.)
            problems.append("the refusal does not name both conditions")
    elif kind == "locking":
        degree = next((v for _, s, k, v in scene.entries if s == "FEM" and k == "Degree"), "1")
        b_bar = next((v for _, s, k, v in scene.entries if s == "FEM" and k == "B-bar"), "false")
        simplex = any(k == "Cell shape" and "simplex" in v for _, s, k, v in scene.entries)
        plane_stress = dimension(scene) == 2 and all(
            "plane stress" in v for _, s, k, v in scene.entries if k == "Stress state") and any(
            k == "Stress state" for _, s, k, v in scene.entries)
        locks = degree.strip() == "1" and (b_bar.strip() != "true" or simplex) and not plane_stress
        warned = "lock volumetrically" in err
        if status in (0, 2, 4) and locks and not warned:
            problems.append("elements that lock at nu = 0.4999 without the locking warning")
        if status in (0, 2, 4) and not locks and warned:
            problems.append("a locking warning for elements that do not lock")
    elif kind == "memory":
        if status != 1:
            problems.append(f"a run far beyond the memory was not refused (exit {status})")
        elif seconds > 30:
            problems.append(f"refused only after {seconds:.0f} s")
    elif kind == "mesh":
        # A mirrored cell (listed clockwise; a simplex with two vertices swapped) is
        # repaired with a warning; every other defect is refused, naming the mesh file.
        if status in (0, 4) and not (detail[0] in ("clockwise", "bow-tie") and "repaired" in err):
            problems.append("a damaged mesh was accepted without a word")
        elif status == 1 and "Mesh file" not in err:
            problems.append("the refusal does not name FEM/Mesh/Mesh file")
    return problems
