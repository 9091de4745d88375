#!/usr/bin/env python3
"""Checkpoint and restart: a run stopped part-way and resumed gives the tables of an
uninterrupted run.

    resume_test.py --hysteron EXE --workdir DIR [--np N] [--resume-np M] [--signal SIGKILL]
                   [--tolerance T] scene.prm [input ...]

1. The scene (with `subsection Checkpoint / set Interval = k` appended, k about a fifth
   of its steps) runs uninterrupted in DIR/reference.
2. It runs again in DIR/stopped, where the test hook HYSTERON_TEST_SIGNAL=<signal>@<step>
   raises the signal in the process after step ~0.55 of the run (after a checkpoint, with
   rows written since). SIGKILL: the process dies at once (rows buffered since the last
   flush are lost, as in a crash). SIGINT / SIGTERM: exit status 4 and a message.
   Every CSV left behind must be readable: a header and complete rows.
3. `hysteron --resume` continues it: exit status 0, and every CSV equals the reference's
   (same rows, values within 1e-12 of each column's largest magnitude), the PVD lists the
   same times, and the manifest says "finished".
4. On as many ranks, every checkpoint that both runs wrote after the resume is the same,
   file for file and byte for byte: each method's state is described once for save and
   load, so a field it saves but does not restore would start the resumed run from
   another value and show here even where no table reads it.
On N ranks, all three runs use N ranks; with --resume-np M the resumed run has M ranks
(a job moved to another allocation), and its tables must equal the reference's within the
tolerance that the method's 1-rank and 2-rank runs meet (--tolerance, of each column's
largest magnitude).
"""
import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from run_prm_test import compare_csv  # noqa: E402  (the 1-rank/2-rank comparison)


def run(command, cwd, env, timeout=900):
    p = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, errors="replace",
                       timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def tables(directory, inputs=()):
    """The CSV files a run wrote (not its checkpoints, not the scene's input files)."""
    found = {}
    for root, dirs, files in os.walk(directory):
        dirs[:] = [d for d in dirs if not d.startswith("checkpoint-")]
        for name in files:
            path = os.path.join(root, name)
            relative = os.path.relpath(path, directory)
            if name.endswith(".csv") and os.path.normpath(relative) not in inputs:
                found[relative] = path
    return found


def read_table(path):
    """Header and rows; raises ValueError for a cut row or a non-number."""
    with open(path, newline="") as f:
        text = f.read()
    if text and not text.endswith("\n"):
        raise ValueError(f"{path} ends inside a row")
    rows = list(csv.reader(text.splitlines()))
    if not rows:
        raise ValueError(f"{path} is empty")
    header = rows[0]
    values = []
    for i, r in enumerate(rows[1:]):
        if len(r) != len(header):
            raise ValueError(f"{path}: row {i} has {len(r)} values for {len(header)} columns")
        values.append([float(x) for x in r])
    return header, values


def pvd_times(directory):
    times = {}
    for root, _, files in os.walk(directory):
        for name in files:
            if name.endswith(".pvd"):
                with open(os.path.join(root, name)) as f:
                    times[name] = re.findall(r'timestep="([^"]*)"', f.read())
    return times


def checkpoints(directory):
    """The checkpoint directories under @directory by their path relative to it."""
    found = {}
    for root, dirs, _ in os.walk(directory):
        for d in dirs:
            if d.startswith("checkpoint-"):
                path = os.path.join(root, d)
                found[os.path.relpath(path, directory)] = path
    return found


