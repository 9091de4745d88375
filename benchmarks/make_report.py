#!/usr/bin/python3
"""Regenerate the whole run-time-versus-error report, doc/benchmarks.md, from scratch (issue 7).

Runs every benchmark study, each of which writes its own tables, CSV and figure into OUT
(doc/benchmarks/ by default), then reads the studies' CSVs into one list of runs per
verification scene (error against an analytic solution, a dissertation table or a converged
solution; time = the study's measured time), computes each scene's Pareto front (no other run is
both at least as fast and more accurate), draws every front into OUT/pareto_fronts.png, picks
the recommended default per scene (the rule: the cheapest run on the front whose error is at
most the scene's target; if none reaches it, the most accurate run) and fills the template
benchmarks/benchmarks.md.in into doc/benchmarks.md. Every number in doc/benchmarks.md therefore
comes from this run: the template holds no measured value, only `{{ expression }}` fields
evaluated here (a missing study or value stops the script before anything is written).

Studies (name: script; minutes on the 2-core Xeon VM with --repeats 3):
  material                     run_material_benchmark.sh (updates/s; error-vs-cost sweep)   4
  mpm_error_vs_time            velocity gradient (§4.6.1) and Taylor bar (§5.8)              7
  mpm_scheme_time_step         vibrating bar: scheme x basis x h x CFL                       8
  fem_mpm_error_vs_time        elastic cantilever and §5.4 patch, FEM against MPM           25
  fem_plastic_error_vs_time    §5.1 plastic cantilever and §3.7.4 plate, FEM                  8
  calculix_cantilever_3d       3D plastic cantilever, FEM against CalculiX 2.20 (C3D20)       8
  rbsn_run_time                RBSN cantilever / titanium plate against cells                 4
  rbsn_large                   RBSN 100k-cell elastic plate, 10k-cell plastic cantilever      6
  rbsn_3d                      RBSN 3D: 20k-cell elastic box, 5k-cell plastic cantilever,    45
                               both on 2 ranks (runs alone: pins its own 1-rank runs)
  rbsn_incremental_assembly    RBSN tangent updated in place against assembled from zero       3
  rbsn_cantilever_plastic      §5.1 RBSN, uncoupled against coupled springs                   3
  rbsn_newmark_vs_variable_order  §3.6.1 element, Newmark against IDA                        3
  mpm_throughput               run_mpm_benchmark.py (M particle-steps/s, 2-rank efficiency)   3
  fem_plate_3d                 3D plate, Q1 + B-bar, 531,441 DoFs to collapse on 2 ranks     25
  fem_plate_3d_speedup         the same plate at 132,651 DoFs on 1 and 2 ranks               12
  pay_for_use                  callgrind instruction counts (deterministic)                  10

Each study runs pinned to one core (taskset). With --lanes 2 two studies run at a time, one per
core (shorter, but they share the memory bus and the L3 cache; the report says so); the
throughput, plate and 3D RBSN studies, which need both cores for their 2-rank runs, then run alone at
the end.
--quick runs every study's quick subset into a temporary directory (throughput and callgrind
skipped) to check the pipeline in a few minutes; its report is not for committing.

Usage: benchmarks/make_report.py BUILD_DIR [--repeats 3] [--lanes 1|2] [--quick]
                                 [--only a,b] [--report-only] [--out DIR] [--doc FILE]
  --only: run only these studies and take the others' results from OUT as they are (the
          run record OUT/report_run.json then lists the rerun studies with their commit)
  --report-only: run nothing, rebuild doc/benchmarks.md and the fronts from OUT's CSVs and
                 OUT/report_run.json (date, commit, load and study times of the last full run)
"""
import argparse
import concurrent.futures
import csv
import datetime
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from report_template import environment, fill, write_atomically  # noqa: E402

PY = "/usr/bin/python3"          # Debian's matplotlib lives here
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


# --------------------------------------------------------------------------------------------
# The studies
# --------------------------------------------------------------------------------------------
class Study:
    def __init__(self, name, command, minutes, exclusive=False, in_quick=True):
        self.name, self.command, self.minutes = name, command, minutes
        self.exclusive, self.in_quick = exclusive, in_quick
        self.seconds, self.status = None, "not run"


