#!/usr/bin/env python3
"""Run one hysteron scene test: a .prm file whose comment lines carry its assertions.

The scene runs in a fresh working directory (relative output paths land there) with
--quiet. Directives, one per comment line:

  # CHECK <file>: <expr>          holds on every data row of the CSV <file>
  # CHECK-LAST <file>: <expr>     holds on the last row
  # CHECK-COLUMNS <file>: <expr>  holds once, each column bound to the list of its values
  # CHECK-SCRIPT: <script> [args]  a Python script (path relative to the .prm) run in the
                                  working directory after the scene must exit with 0: for
                                  checks that would not fit one expression
  # EXPECT-ERROR: <regex>         the run must fail (exit status 1, or the one of EXIT),
                                  stderr must match <regex>, and no output file may be
                                  left behind (exit 1: nothing at all, not even parameters.prm
                                  or a manifest; with EXIT: 2, a run that failed, complete files
                                  of the last good state may stay, but no *.tmp)
  # EXIT: <n>                     the expected non-zero exit status (with EXPECT-ERROR)
  # MAX-SECONDS: <s>              the (first) run must take at most s seconds of CPU time
  # EXPECT-STDERR: <regex>        stderr must match (e.g. a warning) on a successful run
  # EXPECT-STDOUT: <regex>        stdout must match on a successful run
  # ARGS: <arguments>             command line instead of "--quiet <prm>" ({prm} = the file)
  # RANKS: <n>                    run the scene on n MPI ranks (e.g. an error only several
                                  ranks give); MPI lines add runs on their ranks as before
  # FILES: <path>[, <path>]       input files the scene reads (paths relative to the .prm),
                                  copied into the working directory with the .prm
  # MPI: 2                        also run on 2 ranks; every output file must be identical
                                  (with EXPECT-ERROR: the run must fail in the same way)
  # MPI-TOLERANCE: 1e-10[, 1e-14][, s_xy=1e-3, ...]
                                  with MPI: CSV values may differ by this fraction of the
                                  largest magnitude in their column (sums in another order),
                                  or by the optional absolute amount (columns of round-off);
                                  name=value sets the absolute amount of the columns that
                                  match the pattern name (fnmatch), e.g. a stress column of
                                  round-off in Pa beside displacements of 1e-4 m
  # MPI-IGNORE: newton.csv        with MPI: files that must exist on 2 ranks but whose values
                                  are not compared (solver diagnostics such as residual norms
                                  at round-off level)

Expressions are Python over the CSV column names, with abs, sqrt, exp, log, tanh, sin, cos,
pi, min, max, sum, len, all, any, `i` (the row index) for CHECK, and table(<file>): the
columns of another CSV file of the run (a dict of lists), to relate two tables (e.g. the
facet forces of springs.csv to the reactions of reactions.csv).
Exit status 0 when every assertion holds; the failures are printed otherwise.
"""
import argparse
import csv
import filecmp
import fnmatch
import math
import os
import re
import resource
import shutil
import subprocess
import sys

SAFE = {
    "abs": abs, "sqrt": math.sqrt, "exp": math.exp, "log": math.log, "tanh": math.tanh,
    "sin": math.sin, "cos": math.cos, "pi": math.pi, "min": min, "max": max, "sum": sum,
    "len": len, "all": all, "any": any, "range": range, "zip": zip, "math": math,
}


def parse_directives(path):
    directives = []
    pattern = re.compile(r"^\s*#\s*(CHECK-LAST|CHECK-COLUMNS|CHECK-SCRIPT|CHECK|EXPECT-ERROR|EXPECT-STDERR|EXPECT-STDOUT|EXIT|"
                         r"ARGS|FILES|RANKS|MAX-SECONDS|MPI-TOLERANCE|MPI-IGNORE|MPI)\b\s*([^:]*):\s?(.*)$")
    with open(path) as f:
        for line in f:
            m = pattern.match(line)
            if m:
                directives.append((m.group(1), m.group(2).strip(), m.group(3).strip()))
    return directives


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise AssertionError(f"{path} is empty")
    header, data = rows[0], rows[1:]
    values = [[float(x) for x in r] for r in data]
    return header, values


def run(cmd, cwd, env):
    p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    return p.returncode, p.stdout, p.stderr


def output_files(directory):
    found = []
    for root, _, files in os.walk(directory):
        for name in files:
            found.append(os.path.relpath(os.path.join(root, name), directory))
    return sorted(found)


