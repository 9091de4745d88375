#!/usr/bin/env python3
"""Incremental assembly of the RBSN tangent (`RBSN/Incremental assembly`): the matrix keeps every
facet's part and an assembly adds only the change of the facets whose tangent changed. Each scene
runs with it and without it (every assembly from zero); the tables must agree to round-off and the
incremental run must have written only a small share of the facets' matrices.

- quasi-static, linear elastic springs, with fracture: the double-notched bar pulled to rupture
  (tests/rbsn/rupture_displacement.prm): only the breaking facets change, so after the first
  assembly almost no facet is written again;
- quasi-static with the coupled Bouc-Wen law and fracture (prm/rbsn_cantilever_fracture.prm):
  springs that yield change their tangent, the elastic ones do not;
- implicit dynamics (HHT alpha = -0.1, Rayleigh damping on mass and stiffness) with fracture, the
  same bar pulled at its end: the damping part of a broken facet must leave the matrix too;
- the same on 2 MPI ranks against 1 rank (the distributed Trilinos matrix is updated in place).

Tolerance: 1e-8 of each column's largest value, and 1e-9 of the largest value in the table
(columns that are round-off themselves, e.g. the energy balance).

Usage: incremental_assembly.py HYSTERON MPIEXEC WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

hysteron, mpiexec, work = sys.argv[1:4]
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
sys.path.insert(0, os.path.dirname(here))
from table_comparison import compare_tables  # noqa: E402

failures = []


def run(name, text, incremental, ranks=1):
    """Run the scene; returns (output directory, summary line)."""
    d = os.path.join(work, f"{name}_{'incremental' if incremental else 'full'}_{ranks}")
    os.makedirs(d)
    text = text.replace("subsection RBSN\n",
                        f"subsection RBSN\n  set Incremental assembly = {'true' if incremental else 'false'}\n", 1)
    with open(os.path.join(d, "scene.prm"), "w") as f:
        f.write(text)
    command = [hysteron, "scene.prm"]
    if ranks > 1:
        command = [mpiexec, "-np", str(ranks)] + command
    p = subprocess.run(command, cwd=d, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{name}: exit {p.returncode}: {p.stderr[-2000:]}")
    summary = [line for line in p.stdout.splitlines() if "finished in" in line]
    return os.path.join(d, "output"), summary[-1] if summary else ""


def share(name, summary, at_most):
    """The share of the facets' matrices written, from the summary, must be below at_most [%]."""
    m = re.search(r"([\d.]+) % of the facets' matrices", summary)
    if not m:
        failures.append(f"{name}: the summary does not report the incremental assembly: {summary}")
    elif float(m.group(1)) > at_most:
        failures.append(f"{name}: {m.group(1)} % of the facets' matrices written, expected at most {at_most} %")
    print(f"{name}: {summary}")


rupture = open(os.path.join(here, "rupture_displacement.prm")).read()
cantilever = open(os.path.join(root, "prm", "rbsn_cantilever_fracture.prm")).read()
dynamic = rupture.replace("subsection RBSN\n", """subsection RBSN
  set Analysis = implicit dynamics
  subsection Dynamics
    set HHT alpha = -0.1
    set Rayleigh mass coefficient = 5
    set Rayleigh stiffness coefficient = 1e-5
  end
""", 1)

for name, text, at_most in (("static_rupture", rupture, 10), ("coupled_cantilever", cantilever, 80),
                            ("dynamic_rupture", dynamic, 20)):
    a, summary = run(name, text, True)
    b, _ = run(name, text, False)
    failures += compare_tables(name, a, b, 1e-8, 1e-9)
    share(name, summary, at_most)
    if "broken facets" not in summary or " 0 broken facets" in summary:
        failures.append(f"{name}: no facet broke: {summary}")

a, summary = run("static_rupture", rupture, True, 2)
failures += compare_tables("static_rupture, 2 ranks against 1", a,
                           os.path.join(work, "static_rupture_full_1", "output"), 1e-8, 1e-9)
share("static_rupture, 2 ranks", summary, 10)

if failures:
    print("FAILED:\n  " + "\n  ".join(failures[:20]))
    sys.exit(1)
print("passed")