def studies(args, out, work):
    b, r, q = args.build, str(args.repeats), ["--quick"] if args.quick else []
    bench = os.path.join(ROOT, "benchmarks")

    def py(script, *rest):
        return [PY, os.path.join(bench, script), b, *rest]

    return [
        Study("fem_mpm_error_vs_time",
              py("fem_mpm_error_vs_time.py", "--repeats", r, "--out", out, "--wait-minutes", "0",
                 "--workdir", f"{work}/fem_mpm", *q), 25),
        Study("material", ["bash", os.path.join(bench, "run_material_benchmark.sh"), b, "--out", out, *q], 4),
        Study("mpm_error_vs_time",
              py("mpm_error_vs_time.py", "--repeats", r, "--out", out, "--workdir", f"{work}/mpm", *q), 7),
        Study("mpm_scheme_time_step",
              py("mpm_scheme_time_step.py", "--repeats", r, "--out", out, "--workdir", f"{work}/scheme", *q), 8),
        Study("fem_plastic_error_vs_time",
              py("fem_plastic_error_vs_time.py", "--repeats", r, "--out", out,
                 "--workdir", f"{work}/fem_plastic", *q), 8),
        Study("calculix_cantilever_3d",
              [PY, os.path.join(bench, "calculix_cantilever_3d.py"), "--hysteron", os.path.join(b, "hysteron"),
               "--repeats", r, "--out", out, "--workdir", f"{work}/calculix"]
              + (["--meshes", "20x2x1", "--reference", "40x4x2"] if args.quick else []), 8),
        Study("rbsn_run_time",
              py("rbsn_run_time.py", "--repeats", r, "--output", os.path.join(out, "rbsn_run_time"), *q), 4),
        Study("rbsn_large",
              py("rbsn_large.py", "--repeats", r, "--output", os.path.join(out, "rbsn_large"), *q), 6),
        # Its 1-rank runs pin themselves to one core and its 2-rank runs need both: alone.
        Study("rbsn_3d",
              py("rbsn_3d.py", "--repeats", r, "--output", os.path.join(out, "rbsn_3d"), *q), 45,
              exclusive=True),
        Study("rbsn_incremental_assembly",
              py("rbsn_incremental_assembly.py", "--repeats", r, "--output",
                 os.path.join(out, "rbsn_incremental_assembly"), *q), 3),
        Study("rbsn_cantilever_plastic",
              [PY, os.path.join(bench, "rbsn_cantilever_plastic.py"), os.path.join(b, "hysteron"),
               "--repeats", r, "--out", out, "--workdir", f"{work}/rbsn_cantilever"]
              + (["--dm", "0.05,0.03", "--seeds", "1", "--repeats", "1"] if args.quick else []), 3),
        Study("rbsn_newmark_vs_variable_order",
              py("rbsn_newmark_vs_variable_order.py", "--repeats", r, "--out", out,
                 "--workdir", f"{work}/ida", *q), 3),
        Study("pay_for_use", py("pay_for_use.py", "--out", out), 10, in_quick=False),
        Study("mpm_throughput", py("run_mpm_benchmark.py", "--repeats", r, "--out", out), 3,
              exclusive=True, in_quick=False),
        # Set-up and memory against the grid, the mesh and the ranks (up to 8 ranks,
        # oversubscribed: memory is measured faithfully, time is not): alone.
        Study("scaling_mpm", py("scaling_mpm.py", "--repeats", r, "--out", out, "--workdir", f"{work}/scaling_mpm", *q),
              10, exclusive=True, in_quick=False),
        Study("scaling_fem",
              [PY, os.path.join(bench, "scaling_fem.py"), "--hysteron", os.path.join(b, "hysteron"),
               "--workdir", f"{work}/scaling_fem", "--out", os.path.join(out, "scaling_fem.md")], 10,
              exclusive=True, in_quick=False),
        # The 3D plate of 531,441 DoFs on 2 ranks, and the 2-rank speed-up on a quarter of it:
        # both cores, one run each (about 25 and 12 minutes).
        Study("fem_plate_3d",
              [PY, os.path.join(bench, "fem_plate_3d.py"), "--hysteron", os.path.join(b, "hysteron"),
               "--cells", "80,80,26", "--degree", "1", "--b-bar", "--ranks", "2", "--linear-tolerance", "1e-6",
               "--workdir", f"{work}/plate_large", "--out", os.path.join(out, "fem_plate_3d_large.md")], 25,
              exclusive=True, in_quick=False),
        Study("fem_plate_3d_speedup",
              [PY, os.path.join(bench, "fem_plate_3d.py"), "--hysteron", os.path.join(b, "hysteron"),
               "--cells", "50,50,16", "--degree", "1", "--b-bar", "--ranks", "1,2", "--linear-tolerance", "1e-6",
               "--workdir", f"{work}/plate_medium", "--out", os.path.join(out, "fem_plate_3d_medium.md")], 12,
              exclusive=True, in_quick=False),
    ]


