#!/usr/bin/env python3
"""hysteron --status tells a killed run from a running one: a run's manifest says "running"
until the run records its end, which a run killed by SIGKILL (or a lost MPI rank) never does;
its lock goes with the process. Asserted: during the run, --status says "running" with the
process id; after SIGKILL, "interrupted" (while manifest.json itself still says running); after
a run that finished, "finished".

Usage: status_after_kill.py HYSTERON WORKDIR
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

hysteron, work = sys.argv[1:3]
tests = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
with open(os.path.join(tests, "fem", "vibrating_bar_implicit.prm")) as f:
    text = f.read()
failures = []


def status():
    p = subprocess.run([hysteron, "--status", "output"], cwd=work, capture_output=True, text=True)
    if p.returncode != 0:
        failures.append(f"--status: exit {p.returncode}: {p.stderr}")
    return p.stdout.strip()


with open(os.path.join(work, "scene.prm"), "w") as f:
    f.write(text.replace("End time = 0.8", "End time = 1000"))
run = subprocess.Popen([hysteron, "--quiet", "scene.prm"], cwd=work, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
manifest = os.path.join(work, "output", "manifest.json")
for _ in range(600):
    if os.path.exists(manifest) and os.path.exists(os.path.join(work, "output", "probe_0.csv")):
        break
    time.sleep(0.1)
during = status()
if not re.match(r"running: hysteron process %d " % run.pid, during):
    failures.append(f"during the run: '{during}'")
run.send_signal(signal.SIGKILL)
run.wait()
if json.load(open(manifest))["status"] != "running":
    failures.append("the killed run's manifest does not say running (the test's premise)")
after = status()
if not after.startswith("interrupted: the manifest says running, but no process holds the lock"):
    failures.append(f"after SIGKILL: '{after}'")

with open(os.path.join(work, "scene.prm"), "w") as f:
    f.write(text.replace("End time = 0.8", "End time = 0.02"))
p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=work, capture_output=True, text=True)
done = status()
if p.returncode != 0 or not done.startswith("finished"):
    failures.append(f"after a finished run (exit {p.returncode}): '{done}'")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"running -> '{during}'\nkilled -> '{after[:60]}...'\nfinished -> '{done}'")
