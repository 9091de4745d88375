#!/usr/bin/python3
"""MPM error versus run time (issue 4): the velocity-gradient study and the 2D Taylor bar across
cell size h, particles per cell k (k x k points in a cell) and basis, with the Pareto front.

(1) Velocity-gradient study, dissertation §4.6.1: the scene text and the error computation are
    those of tests/mpm/velocity_gradient.py (imported, its run_case() is called); error = the
    RMS of L_p - L over the interior points 1 <= x <= 4 m ("interior" norm of that test);
    basis in {linear, cubic B-spline}, cells along x in {10, 20, 40, 80, 160}, k in {1, 2, 4}.
    One step of 1e-6 s: the time is hysteron's whole in-process run ("Total wallclock time" of
    its timer table: set-up, the step, writing the particle table), process start excluded.
(2) Taylor bar, dissertation §5.8, prm/mpm_taylor_bar_2d.prm (2D plane strain half model) with
    `Cell size` h in {D0/10, D0/20, D0/40}, `Particles per cell` k in {1, 2, 3} and `Basis`
    in {linear, cubic B-spline}; its `# CHECK` lines are dropped (they hold for the default
    only). L_f, D_f, D from doc/scripts/taylor_bar_metrics.py (surface convention). Errors:
    (a) |L_f - L_f,ref| / L_f,ref against the finest cubic run (h = D0/40, k = 3), the converged
    value of this model; (b) |L_f - 1.651 cm| / 1.651 cm against the experiment (model error:
    plane strain is stiffer than the axisymmetric bar). Time = the `steps` timer section.
    Runs that fail (exit status 2: a point leaving the grid, non-finite values) are recorded
    with the first line of their message.

Times are medians of --repeats runs; a run whose timed part takes longer than 60 s is run once.
Pin the whole script to one core (taskset -c 1); every hysteron inherits it.

Writes OUT/mpm_error_vs_time.{csv,md,png}; OUT = doc/benchmarks (with --quick: WORKDIR/quick).

Usage: mpm_error_vs_time.py BUILD_DIR [--repeats 3] [--quick] [--workdir /tmp/mpm_bench]
                            [--out DIR] [--taylor-scene FILE.prm] [--built-from COMMIT]
"""
import argparse
import csv
import datetime
import importlib.util
import math
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
D0 = 0.00782                      # diameter of the Taylor bar [m]
LF_EXPERIMENT = 1.651             # final length of the Taylor bar, experiment [cm]
LONG_RUN = 60.0                   # timed part [s] above which a setting is run only once
# D_f and D are extreme radii of one layer of points, quantised by the point spacing: the two
# finest cubic runs (h = D0/40, k = 2 and 3) differ by 2 % in D_f. A Taylor bar run whose D_f and
# D lie within SHAPE_TOLERANCE of the reference is "admissible" (its shape is right, not only
# its length); the second Pareto front is taken over those.
SHAPE_TOLERANCE = 0.03
BASES = ("linear", "cubic B-spline")


def load_module(relative_path, name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(ROOT, relative_path))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


velocity_gradient = load_module("tests/mpm/velocity_gradient.py", "velocity_gradient")
with_entry = load_module("benchmarks/run_mpm_benchmark.py", "run_mpm_benchmark").with_entry


def timers(stdout):
    """Sections of hysteron's timer table {name: seconds}, plus "total"."""
    sections = {m.group(1): float(m.group(2)) for m in
                re.finditer(r"^\|\s*([^|]+?)\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s\s*\|", stdout, re.M)}
    total = re.search(r"Total wallclock time elapsed since start\s*\|\s*([0-9.e+-]+)s", stdout)
    if total:
        sections["total"] = float(total.group(1))
    return sections


def first_line(text):
    return next((line.strip() for line in text.splitlines() if line.strip()), "")


class CapturingSubprocess:
    """Stands in for the subprocess module inside velocity_gradient.run_case(): runs hysteron
    without --quiet, so that its timer table is printed, and keeps the output."""

    def __init__(self):
        self.stdout = ""

    def run(self, command, **kwargs):
        command = [c for c in command if c != "--quiet"]
        process = subprocess.run(command, capture_output=True, text=True, **kwargs)
        self.stdout = process.stdout
        return process