def run_studies(selected, lanes, log_dir):
    """Run the studies, `lanes` at a time, each pinned to its own core; exclusive ones alone."""
    cores = sorted(os.sched_getaffinity(0))[-lanes:]
    free, lock = list(cores), threading.Lock()

    def one(study, core):
        log = os.path.join(log_dir, f"{study.name}.log")
        start = time.time()
        command = ["taskset", "-c", str(core), *study.command] if core is not None else study.command
        print(f"[{datetime.datetime.now():%H:%M:%S}] start {study.name} (core {core}): "
              f"{' '.join(study.command)}", flush=True)
        with open(log, "w") as f:
            p = subprocess.run(command, stdout=f, stderr=subprocess.STDOUT, env=ENV, cwd=ROOT)
        study.seconds = time.time() - start
        study.status = "ok" if p.returncode == 0 else f"failed (exit {p.returncode}, see {log})"
        print(f"[{datetime.datetime.now():%H:%M:%S}] {study.name}: {study.status}, "
              f"{study.seconds / 60:.1f} min", flush=True)

    def pinned(study):
        with lock:
            core = free.pop()
        try:
            one(study, core)
        finally:
            with lock:
                free.append(core)

    shared = sorted((s for s in selected if not s.exclusive), key=lambda s: -s.minutes)
    with concurrent.futures.ThreadPoolExecutor(max_workers=lanes) as pool:
        list(pool.map(pinned, shared))
    for s in selected:
        if s.exclusive:
            one(s, None)          # its 2-rank run needs both cores, so it runs alone, unpinned


# --------------------------------------------------------------------------------------------
# The runs of every scene, from the studies' CSVs
# --------------------------------------------------------------------------------------------
class Scene:
    """One verification scene: its runs (method, setting, time, error), front and default."""

    def __init__(self, key, title, reference, error_label, time_label, target, study, note=""):
        self.key, self.title, self.reference = key, title, reference
        self.error_label, self.time_label, self.target = error_label, time_label, target
        self.study, self.note, self.runs = study, note, []

    def add(self, method, setting, time_s, error, ok=True, admissible=True):
        if ok and not (math.isfinite(time_s) and math.isfinite(error)):
            ok = False
        self.runs.append(dict(method=method, setting=setting, time=time_s, error=error, ok=ok,
                              admissible=admissible))

    def front(self):
        candidates = sorted((r for r in self.runs if r["ok"] and r["admissible"] and r["error"] > 0),
                            key=lambda r: (r["time"], r["error"]))
        best, front = math.inf, []
        for r in candidates:
            if r["error"] < best:
                front.append(r)
                best = r["error"]
        return front

    def recommended(self):
        front = self.front()
        if not front:
            return None, False
        within = [r for r in front if r["error"] <= self.target]
        return (within[0], True) if within else (front[-1], False)


