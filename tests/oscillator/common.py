"""Helpers of the oscillator tests: run a scene text in a fresh directory, read a CSV."""
import csv
import os
import shutil
import subprocess
import sys


def run(hysteron, workdir, name, text, expect_error=False):
    """Write @p text to WORKDIR/NAME.prm and run it there; returns (returncode, stderr)."""
    os.makedirs(workdir, exist_ok=True)
    prm = os.path.join(workdir, name + ".prm")
    with open(prm, "w") as f:
        f.write(text)
    output = os.path.join(workdir, name)
    shutil.rmtree(output, ignore_errors=True)
    p = subprocess.run([os.path.abspath(hysteron), "--quiet", name + ".prm"], cwd=workdir, capture_output=True, text=True)
    if not expect_error and p.returncode != 0:
        sys.exit(f"{name}: hysteron failed ({p.returncode}):\n{p.stderr}")
    return p.returncode, p.stderr


def table(path):
    """The columns of a CSV file as lists of floats."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


class Checks:
    """Collects failed assertions; exit() ends the test."""

    def __init__(self):
        self.failures = []

    def check(self, condition, message):
        print(("ok   " if condition else "FAIL ") + message)
        if not condition:
            self.failures.append(message)

    def exit(self):
        if self.failures:
            sys.exit(f"{len(self.failures)} check(s) failed")
        print("all checks passed")


def uniaxial_bench(hysteron, workdir, name, E, SY, law, path, end, steps):
    """Run the uniaxial bench (Method = uniaxial) with Young's modulus @p E, the Bouc-Wen
    yield stress @p SY and the entries @p law of subsection Bouc-Wen, along the strain
    expression @p path in @p steps steps to @p end; returns history.csv's columns."""
    text = f"""set Dimension = 2
set Method    = uniaxial
subsection Material
  set Young's modulus = {E!r}
  subsection Bouc-Wen
    set Yield stress = {SY!r}
{law}
  end
end
subsection Uniaxial
  set Strain   = {path}
  set End time = {end}
  set Steps    = {steps}
end
subsection Output
  set Directory = {name}
end
"""
    run(hysteron, workdir, name, text)
    return table(os.path.join(workdir, name, "history.csv"))
