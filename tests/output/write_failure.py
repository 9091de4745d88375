#!/usr/bin/env python3
"""A write that fails (a full disk) is a run-time error that names the file and the system's
reason, for every writer: the FEM's, the MPM's and the RBSN's VTU (the second output: a
symbolic link <name>.tmp -> /dev/full makes the atomic write of <name> fail with ENOSPC) and a
time table (its header), the table also on 2 MPI ranks, where only the root writes tables: its
error must stop the other rank too (which would otherwise wait in its next collective
operation forever). Asserted: exit status 2, "cannot write '<name>': No space left on
device" on stderr, no file under the final name and no *.tmp left; the first VTU (the last
good state) stays complete.

Usage: write_failure.py HYSTERON WORKDIR [MPIEXEC]
"""
import os
import re
import shutil
import subprocess
import sys

hysteron, work = sys.argv[1:3]
mpiexec = sys.argv[3] if len(sys.argv) > 3 else None
mpi_env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
here = os.path.dirname(os.path.abspath(__file__))
tests = os.path.dirname(here)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def scene(path, replace=()):
    with open(os.path.join(tests, path)) as f:
        text = f.read()
    for old, new in replace:
        if old not in text:
            sys.exit(f"{path}: '{old}' not found")
        text = text.replace(old, new)
    return text


cases = [
    # (label, scene text, the file whose write fails)
    ("fem", scene("fem/vibrating_bar_implicit.prm", [("End time = 0.8", "End time = 0.4")]),
     "fem-00001.vtu"),
    ("mpm", scene("mpm/vibrating_bar.prm", [("End time = 0.8", "End time = 0.4")]), "particles-00001.vtu"),
    ("rbsn", scene("rbsn/rupture_force.prm", [("set Write VTU = false", "set Interval = 0.5")]),
     "rbsn-00001.vtu"),
    ("table", scene("fem/vibrating_bar_implicit.prm", [("End time = 0.8", "End time = 0.04")]),
     "probe_0.csv"),
]
if mpiexec:
    cases.append(("table on 2 ranks", cases[-1][1], "probe_0.csv"))
for label, text, name in cases:
    run = os.path.join(work, label.replace(" ", "_"))
    os.makedirs(os.path.join(run, "output"))
    with open(os.path.join(run, "scene.prm"), "w") as f:
        f.write(text)
    os.symlink("/dev/full", os.path.join(run, "output", name + ".tmp"))
    command = [hysteron, "--quiet", "scene.prm"]
    if label.endswith("2 ranks"):
        command = [mpiexec, "-np", "2"] + command
    try:
        p = subprocess.run(command, cwd=run, capture_output=True, text=True, timeout=120,
                           env=mpi_env)
    except subprocess.TimeoutExpired:
        failures.append(f"{label}: no end within 120 s (a rank waits for the one that failed)")
        continue
    left = sorted(os.listdir(os.path.join(run, "output")))
    if p.returncode != 2:
        failures.append(f"{label}: exit {p.returncode}, not 2: {p.stderr[-1500:]}")
    if not re.search(r"cannot write '[^']*" + re.escape(name) + r"': No space left on device", p.stderr):
        failures.append(f"{label}: stderr does not name {name} and ENOSPC: {p.stderr[-1500:]}")
    if name in left or any(n.endswith(".tmp") for n in left):
        failures.append(f"{label}: {name} or a *.tmp is left: {left}")
    if name.endswith(".vtu"):
        first = name.replace("00001", "00000")
        if first not in left or not open(os.path.join(run, "output", first)).read().rstrip().endswith("</VTKFile>"):
            failures.append(f"{label}: the first output {first} is not complete: {left}")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("every write failure reported with the file and ENOSPC, exit 2, nothing partial left")