def read_csv(out, name):
    path = os.path.join(out, name)
    if not os.path.exists(path):
        raise SystemExit(f"make_report.py: {path} is missing; run the study that writes it "
                         f"(or the whole script without --report-only)")
    with open(path) as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def collect(out):
    scenes = {}

    def scene(*a, **k):
        s = Scene(*a, **k)
        scenes[s.key] = s
        return s

    # Bouc-Wen updates, n = 8, every stress state.
    names = {1: "forward Euler", 2: "adaptive", 3: "backward Euler"}
    sweep = read_csv(out, "material_sweep.csv")
    for key, title, dim, ps in (("material_ps", "Bouc–Wen update, plane stress", 2, 1),
                                ("material_pe", "Bouc–Wen update, plane strain", 2, 0),
                                ("material_3d", "Bouc–Wen update, 3D", 3, 0)):
        s = scene(key, f"{title} (n = 8, cyclic non-proportional path)",
                  "adaptive, tolerance 1e-12, 153,600 increments per cycle",
                  "max |σ − σ_ref| / σ_y", "µs per point and cycle", 1e-4, "material")
        for r in sweep:
            if int(number(r["dim"])) == dim and int(number(r["plane_stress"])) == ps:
                i = int(number(r["integrator"]))
                steps = int(number(r["steps_per_cycle"]))
                setting = (f"tol {number(r['tolerance']):.0e}, {steps} inc./cycle" if i == 2
                           else f"{steps} inc./cycle")
                s.add(names[i], setting, 1e6 * number(r["seconds_per_point_cycle"]), number(r["error"]))

    rows = read_csv(out, "mpm_error_vs_time.csv")
    vg = scene("velocity_gradient", "MPM velocity gradient (§4.6.1, Table 4-1/4-2)",
               "the exact L of the prescribed velocity field", "interior RMS of L_p − L [1/s]",
               "s (in-process)", 1e-6, "mpm_error_vs_time")
    tb = scene("taylor_bar", "MPM Taylor bar, 2D plane strain (§5.8)",
               "L_f of cubic, h = D0/40, 3x3 points (converged)", "|L_f − L_f,ref| / L_f,ref",
               "s (steps)", 1e-2, "mpm_error_vs_time",
               note="front over the admissible runs: D_f and D within 3 % of the reference")
    for r in rows:
        basis = "cubic" if r["basis"].startswith("cubic") else "linear"
        setting = f"h = {r['h_label']}, {r['k']}x{r['k']}"
        if r["study"] == "velocity gradient":
            vg.add(f"MPM {basis}", setting, number(r["time"]), number(r["error"]), r["status"] == "ok")
        elif r["reference"] != "True":
            tb.add(f"MPM {basis}", setting, number(r["time"]), number(r["error"]), r["status"] == "ok",
                   r["admissible"] == "True")

    rows = read_csv(out, "mpm_scheme_time_step.csv")
    vb = scene("vibrating_bar", "MPM vibrating bar (first axial mode)", "the analytic mode",
               "max |u_x − u_exact| / amplitude at the tip", "s (steps)", 1e-2, "mpm_scheme_time_step",
               note="front over the runs with CFL factor ≤ 0.8, a margin below the stability bound "
                    "(the linear basis goes unstable inside it on fine grids)")
    for r in rows:
        vb.add(f"MPM {r['basis'].replace(' B-spline', '')}, {r['scheme']}",
               f"h = {r['h_label']}, CFL {number(r['cfl']):g}, {r['k']}x{r['k']}", number(r["time"]),
               number(r["error"]), r["status"] == "ok", number(r["cfl"]) <= 0.8)

    rows = read_csv(out, "fem_mpm_error_vs_time.csv")
    cantilever = scene("cantilever", "Elastic cantilever, FEM against MPM",
                       "FEM Q2, Richardson-extrapolated (D/16, D/32, D/64)", "|q − q_ref| / q_ref (tip deflection)",
                       "s (steps)", 1e-3, "fem_mpm_error_vs_time")
    patch = scene("patch", "§5.4 square patch in tension, FEM against MPM",
                  "FEM Q2, h = 0.3/30, 800 increments", "|σ_vM(A) − ref| / ref", "s (steps)", 1e-2,
                  "fem_mpm_error_vs_time")
    for r in rows:
        method = f"{r['method']} {r['variant']}"
        setting = f"h = {r['h_label']}" + (f", {r['k']}x{r['k']}" if r["k"] else "")
        (cantilever if r["problem"] == "cantilever" else patch).add(
            method, setting, number(r["time"]), number(r["error"]), r["status"] == "ok")

    rows = read_csv(out, "fem_plastic_error_vs_time.csv")
    for r in rows:
        key = "fem_" + re.sub(r"[^a-z0-9]+", "_", (r["scene"] + " " + r["quantity"]).lower()).strip("_")
        if key not in scenes:
            how = ("the independent elastic solution" if "stiffness" in r["quantity"]
                   else "converged FEM, extrapolated in h and the increments")
            scene(key, f"{r['scene']}, FEM: {r['quantity']}",
                  f"{how}, q_ref = {number(r['q_ref']):.6g} (see the study)",
                  "|q − q_ref| / q_ref", "s (steps)", 1e-2, "fem_plastic_error_vs_time")
        scenes[key].add(f"FEM Q{r['degree']}, {r['integrator']}",
                        f"h = {r['h']}, {r['increments']} inc.", number(r["time"]), number(r["error"]),
                        r["status"] == "ok")

    rows = read_csv(out, "rbsn_run_time.csv")
    rt = scene("rbsn_table_3_2", "RBSN elastic cantilever (Table 3-2)",
               "the dissertation's Table 3-2 deflection at the same d_m", "|δ − δ_table| / δ_table",
               "s (whole run)", 2e-2, "rbsn_run_time")
    for r in rows:
        if r["scene"].startswith("elastic cantilever"):
            rt.add("RBSN", f"d_m = {r['d_m']} m ({r['cells']} cells)", number(r["seconds"]), number(r["error"]))

    rows = read_csv(out, "rbsn_cantilever_plastic.csv")
    rp = scene("rbsn_plastic", "RBSN plastic cantilever (§5.1)", "beam theory P_u = 30 kN",
               "|P(50 mm) − P_u| / P_u", "s (whole run)", 5e-2, "rbsn_cantilever_plastic")
    for r in rows:
        rp.add(f"RBSN {r['springs']}", f"d_m = {r['d_m']} m, seed {r['seed']}", number(r["time"]),
               number(r["error"]))

    rows = read_csv(out, "rbsn_newmark_vs_variable_order.csv")
    for scenario in ("undamped", "damped"):
        s = scene(f"rbsn_dynamics_{scenario}", f"RBSN §3.6.1 element, dynamic, {scenario}",
                  "variable order (IDA) at relative tolerance 1e-10", "max |u_x − u_ref| / max |u_ref|",
                  "s (steps)", 1e-3, "rbsn_newmark_vs_variable_order")
        for r in rows:
            if r["scenario"] == scenario:
                label = (f"Δt = {r['setting']} s" if r["method"] == "Newmark" else f"rtol {r['setting']}")
                s.add(r["method"], label, number(r["time"]), number(r["error_u"]))
    return scenes