def differing_files(a, b):
    """Files of checkpoint directory a that b lacks or holds with other bytes."""
    different = []
    for root, _, files in os.walk(a):
        for name in files:
            pa = os.path.join(root, name)
            pb = os.path.join(b, os.path.relpath(pa, a))
            if not os.path.exists(pb):
                different.append(os.path.relpath(pa, a) + " (missing)")
            else:
                with open(pa, "rb") as fa, open(pb, "rb") as fb:
                    if fa.read() != fb.read():
                        different.append(os.path.relpath(pa, a))
    return different


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--resume-np", type=int, default=0, help="ranks of the resumed run (default: --np)")
    ap.add_argument("--signal", default="SIGKILL", choices=["SIGKILL", "SIGINT", "SIGTERM"])
    ap.add_argument("--tolerance", type=float, default=1e-12)
    ap.add_argument("--absolute", type=float, default=0.0,
                    help="absolute tolerance (for columns that are round-off noise around zero)")
    ap.add_argument("--ignore", action="append", default=[],
                    help="a table whose values are not compared (only that it exists), e.g. "
                         "newton.csv when the ranks change: the solver's residuals differ at round-off")
    ap.add_argument("prm")
    ap.add_argument("inputs", nargs="*")
    args = ap.parse_args()
    inputs = {os.path.normpath(x) for x in args.inputs}

    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    env.pop("HYSTERON_TEST_SIGNAL", None)
    launcher = [args.mpiexec, "-np", str(args.np)] if args.np > 1 else []
    resume_np = args.resume_np or args.np
    resume_launcher = [args.mpiexec, "-np", str(resume_np)] if resume_np > 1 else []
    name = os.path.basename(args.prm)
    failures = []

    def prepare(directory, interval):
        shutil.rmtree(directory, ignore_errors=True)
        os.makedirs(directory)
        with open(args.prm) as f:
            text = f.read()
        text += f"\nsubsection Checkpoint\n  set Interval = {interval}\nend\n"
        with open(os.path.join(directory, name), "w") as f:
            f.write(text)
        for item in args.inputs:  # paths relative to the scene, kept (records/x.csv)
            target = os.path.join(directory, item)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copy(os.path.join(os.path.dirname(os.path.abspath(args.prm)), item), target)

    # How many steps the run takes (its summary line), then the reference run.
    probe = os.path.join(args.workdir, "count")
    prepare(probe, 0)
    code, out, err = run([args.hysteron, name], probe, env)
    m = re.search(r"(\d+) steps", out)
    if code != 0 or not m:
        print(out[-3000:], err[-3000:])
        print("FAILED: the scene does not run, or its summary gives no step count")
        return 1
    n_steps = int(m.group(1))
    interval = max(1, n_steps // 5)
    at = max(interval + 1, int(0.55 * n_steps))
    if at % interval == 0:
        at += 1
    if at >= n_steps:
        print(f"FAILED: {n_steps} steps are too few for the test")
        return 1
    print(f"{name}: {n_steps} steps, a checkpoint every {interval}, {args.signal} after step {at}, "
          f"{args.np} rank(s), resumed on {resume_np}")

    reference = os.path.join(args.workdir, "reference")
    prepare(reference, interval)
    code, out, err = run(launcher + [args.hysteron, "--quiet", name], reference, env)
    if code != 0:
        print(err[-3000:])
        print(f"FAILED: the uninterrupted run exited with {code}")
        return 1

    stopped = os.path.join(args.workdir, "stopped")
    prepare(stopped, interval)
    code, out, err = run(launcher + [args.hysteron, "--quiet", name], stopped,
                         dict(env, HYSTERON_TEST_SIGNAL=f"{args.signal}@{at}"))
    print(f"stopped run: exit status {code}\n{err[-2000:]}")
    if code == 0:
        failures.append("the stopped run exited with 0")
    if args.signal != "SIGKILL":
        if code != 4:
            failures.append(f"{args.signal}: exit status {code}, expected 4")
        if not re.search(rf"{args.signal} received: .* stopped after step {at} .*hysteron --resume", err):
            failures.append(f"{args.signal}: no message naming the step and --resume")
    for relative, path in tables(stopped, inputs).items():
        try:
            read_table(path)
        except ValueError as e:
            failures.append(f"after {args.signal}: {e}")

    code, out, err = run(resume_launcher + [args.hysteron, "--quiet", "--resume", name], stopped, env)
    if code != 0:
        print(err[-3000:])
        failures.append(f"the resumed run exited with {code}")
    else:
        expected, got = tables(reference, inputs), tables(stopped, inputs)
        if sorted(expected) != sorted(got):
            failures.append(f"tables differ: {sorted(expected)} vs {sorted(got)}")
        for relative in sorted(expected):
            if relative in got and os.path.basename(relative) not in args.ignore:
                problem = compare_csv(expected[relative], got[relative], (args.tolerance, args.absolute))
                if problem:
                    failures.append(f"{relative}: {problem}")
        if pvd_times(reference) != pvd_times(stopped):
            failures.append("the VTU series (PVD) lists other times")
        manifests = [os.path.join(r, "manifest.json") for r, _, f in os.walk(stopped)
                     if "manifest.json" in f]
        for path in manifests:
            with open(path) as f:
                manifest = json.load(f)
            if manifest.get("status") != "finished" or "resumed" not in manifest:
                failures.append(f"{path}: status {manifest.get('status')!r}, resumed "
                                f"{manifest.get('resumed')!r}")
        print(f"compared {len(expected)} tables")
        if resume_np == args.np:
            # The checkpoints written after the resume (the stopped run's from before it
            # were kept or deleted as the reference's were).
            expected, got = checkpoints(reference), checkpoints(stopped)
            steps = lambda path: int(path.rsplit("-", 1)[1])
            after = [c for c in sorted(expected) if c in got and steps(c) > at]
            if not after:
                failures.append(f"no checkpoint after step {at} in both runs: {sorted(expected)} vs {sorted(got)}")
            for c in after:
                different = differing_files(expected[c], got[c])
                if different:
                    failures.append(f"{c}: the resumed run's checkpoint differs from the uninterrupted run's in "
                                    + ", ".join(different) + " (a state field saved but not restored?)")
            print(f"compared {len(after)} checkpoints byte for byte")

    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
