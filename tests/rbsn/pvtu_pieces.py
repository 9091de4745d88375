#!/usr/bin/env python3
"""The RBSN's parallel VTU: tests/rbsn/rupture_force.prm with VTU output on 2 ranks writes, per
output time, one piece per rank and a .pvtu record naming both; the pieces hold every cell
polygon and every facet line exactly once (cells + facets of the network, split by coordinate bisection), with
the arrays the record declares, and the fragments and released cells of the last output match
fracture.csv (the right half released).

Usage: pvtu_pieces.py HYSTERON MPIEXEC WORKDIR
"""
import base64
import csv
import os
import re
import shutil
import struct
import subprocess
import sys

hysteron, mpiexec, work = sys.argv[1:4]
here = os.path.dirname(os.path.abspath(__file__))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
with open(os.path.join(here, "rupture_force.prm")) as f:
    text = f.read().replace("set Write VTU = false", "set Write VTU = true\n  set Interval = 0.5")
with open(os.path.join(work, "scene.prm"), "w") as f:
    f.write(text)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
p = subprocess.run([mpiexec, "-np", "2", hysteron, "--quiet", "scene.prm"], cwd=work, env=env,
                   capture_output=True, text=True)
failures = []
if p.returncode != 0:
    sys.exit(f"exit {p.returncode}: {p.stderr[-2000:]}")
out = os.path.join(work, "output")


def arrays(path):
    """name -> values of every DataArray with a name (binary, UInt64 header)."""
    codes = {"Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B"}
    result = {}
    t = open(path).read()
    for m in re.finditer(r'<DataArray type="(\w+)"( Name="([^"]*)")?[^>]*format="binary">\s*(.*?)\s*</DataArray>', t, re.S):
        raw = base64.b64decode(m.group(4))
        n = struct.unpack("<Q", raw[:8])[0]
        code = codes[m.group(1)]
        result[m.group(3) or "points"] = struct.unpack("<%d%s" % (n // struct.calcsize(code), code), raw[8:8 + n])
    return result


pvd = open(os.path.join(out, "rbsn.pvd")).read()
records = re.findall(r'file="([^"]+)"', pvd)
if records != ["rbsn-00000.pvtu", "rbsn-00001.pvtu", "rbsn-00002.pvtu"]:
    failures.append(f"the PVD names {records}")
last = open(os.path.join(out, records[-1])).read()
pieces = re.findall(r'<Piece Source="([^"]+)"', last)
declared = re.findall(r'<PDataArray type="\w+" Name="([^"]+)"', last)
if pieces != ["rbsn-00002.0000.vtu", "rbsn-00002.0001.vtu"]:
    failures.append(f"the record names the pieces {pieces}")
cells, facets, released = [], [], 0
for piece in pieces:
    a = arrays(os.path.join(out, piece))
    for name in declared:
        if name not in a:
            failures.append(f"{piece} has no array {name}")
    cells += [c for c in a["cell"] if c >= 0]
    facets += [e for e in a["facet"] if e >= 0]
    released += sum(1 for c, r in zip(a["cell"], a["released"]) if c >= 0 and r == 1)
n_cells, n_facets = 325, 858  # the network of rupture_force.prm (its summary)
if sorted(set(cells)) != list(range(n_cells)) or len(cells) != len(set(cells)):
    failures.append(f"the pieces hold {len(cells)} cell polygons for {n_cells} cells")
if sorted(facets) != list(range(n_facets)):
    failures.append(f"the pieces hold {len(facets)} facet lines for {n_facets} facets")
with open(os.path.join(out, "fracture.csv")) as f:
    rows = list(csv.DictReader(f))
if released != int(float(rows[-1]["released_cells"])):
    failures.append(f"{released} released cells in the VTU, {rows[-1]['released_cells']} in fracture.csv")
if failures:
    sys.exit("FAILED:\n  " + "\n  ".join(failures))
print(f"passed: {len(pieces)} pieces, {len(cells)} cells, {len(facets)} facets, {released} released")