# --------------------------------------------------------------------------------------------
# Figures and text
# --------------------------------------------------------------------------------------------
def plot_fronts(scenes, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(scenes)
    columns = 4
    rows = math.ceil(len(keys) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.5 * rows), dpi=90)
    for ax in axes.flat[len(keys):]:
        ax.axis("off")
    for ax, key in zip(axes.flat, keys):
        s = scenes[key]
        methods = sorted({r["method"] for r in s.runs})
        for i, m in enumerate(methods):
            sel = [r for r in s.runs if r["method"] == m and r["ok"] and r["error"] > 0]
            ax.loglog([r["time"] for r in sel], [r["error"] for r in sel], "o", ms=3.5,
                      color=f"C{i % 10}", alpha=0.75, label=m)
        front = s.front()
        if front:
            ax.loglog([r["time"] for r in front], [r["error"] for r in front], "k-", lw=1.0)
        rec, _ = s.recommended()
        if rec:
            ax.loglog([rec["time"]], [rec["error"]], "*", ms=13, mfc="none", mec="red", mew=1.5)
        ax.axhline(s.target, color="gray", ls=":", lw=1)
        ax.set_title(s.title, fontsize=8)
        ax.set_xlabel(s.time_label, fontsize=7)
        ax.set_ylabel(s.error_label, fontsize=7)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=5.5, loc="best")
    fig.suptitle("Error against run time per verification scene: black line = Pareto front, "
                 "red star = recommended default, dotted = target", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.98))
    tmp = path + ".tmp.png"
    fig.savefig(tmp)
    os.replace(tmp, path)       # a failed plot leaves the old figure, never half a file


def cell(text):
    """Text for a Markdown table cell."""
    return str(text).replace("|", "\\|")


def fmt(x, digits=2):
    if x is None or not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e4:
        return f"{x:.{max(0, digits - 1 - math.floor(math.log10(abs(x))))}f}"
    return f"{x:.{digits - 1}e}"


