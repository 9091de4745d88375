#!/usr/bin/env python3
"""Ground-motion records: the formats agree, and bad records are refused naming file and line.

The same 12 samples (in g, scaled by 9.81) as a PEER .AT2 record with the current header
("NPTS=   12, DT=   .0100 SEC"), with the older one ("12  0.0100  NPTS, DT"), and as a CSV with a
header line drive an elastic SDOF oscillator: the three history.csv files are identical. Then
each broken record must stop the run with exit status 1, an error naming `Ground motion/File`,
the file and the line, and no output directory:
a velocity record (line 3), fewer and more values than NPTS, a word and a NaN among the values,
a CSV with an uneven step, decreasing times, three columns, a missing file, and a record given
to a method that does not read it (fem).
Usage: records.py HYSTERON WORKDIR
"""
import os
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import Checks, run  # noqa: E402

VALUES = [0.0, 0.01, 0.03, -0.02, 0.05, -0.04, 0.02, 0.0, -0.01, 0.015, -0.005, 0.0]
SCENE = """set Dimension = 2
set Method = {method}
subsection Material
  set Model = linear elastic
  set Young's modulus = 200e9
end
subsection Ground motion
  set File = {file}
  set Scale factor = 9.81
end
subsection Oscillator
  set Masses = 1000
  set Stiffnesses = 4e5
  set Time step = 0.0025
  set Duration = 0.2
end
subsection Output
  set Directory = {name}
end
"""


def peer(header4, values, line3="ACCELERATION TIME SERIES IN UNITS OF G"):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "TEST RECORD, written by records.py", line3, header4]
    for i in range(0, len(values), 5):
        lines.append("".join("%15s" % v for v in values[i:i + 5]))
    return "\n".join(lines) + "\n"


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    os.makedirs(workdir, exist_ok=True)
    checks = Checks()
    values = ["%.7E" % v for v in VALUES]
    files = {
        "new.AT2": peer("NPTS=   12, DT=   .0100 SEC", values),
        "old.AT2": peer("   12    0.0100    NPTS, DT", values),
        "record.csv": "time, acceleration\n" + "".join("%g,%s\n" % (0.01 * i, v) for i, v in enumerate(values)),
        "velocity.AT2": peer("NPTS=   12, DT=   .0100 SEC", values, "VELOCITY TIME SERIES IN UNITS OF CM/S"),
        "fewer.AT2": peer("NPTS=   12, DT=   .0100 SEC", values[:11]),
        "more.AT2": peer("NPTS=   12, DT=   .0100 SEC", values + ["0.0"]),
        "word.AT2": peer("NPTS=   12, DT=   .0100 SEC", values[:6] + ["abc"] + values[7:]),
        "nan.AT2": peer("NPTS=   12, DT=   .0100 SEC", values[:3] + ["nan"] + values[4:]),
        "uneven.csv": "0,0\n0.01,0.1\n0.02,0.2\n0.035,0.1\n0.04,0\n",
        "decreasing.csv": "0,0\n0.01,0.1\n0.005,0.2\n",
        "columns.csv": "0,0\n0.01,0.1,7\n",
    }
    for name, text in files.items():
        with open(os.path.join(workdir, name), "w") as f:
            f.write(text)
    histories = []
    for name in ("new.AT2", "old.AT2", "record.csv"):
        stem = "run_" + name.replace(".", "_")
        run(hysteron, workdir, stem, SCENE.format(method="oscillator", file=name, name=stem))
        with open(os.path.join(workdir, stem, "history.csv")) as f:
            histories.append(f.read())
    checks.check(histories[0] == histories[1] == histories[2] and len(histories[0].splitlines()) == 82,
                 "the two PEER headers and the CSV give the same history.csv (81 steps)")
    bad = [("velocity.AT2", "oscillator", r"velocity\.AT2:3: .*ACCELERATION"),
           ("fewer.AT2", "oscillator", r"fewer\.AT2:\d+: the record ends after 11 of NPTS = 12"),
           ("more.AT2", "oscillator", r"more\.AT2:7: more values than NPTS = 12"),
           ("word.AT2", "oscillator", r"word\.AT2:6: 'abc' is not a finite number"),
           ("nan.AT2", "oscillator", r"nan\.AT2:5: 'nan' is not a finite number"),
           ("uneven.csv", "oscillator", r"uneven\.csv:4: uneven time step"),
           ("decreasing.csv", "oscillator", r"decreasing\.csv:3: the times must increase"),
           ("columns.csv", "oscillator", r"columns\.csv:2: expected two columns"),
           ("absent.AT2", "oscillator", r"absent\.AT2"),
           ("new.AT2", "uniaxial", r"the uniaxial method does not take a ground motion")]
    for file, method, pattern in bad:
        stem = "bad_" + file.replace(".", "_") + "_" + method
        code, stderr = run(hysteron, workdir, stem, SCENE.format(method=method, file=file, name=stem),
                           expect_error=True)
        ok = code == 1 and "Ground motion/File" in stderr and re.search(pattern, stderr) is not None
        checks.check(ok and not os.path.exists(os.path.join(workdir, stem)),
                     f"{file} ({method}): exit {code}, {stderr.strip().splitlines()[-1] if stderr.strip() else ''}")
    checks.exit()


if __name__ == "__main__":
    main()