def repeat(one_run, repeats, key):
    """Call one_run() until `repeats` results (one if the first takes > LONG_RUN s); the
    median of every numeric field, and how many runs that was."""
    results = [one_run()]
    while len(results) < repeats and results[0][key] <= LONG_RUN:
        results.append(one_run())
    merged = dict(results[0])
    for name, value in results[0].items():
        if isinstance(value, float):
            merged[name] = statistics.median(r[name] for r in results)
    merged["repeats"] = len(results)
    return merged


def velocity_gradient_study(hysteron, workdir, repeats, quick):
    shim = CapturingSubprocess()
    velocity_gradient.subprocess = shim
    rows = []
    for basis in BASES:
        for n in ((10, 20) if quick else (10, 20, 40, 80, 160)):
            for k in ((1, 2) if quick else (1, 2, 4)):
                def one_run():
                    interior, everywhere, points, wall = velocity_gradient.run_case(
                        hysteron, workdir, n, k, basis)
                    t = timers(shim.stdout)
                    return dict(interior=interior, everywhere=everywhere, points=points, wall=wall,
                                total=t["total"], steps_s=t["steps"], setup=t["set-up"])
                row = dict(study="velocity gradient", basis=basis, h=5.0 / n, h_label=f"5 m/{n}",
                           k=k, steps=1, status="ok", message="")
                try:
                    r = repeat(one_run, repeats, "total")
                except subprocess.CalledProcessError as error:
                    row.update(status="failed", message=first_line(error.stderr or error.stdout or ""))
                    rows.append(row)
                    continue
                row.update(points=r["points"], time=r["total"], steps_s=r["steps_s"],
                           total_s=r["total"], wall_s=r["wall"], repeats=r["repeats"],
                           error=r["interior"], error_all=r["everywhere"])
                print(f"velocity gradient {basis:15s} n = {n:3d} k = {k}: {r['points']:6d} points, "
                      f"{r['total']:.4f} s, interior RMS {r['interior']:.4g}", flush=True)
                rows.append(row)
    return rows


def taylor_run(hysteron, text, directory):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    start = time.perf_counter()
    p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=ENV, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        raise RuntimeError(f"exit status {p.returncode}: {first_line(p.stderr or p.stdout)}")
    t = timers(p.stdout)
    return dict(wall=wall, steps_s=t["steps"], total=t["total"],
                sort=t.get("sort and migrate", 0.0),
                points=int(re.search(r"mpm: (\d+) material points", p.stdout).group(1)),
                steps=int(re.search(r"\((\d+) steps", p.stdout).group(1)))


def taylor_bar_study(hysteron, workdir, repeats, quick, scene_text):
    base = "".join(line for line in scene_text.splitlines(True) if not line.lstrip().startswith("# CHECK"))
    metrics = os.path.join(ROOT, "doc/scripts/taylor_bar_metrics.py")
    rows = []
    for basis in BASES:
        for divisions in ((10,) if quick else (10, 20, 40)):
            for k in ((1, 2) if quick else (1, 2, 3)):
                h = D0 / divisions
                text = with_entry(base, "Grid", "Cell size", f"{h:.6g}")
                text = with_entry(text, "Body bar", "Particles per cell", str(k))
                text = with_entry(text, "MPM", "Basis", basis)
                directory = os.path.join(workdir, "taylor", f"{basis.split()[0]}_D0-{divisions}_k{k}")
                row = dict(study="Taylor bar", basis=basis, h=h, h_label=f"D0/{divisions}", k=k,
                           status="ok", message="")
                try:
                    r = repeat(lambda: taylor_run(hysteron, text, directory), repeats, "steps_s")
                except RuntimeError as error:
                    row.update(status="failed", message=str(error))
                    print(f"Taylor bar {basis:15s} D0/{divisions} k = {k}: FAILED {error}", flush=True)
                    rows.append(row)
                    continue
                out = subprocess.run([sys.executable, metrics,
                                      os.path.join(directory, "output", "particles.csv"), "2"],
                                     capture_output=True, text=True, check=True).stdout.split()
                lf, df, d = (float(v) for v in out)
                row.update(points=r["points"], steps=r["steps"], time=r["steps_s"], steps_s=r["steps_s"],
                           total_s=r["total"], wall_s=r["wall"], sort_s=r["sort"], repeats=r["repeats"],
                           L_f=lf, D_f=df, D=d, model_error=abs(lf - LF_EXPERIMENT) / LF_EXPERIMENT)
                print(f"Taylor bar {basis:15s} D0/{divisions} k = {k}: {r['points']:6d} points, "
                      f"{r['steps']} steps, {r['steps_s']:.3f} s (x{r['repeats']}), "
                      f"L_f {lf:.4f} D_f {df:.4f} D {d:.4f} cm", flush=True)
                rows.append(row)
    ok = [r for r in rows if r["status"] == "ok"]
    cubic = [r for r in ok if r["basis"] == "cubic B-spline"] or ok
    reference = min(cubic, key=lambda r: (r["h"], -r["k"])) if cubic else None
    for r in ok:
        r["reference"] = r is reference
        r["error"] = abs(r["L_f"] - reference["L_f"]) / reference["L_f"]
        r["error_D_f"] = abs(r["D_f"] - reference["D_f"]) / reference["D_f"]
        r["error_D"] = abs(r["D"] - reference["D"]) / reference["D"]
        r["admissible"] = max(r["error_D_f"], r["error_D"]) <= SHAPE_TOLERANCE
    return rows, reference


