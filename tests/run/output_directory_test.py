#!/usr/bin/env python3
"""The output directory is kept safe from other runs and from interruption.

    output_directory_test.py --hysteron EXE --workdir DIR scene.prm

scene.prm must be a field-method scene with two probe points that runs for a few
seconds. Asserts, in DIR:
1. hygiene: a run with two probes, then one with only the first: probe_1.csv (and the
   VTU files the second run does not write) are gone; manifest.json lists exactly the
   files present, says "finished" and names the command and the commit;
2. a refused run (bad input) leaves an existing directory untouched (no file changes, no
   manifest rewrite) and creates no new directory;
3. the lock: while a run writes into the directory, a second run into it is refused with
   exit status 1 and a message naming the running process; the first run goes on;
4. SIGKILL at an arbitrary moment of that first run leaves every table readable with
   complete rows, and the next run into the directory is not refused (the lock died with
   the process).
"""
import argparse
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time


def files_in(directory):
    found = {}
    for root, dirs, files in os.walk(directory):
        for name in files:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                found[os.path.relpath(path, directory)] = f.read()
    return found


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("prm")
    args = ap.parse_args()
    failures = []
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    with open(args.prm) as f:
        scene = f.read()
    m = re.search(r"set Probe points\s*=\s*([^;\n]+);\s*([^\n]+)", scene)
    if not m:
        print("FAILED: the scene needs two probe points")
        return 1
    one_probe = scene.replace(m.group(0), f"set Probe points = {m.group(1)}")

    def write(name, text):
        path = os.path.join(args.workdir, name)
        with open(path, "w") as f:
            f.write(text)
        return name

    out = os.path.join(args.workdir, "output")

    def run(name, extra=(), wait=True):
        command = [args.hysteron, "--quiet", *extra, name]
        if not wait:
            return subprocess.Popen(command, cwd=args.workdir, stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)
        p = subprocess.run(command, cwd=args.workdir, capture_output=True, text=True, timeout=600)
        return p.returncode, p.stderr

    # 1. Hygiene.
    code, err = run(write("two.prm", scene))
    if code != 0:
        print(err)
        print("FAILED: the scene does not run")
        return 1
    if not os.path.exists(os.path.join(out, "probe_1.csv")):
        failures.append("the first run wrote no probe_1.csv")
    code, err = run(write("one.prm", one_probe))
    present = sorted(f for f in files_in(out) if not f.startswith(".") and f != "manifest.json")
    if code != 0:
        failures.append(f"the second run exited with {code}: {err[-500:]}")
    if "probe_1.csv" in present:
        failures.append("probe_1.csv of the earlier run is still there")
    with open(os.path.join(out, "manifest.json")) as f:
        manifest = json.load(f)
    if sorted(manifest["files"]) != present:
        failures.append(f"manifest files {manifest['files']} != present {present}")
    if manifest["status"] != "finished" or "one.prm" not in manifest["command"] or \
            not re.fullmatch(r"[0-9a-f]{40}|unknown", manifest["commit"]):
        failures.append(f"manifest: {manifest}")

    # 2. A refused run writes nothing.
    before = files_in(out)
    code, err = run(write("bad.prm", one_probe.replace("set Dimension = 2",
                                                       "set Dimension = 2\nset No such entry = 1")))
    if code != 1 or files_in(out) != before:
        failures.append(f"a refused run: exit {code}, files changed: "
                        f"{sorted(set(files_in(out).items()) ^ set(before.items()))[:3]}")
    fresh = one_probe.replace("set Directory = output", "set Directory = never_created")
    code, err = run(write("bad_fresh.prm", fresh.replace("set Dimension = 2",
                                                         "set Dimension = 2\nset No such entry = 1")))
    if code != 1 or os.path.exists(os.path.join(args.workdir, "never_created")):
        failures.append("a refused run created its output directory")

    # 3. The lock (a long run of the same scene: tiny time steps).
    write("long.prm", re.sub(r"set CFL factor\s*=\s*[^\n]+", "set CFL factor = 0.0002", scene))
    first = run("long.prm", wait=False)
    deadline = time.time() + 60
    while time.time() < deadline:
        try:
            with open(os.path.join(out, "manifest.json")) as f:
                state = json.load(f)
            if state["status"] == "running" and state["pid"] == first.pid:
                break
        except (OSError, ValueError, KeyError):
            pass
        time.sleep(0.05)
    else:
        failures.append("the first run did not start")
    time.sleep(0.5)  # let it write some rows
    code, err = run("one.prm")
    if code != 1 or not re.search(rf"Output/Directory: 'output' is in use by hysteron process "
                                  rf"{first.pid} on .* since .*long\.prm", err):
        failures.append(f"second run: exit {code}, message {err.strip()!r}")
    if first.poll() is not None:
        failures.append("the first run stopped (it was meant to run on while refused)")

    # 4. SIGKILL at an arbitrary moment.
    first.send_signal(signal.SIGKILL)
    first.wait(timeout=60)
    for name, data in files_in(out).items():
        if not name.endswith(".csv"):
            continue
        text = data.decode()
        rows = list(csv.reader(text.splitlines()))
        if not text.endswith("\n") or any(len(r) != len(rows[0]) for r in rows):
            failures.append(f"after SIGKILL {name} has a cut row")
        try:
            [float(x) for r in rows[1:] for x in r]
        except ValueError:
            failures.append(f"after SIGKILL {name} has a non-number")
    code, err = run("one.prm")
    if code != 0:
        failures.append(f"the run after SIGKILL was refused: {err.strip()}")

    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("passed (hygiene, refused runs, lock, SIGKILL)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