class Context:
    """What the template's `{{ ... }}` fields may call."""

    def __init__(self, scenes, out, info):
        self.scenes, self.out, self.info = scenes, out, info

    def scene(self, key):
        if key not in self.scenes:
            raise KeyError(f"no scene '{key}' (have: {', '.join(self.scenes)})")
        return self.scenes[key]

    def front(self, key):
        s = self.scene(key)
        lines = [f"| method | setting | time [{s.time_label}] | error |", "|---|---|---|---|"]
        for r in s.front():
            lines.append(f"| {cell(r['method'])} | {cell(r['setting'])} | {fmt(r['time'], 3)} | {fmt(r['error'])} |")
        return "\n".join(lines)

    def rec(self, key):
        rec, met = self.scene(key).recommended()
        if rec is None:
            return "no successful run"
        return (f"{rec['method']}, {rec['setting']} ({fmt(rec['error'])} in {fmt(rec['time'], 3)} "
                f"{self.scene(key).time_label.split(' (')[0]}"
                + ("" if met else f"; the target {fmt(self.scene(key).target)} is not reached") + ")")

    def best(self, key, method_prefix, level):
        """The cheapest successful run of the methods starting with method_prefix within level."""
        s = self.scene(key)
        runs = [r for r in s.runs if r["ok"] and r["admissible"] and r["method"].startswith(method_prefix)]
        if not runs:
            raise KeyError(f"scene '{key}' has no run of '{method_prefix}'")
        within = [r for r in runs if r["error"] <= level]
        unit = s.time_label.split(" (")[0]
        if not within:
            r = min(runs, key=lambda r: r["error"])
            return f"not reached (best {fmt(r['error'])}, {r['setting']}, {fmt(r['time'], 3)} {unit})"
        r = min(within, key=lambda r: r["time"])
        return f"{fmt(r['time'], 3)} {unit} ({r['method']}, {r['setting']}: {fmt(r['error'])})"

    def time_to(self, key, method_prefix, level):
        runs = [r for r in self.scene(key).runs if r["ok"] and r["admissible"]
                and r["method"].startswith(method_prefix) and r["error"] <= level]
        return min((r["time"] for r in runs), default=math.nan)

    def ratio(self, key, slow, fast, level):
        return fmt(self.time_to(key, slow, level) / self.time_to(key, fast, level))

    def failed(self, key):
        return sum(1 for r in self.scene(key).runs if not r["ok"])

    def count(self, key):
        return len(self.scene(key).runs)

    def table(self, name, first=0, last=None):
        """The Markdown table lines of OUT/name (the first table, or rows first..last)."""
        text = open(os.path.join(self.out, name)).read().splitlines()
        start = next(i for i, l in enumerate(text) if l.startswith("|"))
        end = next((i for i in range(start, len(text)) if not text[i].startswith("|")), len(text))
        return "\n".join(text[start:end])

    def csv(self, name, column, **where):
        """One value of OUT/name: the column of the one row matching every where=value."""
        rows = [r for r in read_csv(self.out, name)
                if all(r.get(k.replace("__", " ")) == str(v) for k, v in where.items())]
        if len(rows) != 1:
            raise KeyError(f"{name}: {len(rows)} rows match {where}")
        return number(rows[0][column])

    def scenes_of(self, study):
        """Every scene of a study: reference, error, the front and the recommended default."""
        parts = []
        for key, s in self.scenes.items():
            if s.study != study:
                continue
            parts.append(f"**{s.title}.** Reference: {s.reference}. Error: {s.error_label}. "
                         f"{len(s.runs)} runs, {self.failed(key)} of them failed or refused"
                         + (f"; {s.note}" if s.note else "") + f". Recommended default (target "
                         f"{fmt(s.target)}): **{self.rec(key)}**.\n\nPareto front:\n\n{self.front(key)}")
        if not parts:
            raise KeyError(f"no scene of study '{study}'")
        return "\n\n".join(parts)

    def summary(self):
        lines = ["| scene | reference | error | target | recommended default | runs | front |",
                 "|---|---|---|---|---|---|---|"]
        for key, s in self.scenes.items():
            lines.append(f"| {cell(s.title)} | {cell(s.reference)} | {cell(s.error_label)} | {fmt(s.target)} | {cell(self.rec(key))} | "
                         f"{len(s.runs)} ({self.failed(key)} failed) | {len(s.front())} |")
        return "\n".join(lines)


def namespace(context):
    names = {name: getattr(context, name) for name in dir(context) if not name.startswith("_")}
    names.update(fmt=fmt, info=context.info, math=math)
    return names