def mark_pareto(rows, flag="pareto", admissible_only=False):
    """Pareto front in (time, error): no other run is both at least as fast and more accurate.
    The reference run of the Taylor bar (error 0 by definition) is left out."""
    candidates = sorted((r for r in rows if r["status"] == "ok" and not r.get("reference")
                         and (r.get("admissible") or not admissible_only)),
                        key=lambda r: (r["time"], r["error"]))
    best = math.inf
    for r in candidates:
        r[flag] = r["error"] < best
        best = min(best, r["error"])
    return [r for r in candidates if r[flag]]


def machine():
    cpu = open("/proc/cpuinfo").read()
    model = re.search(r"model name\s*:\s*(.*)", cpu)
    return f"{os.cpu_count()} cores, {model.group(1).strip() if model else 'unknown CPU'}"


def build_info(build):
    cache = open(os.path.join(build, "CMakeCache.txt")).read()
    build_type = re.search(r"CMAKE_BUILD_TYPE:STRING=(.*)", cache).group(1)
    dealii = "unknown"
    directory = re.search(r"deal\.II_DIR:PATH=(.*)", cache)
    if directory and os.path.exists(os.path.join(directory.group(1), "deal.IIConfigVersion.cmake")):
        version = re.search(r'PACKAGE_VERSION "([^"]+)"',
                            open(os.path.join(directory.group(1), "deal.IIConfigVersion.cmake")).read())
        dealii = version.group(1) if version else dealii
    return build_type, dealii


def write_csv(path, rows):
    columns = ["study", "basis", "h_label", "h", "k", "points", "steps", "status", "time",
               "steps_s", "total_s", "wall_s", "sort_s", "repeats", "error", "error_all",
               "error_D_f", "error_D", "L_f", "D_f", "D", "model_error", "reference", "admissible", "pareto",
               "pareto_admissible", "message"]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow({c: (f"{r[c]:.6g}" if isinstance(r.get(c), float) else r.get(c, ""))
                             for c in columns})


