#!/usr/bin/env python3
"""Threaded element loop (`FEM/Threads`): the §5.1 plastic cantilever (prm/fem_cantilever_plastic.prm,
Q2, Bouc-Wen, 60 increments) and the implicit-dynamics cantilever of newton_failure_dynamics.prm
(run to t = 0.75 s) with 1, 2 and 3 threads.

- 2 and 3 threads give the same tables bit for bit: the cells' contributions are added in the
  order of the cells whatever thread formed them.
- 1 thread agrees with them to 1e-9 of each column's largest value (and 1e-10 of the table's
  largest value for columns that are round-off themselves): with several threads deal.II
  computes each cell's geometry afresh instead of reusing that of a translated neighbour.
- the summary's Newton iterations are the same.

Usage: threads.py HYSTERON WORKDIR
"""
import csv
import os
import re
import shutil
import subprocess
import sys

hysteron, work = sys.argv[1:3]
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def run(name, text, threads):
    d = os.path.join(work, f"{name}_{threads}")
    os.makedirs(d)
    text = text.replace("subsection FEM\n", f"subsection FEM\n  set Threads = {threads}\n", 1)
    with open(os.path.join(d, "scene.prm"), "w") as f:
        f.write(text)
    p = subprocess.run([hysteron, "scene.prm"], cwd=d, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{name}, {threads} threads: exit {p.returncode}: {p.stderr[-2000:]}")
    newton = re.search(r"(\d+) Newton iterations", p.stdout)
    return os.path.join(d, "output"), newton.group(1) if newton else None


def tables(directory):
    return sorted(f for f in os.listdir(directory) if f.endswith(".csv"))


def compare(name, a, b, exact):
    if tables(a) != tables(b) or not tables(a):
        failures.append(f"{name}: tables {tables(a)} against {tables(b)}")
        return
    for table in tables(a):
        ra = list(csv.reader(open(os.path.join(a, table))))
        rb = list(csv.reader(open(os.path.join(b, table))))
        if exact:
            if ra != rb:
                failures.append(f"{name}: {table} differs")
            continue
        if len(ra) != len(rb) or ra[:1] != rb[:1]:
            failures.append(f"{name}: {table}: {len(ra)} rows against {len(rb)}")
            continue
        columns = []
        for j, column in enumerate(ra[0]):
            try:
                columns.append((column, [float(r[j]) for r in ra[1:]], [float(r[j]) for r in rb[1:]]))
            except ValueError:
                pass
        largest = max([abs(x) for _, xa, _ in columns for x in xa] + [1e-300])
        for column, xa, xb in columns:
            scale = max([abs(x) for x in xa] + [0.0])
            for i, (x, y) in enumerate(zip(xa, xb)):
                if abs(x - y) > max(1e-9 * scale, 1e-10 * largest):
                    failures.append(f"{name}: {table}: column {column}, row {i + 1}: {x!r} vs {y!r}")
                    break


plastic = open(os.path.join(root, "prm", "fem_cantilever_plastic.prm")).read()
plastic = re.sub(r"(?m)^(\s*set Write VTU\s*=).*$", r"\1 false", plastic)
dynamic = "\n".join(l for l in open(os.path.join(here, "newton_failure_dynamics.prm")).read().splitlines()
                    if not l.startswith("#"))
dynamic = dynamic.replace("set Number of increments = 20", "set Number of increments = 15") + \
    "\nsubsection Time\n  set End time = 0.75\nend\n"
for name, text in (("plastic", plastic), ("dynamic", dynamic)):
    one, n1 = run(name, text, 1)
    two, n2 = run(name, text, 2)
    three, n3 = run(name, text, 3)
    compare(f"{name}: 2 against 3 threads", two, three, True)
    compare(f"{name}: 1 against 2 threads", one, two, False)
    if not (n1 == n2 == n3):
        failures.append(f"{name}: Newton iterations {n1}, {n2}, {n3} with 1, 2, 3 threads")

if failures:
    print("FAILED:\n  " + "\n  ".join(failures[:20]))
    sys.exit(1)
print("passed")