def compare_csv(path_one, path_two, tolerance):
    """None if the tables agree to tolerance[0] times each column's largest magnitude
    (or to the absolute tolerance[1], or that of tolerance[2] for the columns matching a
    pattern there)."""
    relative, default_absolute, *rest = tolerance
    columns = rest[0] if rest else {}
    header1, one = read_csv(path_one)
    header2, two = read_csv(path_two)
    if header1 != header2:
        return "the columns differ"
    if len(one) != len(two):
        return f"{len(two)} rows instead of {len(one)}"
    for c, name in enumerate(header1):
        absolute = next((a for pattern, a in columns.items() if fnmatch.fnmatchcase(name, pattern)),
                        default_absolute)
        scale = max([abs(r[c]) for r in one] + [1e-300])
        for i, (a, b) in enumerate(zip(one, two)):
            if abs(a[c] - b[c]) > max(relative * scale, absolute):
                return (f"column {name}, row {i}: {a[c]!r} vs {b[c]!r} (more than {relative} of "
                        f"the column's scale {scale:g} and more than {absolute})")
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hysteron", required=True)
    ap.add_argument("--mpiexec", default="mpirun")
    ap.add_argument("--workdir", required=True)
    ap.add_argument("prm")
    args = ap.parse_args()

    prm = os.path.abspath(args.prm)
    directives = parse_directives(prm)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")

    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    local_prm = os.path.join(args.workdir, os.path.basename(prm))
    shutil.copy(prm, local_prm)
    inputs = [x.strip() for k, _, v in directives if k == "FILES" for x in v.split(",") if x.strip()]

    def copy_inputs(directory):
        for name in inputs:
            target = os.path.join(directory, name)
            os.makedirs(os.path.dirname(target) or directory, exist_ok=True)
            shutil.copy(os.path.join(os.path.dirname(prm), name), target)

    copy_inputs(args.workdir)

    arg_line = next((v for k, _, v in directives if k == "ARGS"), "--quiet {prm}")
    command = [args.hysteron] + [a.replace("{prm}", os.path.basename(prm))
                                 for a in arg_line.split()]
    ranks_line = next((v for k, _, v in directives if k == "RANKS"), None)
    main_command = ([args.mpiexec, "-np", ranks_line.strip()] + command) if ranks_line else command
    failures = []

    # The CPU time of the run (user + system, its children's too): unlike the wall time it
    # does not grow when other tests share the cores.
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    code, out, err = run(main_command, args.workdir, env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    print("$ " + " ".join(main_command) + f"  ({seconds:.2f} s of CPU)")
    for k, _, v in directives:
        if k == "MAX-SECONDS" and seconds > float(v):
            failures.append(f"the run took {seconds:.2f} s of CPU, more than {v} s")
    if out:
        print(out[-4000:])
    if err:
        print("stderr:\n" + err[-4000:])

    expect_error = [v for k, _, v in directives if k == "EXPECT-ERROR"]
    if expect_error:
        expected_code = int(next((v for k, _, v in directives if k == "EXIT"), "1"))
        if code != expected_code:
            failures.append(f"exit status {code}, expected {expected_code}")
        for regex in expect_error:
            if not re.search(regex, err):
                failures.append(f"stderr does not match /{regex}/")
        if "Traceback" in err or "terminate called" in err or "Aborted" in err:
            failures.append("the program crashed instead of reporting the error")
        # Bad input (exit 1) writes nothing; a run that fails (exit 2) keeps its last good
        # state, complete files only.
        left = [f for f in output_files(args.workdir)
                if f != os.path.basename(prm) and f not in inputs
                and (expected_code == 1 or f.endswith(".tmp"))]
        if left:
            failures.append(f"output files left behind after a failed run: {left}")
        # With MPI: N the run fails the same way on N ranks (rank 0's error reaches every rank).
        for k, _, v in directives:
            if k != "MPI":
                continue
            mpi_dir = args.workdir + f".np{v}"
            shutil.rmtree(mpi_dir, ignore_errors=True)
            os.makedirs(mpi_dir)
            shutil.copy(prm, mpi_dir)
            copy_inputs(mpi_dir)
            mpi_command = [args.mpiexec, "-np", v] + command
            code2, _, err2 = run(mpi_command, mpi_dir, env)
            print("$ " + " ".join(mpi_command))
            if code2 != expected_code:
                failures.append(f"{v} ranks: exit status {code2}, expected {expected_code}: {err2[-2000:]}")
            for regex in expect_error:
                if not re.search(regex, err2):
                    failures.append(f"{v} ranks: stderr does not match /{regex}/")
            left = [f for f in output_files(mpi_dir)
                    if f != os.path.basename(prm) and f not in inputs
                    and (expected_code == 1 or f.endswith(".tmp"))]
            if left:
                failures.append(f"{v} ranks: output files left behind after a failed run: {left}")
    else:
        if code != 0:
            failures.append(f"exit status {code}")
        for k, _, v in directives:
            if k == "EXPECT-STDERR" and not re.search(v, err):
                failures.append(f"stderr does not match /{v}/")
            if k == "EXPECT-STDOUT" and not re.search(v, out):
                failures.append(f"stdout does not match /{v}/")

    # CHECKs hold on a successful run, and on the last good state a failed run (EXIT: 2) wrote.
    if not expect_error or expected_code == 2:
        def table(name):
            columns, values = read_csv(os.path.join(args.workdir, name))
            return {h: [r[j] for r in values] for j, h in enumerate(columns)}

        for kind, target, expr in directives:
            if kind == "CHECK-SCRIPT":
                words = expr.split()
                script = os.path.join(os.path.dirname(os.path.abspath(prm)), words[0])
                code, out_s, err_s = run([sys.executable, script] + words[1:], args.workdir, env)
                if code != 0:
                    failures.append(f"CHECK-SCRIPT {expr}: exit {code}\n{out_s}{err_s}")
                continue
            if kind not in ("CHECK", "CHECK-LAST", "CHECK-COLUMNS"):
                continue
            path = os.path.join(args.workdir, target)
            try:
                header, rows = read_csv(path)
            except (OSError, ValueError, AssertionError) as e:
                failures.append(f"{target}: cannot read: {e}")
                continue
            if not rows:
                failures.append(f"{target}: no data rows")
                continue
            try:
                if kind == "CHECK-COLUMNS":
                    scope = dict(SAFE, table=table)
                    scope.update({h: [r[j] for r in rows] for j, h in enumerate(header)})
                    if not eval(expr, dict(scope, __builtins__={})):
                        failures.append(f"{kind} {target}: {expr} is false")
                else:
                    selected = [(len(rows) - 1, rows[-1])] if kind == "CHECK-LAST" else \
                        list(enumerate(rows))
                    for i, r in selected:
                        scope = dict(SAFE, table=table)
                        scope.update(dict(zip(header, r)))
                        scope["i"] = i
                        if not eval(expr, dict(scope, __builtins__={})):
                            shown = ", ".join(f"{h}={v:.6g}" for h, v in zip(header, r))
                            failures.append(f"{kind} {target}: {expr} is false at row {i}: "
                                            f"{shown[:600]}")
                            break
            except Exception as e:  # a broken expression is a failing test
                failures.append(f"{kind} {target}: cannot evaluate {expr}: {e}")

        tolerance = None
        for k, _, v in directives:
            if k == "MPI-TOLERANCE":
                parts = [x.strip() for x in v.split(",")]
                numbers = [float(x) for x in parts if "=" not in x]
                columns = {x.split("=")[0].strip(): float(x.split("=")[1]) for x in parts if "=" in x}
                tolerance = (numbers[0], numbers[1] if len(numbers) > 1 else 0.0, columns)
        for k, _, v in directives:
            if k != "MPI" or expect_error:
                continue
            ranks = int(v)
            mpi_dir = args.workdir + f".np{ranks}"
            shutil.rmtree(mpi_dir, ignore_errors=True)
            os.makedirs(mpi_dir)
            shutil.copy(prm, mpi_dir)
            copy_inputs(mpi_dir)
            mpi_command = [args.mpiexec, "-np", str(ranks)] + command
            code2, out2, err2 = run(mpi_command, mpi_dir, env)
            print("$ " + " ".join(mpi_command))
            if code2 != 0:
                failures.append(f"{ranks} ranks: exit status {code2}: {err2[-2000:]}")
                continue
            one, two = output_files(args.workdir), output_files(mpi_dir)
            inputs_here = {os.path.normpath(x) for x in inputs}  # the scene's inputs are no output
            comparable = [f for f in one if f.endswith(".csv") and os.path.normpath(f) not in inputs_here]
            ignored = [x.strip() for k, _, v in directives if k == "MPI-IGNORE" for x in v.split(",")]
            for f in comparable:
                if f not in two:
                    failures.append(f"{ranks} ranks: {f} missing")
                elif os.path.basename(f) in ignored:
                    continue
                elif tolerance is not None:
                    problem = compare_csv(os.path.join(args.workdir, f), os.path.join(mpi_dir, f),
                                          tolerance)
                    if problem:
                        failures.append(f"{ranks} ranks: {f}: {problem}")
                elif not filecmp.cmp(os.path.join(args.workdir, f), os.path.join(mpi_dir, f),
                                     shallow=False):
                    failures.append(f"{ranks} ranks: {f} differs from the 1-rank run")

    n_checks = sum(1 for k, _, _ in directives
                   if k in ("CHECK", "CHECK-LAST", "CHECK-COLUMNS", "CHECK-SCRIPT", "EXPECT-ERROR", "MPI", "MAX-SECONDS",
                            "EXPECT-STDERR", "EXPECT-STDOUT"))
    if n_checks == 0 and not expect_error:
        failures.append("the test has no assertion (add a CHECK, EXPECT-ERROR or MPI line)")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print(f"passed ({n_checks} assertions)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