def write_markdown(path, args, vg_rows, tb_rows, reference, elapsed, scene):
    build_type, dealii = build_info(args.build)
    command = "benchmarks/mpm_error_vs_time.py " + " ".join(sys.argv[1:])
    lines = [
        "# MPM: error versus run time", "",
        f"Machine: {machine()}; run pinned to one core (taskset); {build_type} build, deal.II {dealii}; "
        f"hysteron built from {args.built_from}; {datetime.date.today().isoformat()}; total benchmark wall time "
        f"{elapsed / 60:.1f} min.", "",
        f"Command: `{command}`", "",
        f"Times are medians of {args.repeats} runs; runs whose timed part exceeds {LONG_RUN:.0f} s "
        "were run once (column `runs`). **P** marks the Pareto front (no other run is both faster "
        "and more accurate), for the Taylor bar **A** the front of the admissible runs. Raw data: [mpm_error_vs_time.csv](mpm_error_vs_time.csv).", "",
        "![error versus run time](mpm_error_vs_time.png)", "",
        "## Velocity-gradient study (dissertation §4.6.1)", "",
        "Error: RMS of L_p − L over the interior points 1 ≤ x ≤ 4 m [1/s] (the `interior` norm of "
        "tests/mpm/velocity_gradient.py; the all-points RMS is listed too). Time: hysteron's "
        "in-process total (set-up, one step of 1e-6 s, writing the particle table; the process "
        "start, about 0.5 s, is excluded). The cost of this study is dominated by start-up (the "
        "step itself is the `step` column), so its time axis mainly shows the number of points.", "",
        "| basis | cells along x | h [m] | points per cell | points | time [s] | step [s] | "
        "interior RMS error [1/s] | all-points RMS error [1/s] | runs | Pareto |",
        "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in vg_rows:
        if r["status"] != "ok":
            lines.append(f"| {r['basis']} | {r['h_label']} | {r['h']:.4g} | {r['k']}x{r['k']} | | "
                         f"failed: {r['message']} | | | | | |")
            continue
        lines.append(f"| {r['basis']} | {round(5.0 / r['h'])} | {r['h']:.4g} | {r['k']}x{r['k']} | "
                     f"{r['points']} | {r['time']:.4f} | {r['steps_s']:.2e} | {r['error']:.3e} | "
                     f"{r['error_all']:.3e} | {r['repeats']} | {'**P**' if r.get('pareto') else ''} |")
    lines += [
        "", "## Taylor bar, 2D plane strain (dissertation §5.8)", "",
        f"Scene: {os.path.relpath(scene, ROOT) if scene.startswith(ROOT) else scene} with `Cell size`, "
        "`Particles per cell` and `Basis` replaced and its `# CHECK` lines dropped. L_f, D_f, D in "
        "cm from doc/scripts/taylor_bar_metrics.py (surface convention: extreme points + one point "
        "spacing). Error (a): |L_f − L_f,ref| / L_f,ref against the finest cubic run"
        + (f" ({reference['basis']}, h = {reference['h_label']}, {reference['k']}x{reference['k']} "
           f"points per cell: L_f,ref = {reference['L_f']:.4f} cm, D_f,ref = {reference['D_f']:.4f} cm)"
           if reference else "")
        + "; the D_f and D columns are the same measure for D_f and D (the diameter 0.25 cm above the "
        "bottom). Admissible: D_f and D within "
        f"{100 * SHAPE_TOLERANCE:.0f} % of the reference (the two finest cubic runs differ by about 2 % in "
        "D_f, an extreme radius quantised by the point spacing); **A** marks the Pareto front over "
        "the admissible runs. Error (b): |L_f − 1.651 cm| / 1.651 cm "
        "against the experiment. Time: the `steps` timer section (set-up, sorting and output "
        "excluded).", "",
        "| basis | h | points per cell | points | steps | time [s] | L_f [cm] | D_f [cm] | "
        "D [cm] | error (a) L_f | error (a) D_f | error (a) D | error (b) vs experiment | runs | Pareto |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in tb_rows:
        if r["status"] != "ok":
            lines.append(f"| {r['basis']} | {r['h_label']} | {r['k']}x{r['k']} | | | "
                         f"failed ({r['message']}) | | | | | | | | | |")
            continue
        mark = "reference" if r.get("reference") else " ".join(
            m for m, key in (("**P**", "pareto"), ("**A**", "pareto_admissible")) if r.get(key))
        lines.append(f"| {r['basis']} | {r['h_label']} | {r['k']}x{r['k']} | {r['points']} | {r['steps']} | "
                     f"{r['time']:.3f} | {r['L_f']:.4f} | {r['D_f']:.4f} | {r['D']:.4f} | {r['error']:.2e} | "
                     f"{r['error_D_f']:.2e} | {r['error_D']:.2e} | {100 * r['model_error']:.1f} % | {r['repeats']} | {mark} |")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(path, vg_rows, tb_rows, vg_front, tb_front, tb_admissible_front):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    markers = {"linear": "s", "cubic B-spline": "o"}
    colours = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:red"}
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.4))
    panels = ((axes[0], vg_rows, vg_front, "velocity-gradient study (§4.6.1)",
               "hysteron run time (set-up + 1 step + output) [s]", "interior RMS error of L_p [1/s]"),
              (axes[1], tb_rows, tb_front, "Taylor bar 2D plane strain (§5.8)",
               "time of the steps [s]", "|L_f − L_f,ref| / L_f,ref"))
    for ax, rows, front, title, xlabel, ylabel in panels:
        ok = [r for r in rows if r["status"] == "ok" and not r.get("reference")]
        positive = [r["error"] for r in ok if r["error"] > 0]
        floor = 0.3 * min(positive) if positive else 1e-6
        for basis in BASES:
            for k in sorted({r["k"] for r in ok}):
                sel = [r for r in ok if r["basis"] == basis and r["k"] == k]
                if sel:
                    ax.loglog([r["time"] for r in sel], [max(r["error"], floor) for r in sel],
                              markers[basis], color=colours[k], mfc="none" if basis == "linear" else colours[k],
                              ms=7, label=f"{basis}, {k}x{k} per cell")
        for r in ok:
            linear = r["basis"] == "linear"
            ax.annotate(r["h_label"].replace("5 m/", "n="), (r["time"], max(r["error"], floor)),
                        textcoords="offset points", xytext=(5, 2) if linear else (-5, -9),
                        ha="left" if linear else "right", fontsize=6.5, color="0.3")
        if front:
            ax.loglog([r["time"] for r in front], [max(r["error"], floor) for r in front], "k--", lw=1,
                      label="Pareto front")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    if tb_admissible_front:
        axes[1].loglog([r["time"] for r in tb_admissible_front], [r["error"] for r in tb_admissible_front],
                       "-", color="tab:purple", lw=2.5, alpha=0.5,
                       label=f"Pareto front, D_f and D within {100 * SHAPE_TOLERANCE:.0f} %")
    model = [r["model_error"] for r in tb_rows if r["status"] == "ok"]
    if model:
        axes[1].axhline(statistics.median(model), color="0.5", lw=1, ls=":",
                        label=f"model error vs experiment ({100 * statistics.median(model):.0f} %)")
    failed = [r for r in tb_rows if r["status"] != "ok"]
    if failed:
        axes[1].text(0.02, 0.02, "failed: " + ", ".join(f"{r['basis'].split()[0]} {r['h_label']} "
                                                         f"{r['k']}x{r['k']}" for r in failed),
                     transform=axes[1].transAxes, fontsize=7, color="tab:red")
    for ax in axes:
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3)
    fig.suptitle("MPM error versus run time (filled: cubic B-spline, open squares: linear; labels: h)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build", help="build directory holding the hysteron executable")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="a tiny subset, to check the script")
    parser.add_argument("--workdir", default="/tmp/mpm_bench")
    parser.add_argument("--out", help="output directory (default doc/benchmarks; --quick: WORKDIR/quick)")
    parser.add_argument("--taylor-scene", default=os.path.join(ROOT, "prm/mpm_taylor_bar_2d.prm"))
    parser.add_argument("--built-from", help="the commit BUILD_DIR was built from (default: git HEAD)")
    args = parser.parse_args()
    if not args.built_from:
        head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        args.built_from = head.stdout.strip() or "unknown"
    args.build = os.path.abspath(args.build)
    hysteron = os.path.join(args.build, "hysteron")
    out = args.out or (os.path.join(args.workdir, "quick") if args.quick else os.path.join(ROOT, "doc/benchmarks"))
    os.makedirs(out, exist_ok=True)
    scene_text = open(args.taylor_scene).read()
    start = time.perf_counter()
    vg_rows = velocity_gradient_study(hysteron, os.path.join(args.workdir, "velocity_gradient"),
                                      args.repeats, args.quick)
    tb_rows, reference = taylor_bar_study(hysteron, args.workdir, args.repeats, args.quick, scene_text)
    elapsed = time.perf_counter() - start
    vg_front, tb_front = mark_pareto(vg_rows), mark_pareto(tb_rows)
    tb_admissible_front = mark_pareto(tb_rows, "pareto_admissible", admissible_only=True)
    write_csv(os.path.join(out, "mpm_error_vs_time.csv"), vg_rows + tb_rows)
    write_markdown(os.path.join(out, "mpm_error_vs_time.md"), args, vg_rows, tb_rows, reference, elapsed,
                   os.path.abspath(args.taylor_scene))
    plot(os.path.join(out, "mpm_error_vs_time.png"), vg_rows, tb_rows, vg_front, tb_front, tb_admissible_front)
    print(f"wrote {out}/mpm_error_vs_time.{{csv,md,png}}; benchmark wall time {elapsed:.0f} s")


if __name__ == "__main__":
    main()
