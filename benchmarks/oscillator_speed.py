#!/usr/bin/env python3
"""Run time of the oscillator and spectrum methods (doc/benchmarks.md, "Earthquake oscillators
and spectra"): medians of repeated runs of

  * prm/oscillator_record.prm cut to 4,000 steps (20 s of the record at 0.005 s): a Bouc-Wen
    SDOF with the adaptive integrator, history.csv and energy.csv written every step;
  * the same storey elastic (linear elastic material);
  * prm/spectrum_record.prm: 60 periods, elastic, R = 4 and the constant-ductility spectrum;

the timed section of the integration ("oscillator steps", "oscillators") and the whole process.
Usage: oscillator_speed.py HYSTERON [--repeats 21]
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(hysteron, workdir, prm, section):
    start = time.perf_counter()
    p = subprocess.run([hysteron, prm], cwd=workdir, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    m = re.search(r"\|\s*" + re.escape(section) + r"\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s", p.stdout)
    return float(m.group(1)), wall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("hysteron")
    ap.add_argument("--repeats", type=int, default=21)
    a = ap.parse_args()
    hysteron = os.path.abspath(a.hysteron)
    with tempfile.TemporaryDirectory() as work:
        os.makedirs(os.path.join(work, "records"))
        shutil.copy(os.path.join(ROOT, "prm", "records", "synthetic_kanai_tajimi.AT2"), os.path.join(work, "records"))
        with open(os.path.join(ROOT, "prm", "oscillator_record.prm")) as f:
            scene = f.read().replace("set Duration = 25", "set Duration = 20")
        with open(os.path.join(work, "bouc_wen.prm"), "w") as f:
            f.write(scene)
        elastic = re.sub(r"subsection Material.*?\nend\n", "subsection Material\n  set Model = linear elastic\n"
                         "  set Young's modulus = 200e9\nend\n", scene, flags=re.S)
        with open(os.path.join(work, "elastic.prm"), "w") as f:
            f.write(elastic)
        shutil.copy(os.path.join(ROOT, "prm", "spectrum_record.prm"), work)
        print("| run | steps | integration (median) | whole process (median) | runs |")
        print("|---|---|---|---|---|")
        for label, prm, section, steps, repeats in (
                ("Bouc-Wen SDOF, 20 s record", "bouc_wen.prm", "oscillator steps", "4,000", a.repeats),
                ("elastic SDOF, 20 s record", "elastic.prm", "oscillator steps", "4,000", a.repeats),
                ("spectrum: 60 periods, R = 4, mu = 4", "spectrum_record.prm", "oscillators", "see text",
                 max(3, a.repeats // 4))):
            runs = [timed(hysteron, work, prm, section) for _ in range(repeats)]
            inner = statistics.median(r[0] for r in runs)
            whole = statistics.median(r[1] for r in runs)
            print(f"| {label} | {steps} | {1e3 * inner:.1f} ms | {1e3 * whole:.0f} ms | {repeats} |")


if __name__ == "__main__":
    main()
