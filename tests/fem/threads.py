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
sys.path.insert(0, os.path.dirname(here))
from table_comparison import compare_tables  # noqa: E402

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
    failures += compare_tables(f"{name}: 2 against 3 threads", two, three, 0, 0, exact=True)
    failures += compare_tables(f"{name}: 1 against 2 threads", one, two, 1e-9, 1e-10)
    if not (n1 == n2 == n3):
        failures.append(f"{name}: Newton iterations {n1}, {n2}, {n3} with 1, 2, 3 threads")

if failures:
    print("FAILED:\n  " + "\n  ".join(failures[:20]))
    sys.exit(1)
print("passed")
