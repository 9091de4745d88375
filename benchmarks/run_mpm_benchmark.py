#!/usr/bin/env python3
"""MPM throughput benchmark (issue 4): particle-steps per second per core, memory per point and
2-rank parallel efficiency.

(a) benchmarks/mpm/block_3d.prm: a 3D elastic block under gravity (73,728 points, linear basis,
    USF, dt = 1e-4 s), 200 steps.
(b) prm/mpm_taylor_bar_2d.prm if present: the 2D Taylor bar (cubic B-splines, MUSL, Bouc-Wen),
    the whole run (impact to rest), without VTU output.

The time is the `steps` section of hysteron's timer table (set-up and output excluded), the
median of --repeats runs. Memory per point: (peak RSS of the run - peak RSS of the same scene
with a single-cell block) / points. Writes OUT/mpm_throughput.md (OUT = doc/benchmarks).

Usage: run_mpm_benchmark.py BUILD_DIR [--repeats 3] [--mpiexec mpirun] [--out OUT]
"""
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def run(command, prm_text, workdir):
    """Run hysteron on prm_text; return (steps seconds, points, steps, peak RSS in KiB)."""
    prm = os.path.join(workdir, "scene.prm")
    with open(prm, "w") as f:
        f.write(prm_text)
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    p = subprocess.run(command + [prm], cwd=workdir, env=ENV, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    seconds = float(re.search(r"\|\s*steps\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s", p.stdout).group(1))
    points = int(re.search(r"mpm: (\d+) material points", p.stdout).group(1))
    steps = int(re.search(r"\((\d+) steps", p.stdout).group(1))
    return seconds, points, steps, rss if rss > before else None


def with_entry(text, section_path, entry, value):
    """Replace `set entry = ...` (first occurrence after the section header) in a .prm text."""
    lines = text.splitlines()
    start = 0
    if section_path:
        start = next(i for i, l in enumerate(lines) if l.strip() == f"subsection {section_path}")
    for i in range(start, len(lines)):
        if re.match(rf"\s*set {re.escape(entry)}\s*=", lines[i]):
            indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
            lines[i] = f"{indent}set {entry} = {value}"
            return "\n".join(lines) + "\n"
    raise KeyError(entry)


def main():
    build = os.path.abspath(sys.argv[1])
    repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 3
    mpiexec = sys.argv[sys.argv.index("--mpiexec") + 1] if "--mpiexec" in sys.argv else "mpirun"
    out_dir = (sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv
               else os.path.join(ROOT, "doc/benchmarks"))
    hysteron = os.path.join(build, "hysteron")
    rows = []
    with tempfile.TemporaryDirectory() as work:
        block = open(os.path.join(ROOT, "benchmarks/mpm/block_3d.prm")).read()
        one = [run([hysteron], block, work) for _ in range(repeats)]
        t1 = statistics.median(r[0] for r in one)
        points, steps = one[0][1], one[0][2]
        # Separate processes for the peak RSS: the big run and a one-cell block.
        small = with_entry(block, "Body block", "Shape", "box(0.7, 0.7, 0, 0.75, 0.75, 0.05)")
        small = with_entry(small, "Output", "Probe points", "")  # the probe is off the one-cell block
        rss_big = subprocess_peak(hysteron, block, work)
        rss_small = subprocess_peak(hysteron, small, work)
        per_point = (rss_big - rss_small) * 1024 / points
        two = [run([mpiexec, "-np", "2", hysteron], block, work) for _ in range(repeats)]
        t2 = statistics.median(r[0] for r in two)
        rows.append(("(a) 3D elastic block, linear, USF", points, steps, t1, points * steps / t1 / 1e6,
                     per_point, t1 / (2 * t2)))
        taylor = os.path.join(ROOT, "prm/mpm_taylor_bar_2d.prm")
        if os.path.exists(taylor):
            text = open(taylor).read()
            text = with_entry(text, "Output", "Write VTU", "false")
            runs = [run([hysteron], text, work) for _ in range(repeats)]
            tb = statistics.median(r[0] for r in runs)
            rows.append(("(b) 2D Taylor bar, cubic B-spline, MUSL, Bouc-Wen", runs[0][1], runs[0][2], tb,
                         runs[0][1] * runs[0][2] / tb / 1e6, float("nan"), float("nan")))
    cpu = open("/proc/cpuinfo").read()
    model = re.search(r"model name\s*:\s*(.*)", cpu).group(1)
    out = [f"Machine: {os.cpu_count()} cores, {model}; Release build; median of {repeats} runs; "
           f"command: benchmarks/run_mpm_benchmark.py BUILD_DIR --repeats {repeats}", "",
           "| scene | points | steps | time of the steps [s] | M particle-steps/s/core | "
           "memory per point [B] | 2-rank efficiency |", "|---|---|---|---|---|---|---|"]
    for name, p, s, t, rate, mem, eff in rows:
        out.append(f"| {name} | {p} | {s} | {t:.3f} | {rate:.2f} | {mem:.0f} | {eff:.2f} |")
    text = "\n".join(out) + "\n"
    print(text)
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "mpm_throughput.md"), "w") as f:
        f.write(text)


def subprocess_peak(hysteron, prm_text, work):
    """Peak RSS [KiB] of one run, measured by a child python so the maximum is its own."""
    prm = os.path.join(work, "peak.prm")
    with open(prm, "w") as f:
        f.write(prm_text)
    code = ("import resource,subprocess,sys;"
            "subprocess.run(sys.argv[1:],check=True,capture_output=True);"
            "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    p = subprocess.run([sys.executable, "-c", code, hysteron, "--quiet", prm], cwd=work, env=ENV,
                       capture_output=True, text=True, check=True)
    return int(p.stdout.strip())


if __name__ == "__main__":
    main()