def machine_info(args, started, load_before, load_samples, selected):
    return dict(
        environment(args.build, ROOT),
        date=started.strftime("%Y-%m-%d %H:%M UTC"), repeats=args.repeats, lanes=args.lanes,
        command=" ".join(["benchmarks/make_report.py", *sys.argv[1:]]),
        load_before=load_before,
        load_during=(f"median {sorted(load_samples)[len(load_samples) // 2]:.2f}, max {max(load_samples):.2f}"
                     if load_samples else "not sampled"),
        studies="; ".join(f"{s.name} {s.seconds / 60:.1f} min" for s in selected if s.seconds is not None),
        total=f"{sum(s.seconds for s in selected if s.seconds is not None) / 60:.0f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build", help="a Release build directory (holds hysteron)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--lanes", type=int, default=1, choices=(1, 2))
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only", default="", help="comma-separated studies to run")
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument("--out", help="the studies' output directory (default doc/benchmarks)")
    parser.add_argument("--doc", help="the report (default doc/benchmarks.md; --quick: OUT/benchmarks.md)")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    if not os.access(os.path.join(args.build, "hysteron"), os.X_OK):
        raise SystemExit(f"make_report.py: no hysteron executable in {args.build}")
    if "CMAKE_BUILD_TYPE:STRING=Release" not in open(os.path.join(args.build, "CMakeCache.txt")).read():
        raise SystemExit(f"make_report.py: {args.build} is not a Release build")
    work = tempfile.mkdtemp(prefix="hysteron_report_")
    out = os.path.abspath(args.out or (os.path.join(work, "quick") if args.quick
                                       else os.path.join(ROOT, "doc", "benchmarks")))
    doc = os.path.abspath(args.doc or (os.path.join(out, "benchmarks.md") if args.quick
                                       else os.path.join(ROOT, "doc", "benchmarks.md")))
    os.makedirs(out, exist_ok=True)
    started = datetime.datetime.utcnow()
    load_before = open("/proc/loadavg").read().split()[0]
    all_studies = studies(args, out, work)
    known = {s.name for s in all_studies}
    only = {x for x in args.only.split(",") if x}
    if only - known:
        raise SystemExit(f"make_report.py: unknown studies {sorted(only - known)}; known: {sorted(known)}")
    selected = [s for s in all_studies if (not only or s.name in only) and (s.in_quick or not args.quick)]
    samples, done = [], threading.Event()
    if not args.report_only:
        def sample():
            while not done.wait(30):
                samples.append(float(open("/proc/loadavg").read().split()[0]))
        threading.Thread(target=sample, daemon=True).start()
        print(f"results in {out}; logs and scratch in {work}", flush=True)
        run_studies(selected, args.lanes, work)
        done.set()
        failed = [s for s in selected if s.status != "ok"]
        if failed:
            raise SystemExit("make_report.py: " + "; ".join(f"{s.name}: {s.status}" for s in failed))

    scenes = collect(out)
    plot_fronts(scenes, os.path.join(out, "pareto_fronts.png"))
    info = machine_info(args, started, load_before, samples, selected)
    # The record of the run that measured the studies' files: written by a full run, updated
    # by --only (the studies it reran, with their commit), read by --report-only.
    run_file = os.path.join(out, "report_run.json")
    keys = ("date", "repeats", "lanes", "command", "load_before", "load_during", "studies", "total", "commit")
    if args.report_only or only:
        if not os.path.exists(run_file):
            raise SystemExit(f"make_report.py: --report-only and --only need {run_file} of a full run")
        with open(run_file) as f:
            measured = json.load(f)
        if only and not args.quick:
            reran = "; ".join(f"{s.name} {s.seconds / 60:.1f} min on {info['date']} at {info['commit']}"
                              for s in selected)
            measured["studies"] += f"; rerun with --only: {reran}"
            write_atomically(run_file, json.dumps(measured, indent=1))
        # The machine of the full run (older records lack it: then this one's).
        info.update({k: measured[k] for k in keys + ("cpu", "os", "memory") if k in measured})
        if args.report_only:
            info["command"] += " (report rebuilt by --report-only)"
    elif not args.quick:
        write_atomically(run_file, json.dumps({k: info[k] for k in keys + ("cpu", "os", "memory")}, indent=1))
    context = Context(scenes, out, info)
    text = fill(open(os.path.join(ROOT, "benchmarks", "benchmarks.md.in")).read(), namespace(context),
                "make_report.py")
    write_atomically(doc, text)
    print(f"wrote {doc} and {os.path.join(out, 'pareto_fronts.png')}")


if __name__ == "__main__":
    main()
