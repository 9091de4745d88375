#!/usr/bin/env python3
"""MPM throughput of two builds side by side: does a change cost time on scenes that do not use it?

    mpm_ab_throughput.py --a NAME=HYSTERON --b NAME=HYSTERON [--runs 9] [--core 1] [--out FILE]

Runs the two scenes of run_mpm_benchmark.py, (a) benchmarks/mpm/block_3d.prm (73,728 points,
linear basis, USF, 200 steps) and (b) prm/mpm_taylor_bar_2d.prm without VTU output (cubic
B-splines, MUSL, Bouc-Wen), with the two executables in turn, A B A B ..., pinned to one core
(taskset -c CORE), so that a slow phase of a shared machine falls on both. The time is the
`steps` section of hysteron's timer table. Reported per scene and build: the median, the
quartiles and the change of the median of B against A. Both builds must come from the same
source tree layout (a scene file they do not both read is refused by one of them).
"""
import argparse
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_mpm_benchmark import ROOT, run, with_entry  # noqa: E402


def quartiles(values):
    q = statistics.quantiles(values, n=4) if len(values) > 1 else [values[0]] * 3
    return q[0], q[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--a", required=True, help="NAME=path/to/hysteron (the reference)")
    parser.add_argument("--b", required=True, help="NAME=path/to/hysteron (the change)")
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--core", default="1")
    parser.add_argument("--out", default=None, help="also write the markdown table here")
    args = parser.parse_args()
    builds = [tuple(spec.split("=", 1)) for spec in (args.a, args.b)]
    block = open(os.path.join(ROOT, "benchmarks/mpm/block_3d.prm")).read()
    taylor = with_entry(open(os.path.join(ROOT, "prm/mpm_taylor_bar_2d.prm")).read(), "Output", "Write VTU", "false")
    scenes = [("(a) 3D elastic block, linear, USF", block),
              ("(b) 2D Taylor bar, cubic B-spline, MUSL, Bouc-Wen", taylor)]
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for name, text in scenes:
            times = {label: [] for label, _ in builds}
            for k in range(args.runs):
                for label, hysteron in builds:
                    seconds = run(["taskset", "-c", args.core, os.path.abspath(hysteron)], text, work)[0]
                    times[label].append(seconds)
                print(f"{name}: run {k + 1} of {args.runs}: " +
                      ", ".join(f"{label} {times[label][-1]:.3f} s" for label, _ in builds), flush=True)
            (la, _), (lb, _) = builds
            ma, mb = statistics.median(times[la]), statistics.median(times[lb])
            rows.append((name, ma, quartiles(times[la]), mb, quartiles(times[lb]), mb / ma - 1))
    (la, _), (lb, _) = builds
    model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    out = [f"Machine: {os.cpu_count()} cores, {model}, pinned to core {args.core}; Release builds; "
           f"{args.runs} alternating runs of each; `steps` timer; command: benchmarks/mpm_ab_throughput.py "
           f"--a {la}=... --b {lb}=... --runs {args.runs} --core {args.core}", "",
           f"| scene | {la}: median [s] | {la}: quartiles [s] | {lb}: median [s] | {lb}: quartiles [s] | change of the median |",
           "|---|---|---|---|---|---|"]
    for name, ma, qa, mb, qb, change in rows:
        out.append(f"| {name} | {ma:.3f} | {qa[0]:.3f} – {qa[1]:.3f} | {mb:.3f} | {qb[0]:.3f} – {qb[1]:.3f} | {100 * change:+.1f} % |")
    text = "\n".join(out) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
