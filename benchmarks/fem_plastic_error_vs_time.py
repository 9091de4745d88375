#!/usr/bin/python3
"""FEM with Bouc-Wen plasticity: error versus run time on the §5.1 plastic cantilever and the
§3.7.4 perforated plate, across degree, cell size, number of increments and integrator, with the
Pareto fronts and a recommended default per scene.

Both scenes are quasi-static FEM runs of the shipped scene files with `FEM/Degree`,
`FEM/Mesh/Cell size`, `FEM/Number of increments` and `Material/Bouc-Wen/Integrator` replaced,
`Output/Directory = output`, `Output/Write VTU = false`, `FEM/Write quadrature point table =
false` and the `# CHECK` lines dropped (they hold for the shipped settings only).

(1) Plastic cantilever, dissertation §5.1, prm/fem_cantilever_plastic.prm (elastic-perfectly
    plastic, plane stress, the tip node (1, 0) driven down to 30 mm). Quantity: the tip load
    -tip_y in the last row of output/reactions.csv (t = 1, 30 mm: the collapse plateau; the
    scene's `CHECK-LAST output/reactions.csv: 30e3 < -tip_y < 31.5e3`, 30.97 kN shipped).
    Grid: backward Euler, Q1 with h = 0.05, 0.025, 0.0125, 0.00625 m and Q2 with h = 0.05,
    0.025, 0.0125 m, each at 15 and 60 increments, and at h = 0.0125 m also 30 and 120; the
    `adaptive` integrator at Q1 h = 0.0125 (15) and Q2 h = 0.025 (15, 60). Reference run: Q2,
    h = 0.00625 m, 15 increments. Reference value:
        q_ref = R_h + [q(Q2, 0.0125, 120) - q(Q2, 0.0125, 15)]
    where R_h is the Richardson extrapolation of Q2 at 15 increments from h = 0.025, 0.0125,
    0.00625 with the observed rate (fem_mpm_error_vs_time.richardson), and the bracket the
    increment correction measured at h = 0.0125 (errors in h and in the increment assumed
    additive). Estimated uncertainty: U = max(a, b) + c with (a) the change of q_ref when R_h
    uses h = 0.05, 0.025, 0.0125 instead, (b) its difference from the same construction with Q1
    (h = 0.025, 0.0125, 0.00625; increment correction of Q1 at 0.0125), (c) the last increment
    difference q(Q2, 0.0125, 120) - q(Q2, 0.0125, 60) (first order: the error left at 120). The
    beam-theory plastic hinge P_u = sigma_y b D^2 / (4 L) = 30 kN is listed for scale.
(2) Perforated plate, dissertation §3.7.4, prm/fem_perforated_plate.prm (quarter model,
    displacement control of the top edge to 4 mm). Quantities from output/reactions.csv:
    (a) the initial stiffness K0 = top_y[1] / (4e-3 time[1]) (first increment), against K_ref,
        the independent elastic reference (doc/scripts/perforated_plate_elastic_reference.py,
        biquadratic code with the exact circular hole, converged to 2.5e-7; the value is read
        from the `K_ref` comment of the scene file, as in doc/verification/fem_perforated_plate.md);
        its uncertainty is that last change; hysteron's 64-gon hole keeps every run with an
        elastic first increment about +7e-4 above it (a floor, listed: the K0 of the Q2 run with
        the most increments);
    (b) the load at 4 mm, top_y in the last row (t = 1), against a converged FEM value
        q_ref = q(Q2, 0.0125, 20) + [q(Q2, 0.05, 160) - q(Q2, 0.05, 20)] (the finest mesh and
        the increment correction measured at h = 0.05); uncertainty |q(Q2, 0.0125, 20) -
        q(Q2, 0.025, 20)| + |q(Q2, 0.05, 160) - q(Q2, 0.05, 80)|.
    Grid: backward Euler, Q1 with h = 0.1, 0.05, 0.025, 0.0125 m and Q2 with h = 0.1, 0.05,
    0.025 m at 20 increments; Q2 h = 0.05 also at 10, 40, 80 (the shipped scene) and 160; the
    `adaptive` integrator at Q2 h = 0.05, 20 increments. Reference run: Q2, h = 0.0125, 20
    (it is also a K0 run of the sweep).
Errors below a reference's uncertainty are listed as not resolved (and shaded in the figure).
The `adaptive` integrator returns the continuum tangent (doc/fem.md): Newton converges linearly
and may cut increments; `backward euler` returns the consistent tangent. `forward euler` is not
swept (the same continuum tangent, and stable only for small increments).

Time = the `steps` section of hysteron's timer table (set-up and output excluded), the median of
--repeats runs (mpm_error_vs_time.repeat: a setting whose timed part exceeds 60 s is run once).
Error = |q - q_ref| / |q_ref|. The Pareto front is marked per quantity
(mpm_error_vs_time.mark_pareto; the reference run of a quantity is left out). Recommended
default per scene: the cheapest run (by time) whose errors are <= 1e-2 in every quantity of the
scene, among the runs on the Pareto front of at least one of them (for one quantity: the
cheapest Pareto run with error <= 1e-2). A run that fails (non-zero exit status, a non-finite
value, an unfinished load history) is recorded with its message. The script does not pin
hysteron to a core; run it under taskset for stable times (it reports the affinity it had).

Each setting runs in WORKDIR/runs/<scene>/<setting>/ (default WORKDIR /tmp/fem_plastic_bench;
hysteron's output of the last run in stdout.txt). If a run that a reference needs fails, the
script stops without writing the report. --quick runs a subset in under a minute (references
from coarser meshes, not converged: it checks the script, not the numbers) in
WORKDIR/quick_runs. Writes OUT/fem_plastic_error_vs_time.{csv,md,png}; OUT = doc/benchmarks
(with --quick: WORKDIR/quick).

Usage: fem_plastic_error_vs_time.py BUILD_DIR [--repeats 3] [--quick] [--workdir DIR] [--out DIR]
"""
import argparse
import csv
import datetime
import math
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_error_vs_time as bench  # noqa: E402  (timers, repeat, mark_pareto, machine, build_info)
import fem_mpm_error_vs_time as fem_mpm  # noqa: E402  (richardson)

ROOT = bench.ROOT
with_entry = bench.with_entry
TOLERANCE = 1e-2                  # error bound of the recommended default
BE, AD = "backward euler", "adaptive"
CANTILEVER, PLATE = "plastic cantilever (§5.1)", "perforated plate (§3.7.4)"
TIP_LOAD, STIFFNESS, LOAD_4MM = "tip load at 30 mm", "initial stiffness", "load at 4 mm"
QUANTITIES = {CANTILEVER: (TIP_LOAD,), PLATE: (STIFFNESS, LOAD_4MM)}
UNITS = {TIP_LOAD: "N", STIFFNESS: "N/m", LOAD_4MM: "N"}
P_U = 240e6 * 0.05 * 0.1**2 / (4 * 1.0)   # beam-theory plastic hinge load of §5.1 [N]
PLATE_DISPLACEMENT = 4e-3                 # the prescribed edge displacement at t = 1 [m]
K_REF_CONVERGENCE = 2.5e-7               # plate: the last refinement's change of K_ref (same report)
FIRST_YIELD_DISPLACEMENT = 0.545e-3       # plate: first yield at the root, doc/verification/fem_perforated_plate.md


def grid(scene, quick):
    """The settings (degree, h, increments, integrator, reference-of) of a scene; the reference
    settings of the quantities (see the docstring) and the h / increment series they use."""
    if scene == CANTILEVER:
        if quick:
            runs = [(1, 0.05, 15, BE), (2, 0.05, 15, BE), (2, 0.05, 30, BE), (2, 0.05, 60, BE),
                    (2, 0.025, 15, BE), (2, 0.05, 15, AD)]
            ref = dict(degree=2, hs=(0.05, 0.025, 0.0125), n=15, inc_h=0.05, inc_n=(15, 30, 60), q1_hs=())
        else:
            runs = [(1, h, n, BE) for h in (0.05, 0.025, 0.0125, 0.00625) for n in (15, 60)]
            runs += [(1, 0.0125, 30, BE), (1, 0.0125, 120, BE)]
            runs += [(2, h, n, BE) for h in (0.05, 0.025, 0.0125) for n in (15, 60)]
            runs += [(2, 0.0125, 30, BE), (2, 0.0125, 120, BE)]
            runs += [(1, 0.0125, 15, AD), (2, 0.025, 15, AD), (2, 0.025, 60, AD)]
            ref = dict(degree=2, hs=(0.025, 0.0125, 0.00625), n=15, inc_h=0.0125, inc_n=(15, 60, 120),
                       q1_hs=(0.025, 0.0125, 0.00625), coarse_hs=(0.05, 0.025, 0.0125))
        settings = [dict(degree=p, h=h, increments=n, integrator=i, reference_of=()) for p, h, n, i in runs]
        settings.append(dict(degree=2, h=ref["hs"][-1], increments=ref["n"], integrator=BE,
                             reference_of=(TIP_LOAD,)))
        return settings, ref
    if quick:
        runs = [(1, 0.1, 10, BE), (1, 0.1, 20, BE), (1, 0.1, 40, BE), (2, 0.1, 10, BE)]
        ref = dict(h=0.05, n=10, inc_degree=1, inc_h=0.1, inc_n=(10, 20, 40), coarse_h=0.1)
    else:
        runs = [(1, h, 20, BE) for h in (0.1, 0.05, 0.025, 0.0125)]
        runs += [(2, h, 20, BE) for h in (0.1, 0.05, 0.025)]
        runs += [(2, 0.05, n, BE) for n in (10, 40, 80, 160)]
        runs += [(2, 0.05, 20, AD)]
        ref = dict(h=0.0125, n=20, inc_h=0.05, inc_n=(20, 80, 160), coarse_h=0.025)
    settings = [dict(degree=p, h=h, increments=n, integrator=i, reference_of=()) for p, h, n, i in runs]
    settings.append(dict(degree=2, h=ref["h"], increments=ref["n"], integrator=BE, reference_of=(LOAD_4MM,)))
    return settings, ref


def label(s):
    return f"Q{s['degree']}, h = {s['h']:g}, {s['increments']} inc., {s['integrator']}"


def scene_text(path, s):
    text = "".join(l for l in open(path).read().splitlines(True) if not l.lstrip().startswith("# CHECK"))
    text = with_entry(text, "FEM", "Degree", str(s["degree"]))
    text = with_entry(text, "FEM", "Number of increments", str(s["increments"]))
    text = with_entry(text, "Mesh", "Cell size", f"{s['h']:.10g}")
    text = with_entry(text, "Bouc-Wen", "Integrator", s["integrator"])
    text = with_entry(text, "Output", "Directory", "output")
    if re.search(r"^\s*set Write quadrature point table\s*=", text, re.M):
        text = with_entry(text, "FEM", "Write quadrature point table", "false")
    if re.search(r"^\s*set Write VTU\s*=", text, re.M):
        return with_entry(text, "Output", "Write VTU", "false")
    return text.replace("\nsubsection Output\n", "\nsubsection Output\n  set Write VTU = false\n", 1)


def run_once(hysteron, directory):
    """One run of directory/scene.prm (timer table on): the timings and the solver's counts."""
    started = time.perf_counter()
    done = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=bench.ENV, capture_output=True, text=True)
    wall = time.perf_counter() - started
    with open(os.path.join(directory, "stdout.txt"), "w") as f:
        f.write(done.stdout + done.stderr)
    if done.returncode:
        raise RuntimeError(f"exit status {done.returncode}: {bench.first_line(done.stderr or done.stdout)}")
    sections = bench.timers(done.stdout)
    mesh = re.search(r"fem: (\d+) cells, (\d+) DoFs", done.stdout)
    finish = re.search(r"\((\d+) steps, (\d+) Newton iterations, (\d+) increment cuts", done.stdout)
    if "steps" not in sections or not mesh or not finish:
        raise RuntimeError("unexpected output: " + bench.first_line(done.stdout))
    return dict(steps_s=sections["steps"], total_s=sections["total"], wall_s=wall, cells=int(mesh.group(1)),
                dofs=int(mesh.group(2)), steps=int(finish.group(1)), newton_iterations=int(finish.group(2)),
                increment_cuts=int(finish.group(3)))


def measured_values(scene, directory):
    """The quantities of a finished run {quantity: value}, from output/reactions.csv."""
    with open(os.path.join(directory, "output", "reactions.csv")) as f:
        table = list(csv.DictReader(f))
    if abs(float(table[-1]["time"]) - 1.0) > 1e-9:
        raise RuntimeError(f"the load history ended at t = {table[-1]['time']}")
    if scene == CANTILEVER:
        values = {TIP_LOAD: -float(table[-1]["tip_y"])}
    else:
        values = {STIFFNESS: float(table[1]["top_y"]) / (PLATE_DISPLACEMENT * float(table[1]["time"])),
                  LOAD_4MM: float(table[-1]["top_y"])}
    bad = [name for name, value in values.items() if not math.isfinite(value)]
    if bad:
        raise RuntimeError("non-finite " + ", ".join(bad))
    return values


def study(scene, scene_file, hysteron, workdir, repeats, quick):
    """Run every setting of the scene; return the runs (one dict per setting)."""
    settings, ref = grid(scene, quick)
    runs = []
    for s in settings:
        name = f"q{s['degree']}_h{s['h']:g}_n{s['increments']}_{s['integrator'].split()[0]}"
        directory = os.path.join(workdir, "cantilever" if scene == CANTILEVER else "plate", name)
        os.makedirs(directory, exist_ok=True)
        with open(os.path.join(directory, "scene.prm"), "w") as f:
            f.write(scene_text(scene_file, s))
        run = dict(s, scene=scene, setting=label(s), status="ok", message="")
        try:
            r = bench.repeat(lambda: run_once(hysteron, directory), repeats, "steps_s")
            run.update(r, time=r["steps_s"], runs=r["repeats"], values=measured_values(scene, directory))
        except RuntimeError as error:
            run.update(status="failed", message=str(error), values={})
            print(f"{scene}: {label(s)}: FAILED {error}", flush=True)
            runs.append(run)
            continue
        print(f"{scene}: {label(s)}: {r['dofs']} DoFs, {r['newton_iterations']} Newton iterations, "
              f"{r['increment_cuts']} cuts, {r['steps_s']:.3f} s (x{r['repeats']}), "
              + ", ".join(f"{k} {v:.7g}" for k, v in run["values"].items()), flush=True)
        runs.append(run)
    return runs, ref


def value(runs, quantity, degree, h, increments, integrator=BE):
    for r in runs:
        if (r["degree"], r["integrator"], r["increments"]) == (degree, integrator, increments) \
                and math.isclose(r["h"], h) and quantity in r["values"]:
            return r["values"][quantity]
    return None


def cantilever_reference(runs, ref):
    q = lambda p, h, n: value(runs, TIP_LOAD, p, h, n)  # noqa: E731
    n0, (n_lo, n_mid, n_hi) = ref["n"], ref["inc_n"]

    def construction(p, hs):
        values = [q(p, h, n0) for h in hs]
        corr = [q(p, ref["inc_h"], n) for n in (n_lo, n_hi)]
        if None in values or None in corr:
            return None
        limit, rate = fem_mpm.richardson(list(hs), values)
        return dict(hs=hs, values=values, limit=limit, rate=rate, correction=corr[1] - corr[0],
                    q_ref=limit + corr[1] - corr[0])

    main = construction(2, ref["hs"])
    if main is None:
        raise RuntimeError("the reference runs of the cantilever failed")
    result = dict(main, kind="richardson", increments=n0, inc_h=ref["inc_h"], inc_n=ref["inc_n"])
    coarse = construction(2, ref["coarse_hs"]) if ref.get("coarse_hs") else None
    q1 = construction(1, ref["q1_hs"]) if ref.get("q1_hs") else None
    result["coarse"], result["q1"] = coarse, q1
    a = abs(coarse["q_ref"] - main["q_ref"]) if coarse else 0.0
    b = abs(q1["q_ref"] - main["q_ref"]) if q1 else 0.0
    c = abs(q(2, ref["inc_h"], n_hi) - q(2, ref["inc_h"], n_mid))
    result.update(u_coarse=a, u_q1=b, u_increments=c, uncertainty=max(a, b) + c)
    return {TIP_LOAD: result}


def plate_reference(runs, ref, scene_file):
    k_ref = float(re.search(r"K_ref\s*=\s*([0-9.eE+-]+)\s*N/m", open(scene_file).read()).group(1))
    q = lambda h, n, p=2: value(runs, LOAD_4MM, p, h, n)  # noqa: E731
    n_lo, n_mid, n_hi = ref["inc_n"]
    p_inc = ref.get("inc_degree", 2)
    fine, coarse = q(ref["h"], ref["n"]), q(ref["coarse_h"], ref["n"])
    lo, mid, hi = (q(ref["inc_h"], n, p_inc) for n in (n_lo, n_mid, n_hi))
    if None in (fine, coarse, lo, mid, hi):
        raise RuntimeError("the reference runs of the perforated plate failed")
    # The stiffness floor: the Q2 run with the most increments (an elastic first increment; Q2's K0
    # is converged in h to 1e-5, the rest is the polygonal hole), the finest of them.
    floor_runs = [r for r in runs if r["status"] == "ok" and r["degree"] == 2 and r["integrator"] == BE]
    floor_run = min(floor_runs, key=lambda r: (-r["increments"], r["h"]))
    k_fine = floor_run["values"][STIFFNESS]
    return {STIFFNESS: dict(kind="external", q_ref=k_ref, uncertainty=K_REF_CONVERGENCE * k_ref,
                            floor=k_fine / k_ref - 1, floor_setting=floor_run["setting"]),
            LOAD_4MM: dict(kind="fem", q_ref=fine + hi - lo, fine=fine, coarse=coarse, h=ref["h"], n=ref["n"],
                           coarse_h=ref["coarse_h"], inc_degree=p_inc, inc_h=ref["inc_h"], inc_n=(n_lo, n_mid, n_hi),
                           inc_values=(lo, mid, hi), correction=hi - lo, u_h=abs(fine - coarse),
                           u_increments=abs(hi - mid), uncertainty=abs(fine - coarse) + abs(hi - mid))}


def make_rows(runs, references):
    """One row per run and quantity, with the error; the Pareto fronts per quantity."""
    rows = []
    for run in runs:
        for quantity in QUANTITIES[run["scene"]]:
            row = {k: v for k, v in run.items() if k != "values"}
            row.update(method="FEM", quantity=quantity, q_ref=references[quantity]["q_ref"], pareto=False,
                       reference=quantity in run["reference_of"])
            if run["status"] == "ok":
                row["q"] = run["values"][quantity]
                row["error"] = abs(row["q"] - row["q_ref"]) / abs(row["q_ref"])
            rows.append(row)
    fronts = {}
    for scene, quantities in QUANTITIES.items():
        for quantity in quantities:
            group = [r for r in rows if r["scene"] == scene and r["quantity"] == quantity]
            if group:
                fronts[quantity] = bench.mark_pareto(group)
    return rows, fronts


def recommend(rows, scene):
    """The cheapest run with error <= TOLERANCE in every quantity of the scene, among the runs on
    the Pareto front of at least one quantity (see the docstring)."""
    by_setting = {}
    for r in rows:
        if r["scene"] == scene:
            by_setting.setdefault(r["setting"], []).append(r)
    candidates = [group for group in by_setting.values()
                  if all(r["status"] == "ok" and not r["reference"] and r["error"] <= TOLERANCE for r in group)
                  and len(group) == len(QUANTITIES[scene])]
    on_front = [g for g in candidates if any(r["pareto"] for r in g)]
    pool = on_front or candidates
    return min(pool, key=lambda g: g[0]["time"]) if pool else None


COLUMNS = ["scene", "method", "setting", "degree", "h", "increments", "integrator", "cells", "dofs", "status",
           "time", "runs", "quantity", "q", "q_ref", "error", "pareto", "reference", "newton_iterations",
           "increment_cuts", "steps", "total_s", "wall_s", "message"]


def write_csv(path, rows):
    def cell(v):
        return f"{v:.9g}" if isinstance(v, float) else ("" if v is None else v)
    with open(path, "w", newline="") as f:
        table = csv.writer(f)
        table.writerow(COLUMNS)
        table.writerows([cell(r.get(c)) for c in COLUMNS] for r in rows)


# ------------------------------------------------------------------------------------------
# Report

def kn(value):
    return f"{value / 1e3:.3f} kN"


def short(r):
    return f"Q{r['degree']} h = {r['h']:g} {r['increments']} inc. {'BE' if r['integrator'] == BE else 'adaptive'}"


def front_text(front):
    return " → ".join(f"{short(r)} ({r['time']:.3g} s, {r['error']:.1e})" for r in front)


def run_cells(r):
    if r["status"] != "ok":
        return [f"Q{r['degree']}", f"{r['h']:g}", str(r["increments"]), r["integrator"], "", "", "", "",
                f"failed: {r['message'][:100]}", ""]
    return [f"Q{r['degree']}", f"{r['h']:g}", str(r["increments"]), r["integrator"], str(r["cells"]),
            str(r["dofs"]), str(r["newton_iterations"]), str(r["increment_cuts"]), f"{r['time']:.3g}", str(r["runs"])]


def mark(r):
    return "reference" if r["reference"] else ("**P**" if r["pareto"] else "")


def resolution_bullet(ok, reference, quantity):
    """Which runs' errors lie below the reference's own uncertainty (not resolved)."""
    bound = reference["uncertainty"] / abs(reference["q_ref"])
    below = [r for r in ok if r["quantity"] == quantity and not r["reference"] and r["error"] < bound]
    text = f"* {quantity[0].upper() + quantity[1:]}: the reference is known to {bound:.1e}; "
    if not below:
        return text + "every error in the table is larger, so all are resolved."
    return (text + "errors below that are not resolved (their order among themselves is chance): "
            + ", ".join(f"{short(r)} ({r['error']:.1e})" for r in below) + ".")


def observations_cantilever(rows, reference):
    ok = [r for r in rows if r["scene"] == CANTILEVER and r["status"] == "ok"]
    lines = []
    rate_main = reference["rate"]
    text = f"* The error is the mesh's: Q2 converges at the observed rate h^{rate_main:.2f}"
    if reference.get("q1"):
        text += f", Q1 at h^{reference['q1']['rate']:.2f}"
    lines.append(text + " (the clamp's corners and the tip node's point load are singular, so neither "
                        "reaches its smooth-solution rate).")
    spreads = []
    for p in (1, 2):
        for h in sorted({r["h"] for r in ok if r["degree"] == p}):
            sel = [r for r in ok if r["degree"] == p and math.isclose(r["h"], h) and r["integrator"] == BE]
            if len(sel) > 1:
                qs = [r["q"] for r in sel]
                spreads.append((max(qs) - min(qs)) / reference["q_ref"])
    if spreads:
        errors = [r["error"] for r in ok if not r["reference"]]
        front = [r for r in ok if r["pareto"]]
        counts = sorted({r["increments"] for r in front})
        lines.append(f"* The number of increments hardly matters at the plateau: across "
                     f"{min(r['increments'] for r in ok)} to {max(r['increments'] for r in ok)} increments q "
                     f"changes by at most {max(spreads):.1e} (relative) at a fixed mesh and integrator, against "
                     f"mesh errors of {min(errors):.0e} to {max(errors):.0e}; the front holds runs with "
                     + ", ".join(map(str, counts)) + " increments.")
    pairs = []
    for r in ok:
        if r["degree"] == 1 and r["integrator"] == BE:
            twin = next((t for t in ok if t["degree"] == 2 and t["integrator"] == BE and t["increments"] == r["increments"]
                         and t["dofs"] == r["dofs"] and not t["reference"]), None)
            if twin:
                pairs.append((r, twin))
    if pairs:
        r, t = max(pairs, key=lambda pair: pair[0]["dofs"] * 1000 + pair[0]["increments"])
        lines.append(f"* At the same number of DoFs ({r['dofs']}) Q2 (h = {t['h']:g}) is {r['error'] / t['error']:.1f} "
                     f"times more accurate than Q1 (h = {r['h']:g}): {t['error']:.1e} against {r['error']:.1e}, "
                     f"in {t['time']:.3g} s against {r['time']:.3g} s ({r['increments']} increments).")
    for r in ok:
        if r["integrator"] == AD:
            twin = next((t for t in ok if t["integrator"] == BE and t["degree"] == r["degree"]
                         and math.isclose(t["h"], r["h"]) and t["increments"] == r["increments"]), None)
            if twin:
                lines.append(f"* `adaptive` (continuum tangent) at {short(r).replace(' adaptive', '')}: "
                             f"{r['newton_iterations']} Newton iterations and {r['increment_cuts']} cuts against "
                             f"{twin['newton_iterations']} and {twin['increment_cuts']} with backward Euler, "
                             f"{r['time'] / twin['time']:.1f} times the time; its q differs by "
                             f"{abs(r['q'] - twin['q']) / reference['q_ref']:.1e} (it integrates each increment to "
                             "its tolerance, backward Euler is first order in the increment), against an error of "
                             f"{twin['error']:.1e} of that mesh.")
    lines.append(resolution_bullet(ok, reference, TIP_LOAD))
    shipped = next((r for r in ok if r["degree"] == 2 and math.isclose(r["h"], 0.0125) and r["increments"] == 60
                    and r["integrator"] == BE), None)
    if shipped:
        lines.append(f"* The shipped scene (Q2, h = 0.0125, 60 increments) gives {kn(shipped['q'])}, "
                     f"{shipped['error']:.1e} above q_ref, in {shipped['time']:.3g} s; beam theory's P_u = "
                     f"{kn(P_U)} lies {abs(P_U - reference['q_ref']) / reference['q_ref']:.1%} below q_ref (it ignores "
                     "the clamp's restraint).")
    return lines


def observations_plate(rows, references):
    ok = [r for r in rows if r["scene"] == PLATE and r["status"] == "ok"]
    k, f = references[STIFFNESS], references[LOAD_4MM]
    lines = [f"* Initial stiffness: with an elastic first increment Q2 lies {k['floor']:+.1e} off K_ref at any h "
             f"(the 64-gon hole; {k['floor_setting']}); K0 errors below that floor come from a softer first "
             "increment cancelling it, not from convergence."]
    few = [r for r in ok if r["quantity"] == STIFFNESS and r["degree"] == 2 and math.isclose(r["h"], 0.05)
           and r["integrator"] == BE]
    if len(few) > 1:
        lo = min(few, key=lambda r: r["increments"])
        hi = max(few, key=lambda r: r["increments"])
        step = PLATE_DISPLACEMENT / lo["increments"]
        lines.append(f"* K0 is the secant of the first increment: with {lo['increments']} increments the first step is "
                     f"{step * 1e3:.2f} mm, {step / FIRST_YIELD_DISPLACEMENT:.0%} of the displacement of first yield at "
                     f"the ligament root ({FIRST_YIELD_DISPLACEMENT * 1e3:.3f} mm), where the smooth Bouc–Wen law already "
                     f"softens: Q2 h = 0.05 gives {lo['q'] / k['q_ref'] - 1:+.1e} with {lo['increments']} increments, "
                     f"{hi['q'] / k['q_ref'] - 1:+.1e} with {hi['increments']}.")
    q1 = sorted((r for r in ok if r["quantity"] == LOAD_4MM and r["degree"] == 1), key=lambda r: -r["h"])
    q2 = sorted((r for r in ok if r["quantity"] == LOAD_4MM and r["degree"] == 2 and r["increments"] == 20
                 and r["integrator"] == BE and not r["reference"]), key=lambda r: -r["h"])
    if q1 and q2:
        sign = ("overestimates" if all(r["q"] > f["q_ref"] for r in q1) else
                "underestimates" if all(r["q"] < f["q_ref"] for r in q1) else "misses")
        lines.append(f"* Load at 4 mm: Q1 {sign} it ("
                     + ", ".join(f"h = {r['h']:g}: {r['error']:.1e}" for r in q1)
                     + "), Q2 is within " + f"{max(r['error'] for r in q2):.1e} from h = {q2[0]['h']:g} on "
                     "(bilinear cells resolve the inclined plastic band poorly).")
    inc = sorted((r for r in ok if r["quantity"] == LOAD_4MM and r["degree"] == 2 and math.isclose(r["h"], 0.05)
                  and r["integrator"] == BE), key=lambda r: r["increments"])
    if len(inc) > 2:
        a, b, c = inc[-3:]
        order = math.log(abs((b["q"] - a["q"]) / (c["q"] - b["q"]))) / math.log(c["increments"] / b["increments"])
        lines.append(f"* The increments change the load at 4 mm by {abs(inc[-1]['q'] - inc[0]['q']) / f['q_ref']:.1e} "
                     f"from {inc[0]['increments']} to {inc[-1]['increments']} (observed order {order:.2f} in the "
                     f"increment over {a['increments']}, {b['increments']}, {c['increments']}: backward Euler) while "
                     f"the time grows {inc[-1]['time'] / inc[0]['time']:.1f}-fold.")
    for r in ok:
        if r["integrator"] == AD and r["quantity"] == LOAD_4MM:
            twin = next((t for t in ok if t["integrator"] == BE and t["degree"] == r["degree"] and t["quantity"] == LOAD_4MM
                         and math.isclose(t["h"], r["h"]) and t["increments"] == r["increments"]), None)
            if twin:
                k_twin = next(t for t in ok if t["setting"] == twin["setting"] and t["quantity"] == STIFFNESS)
                k_run = next(t for t in ok if t["setting"] == r["setting"] and t["quantity"] == STIFFNESS)
                lines.append(f"* `adaptive` (continuum tangent) at {short(r).replace(' adaptive', '')}: "
                             f"{r['newton_iterations']} Newton iterations and {r['increment_cuts']} increment cuts "
                             f"({r['steps']} steps) against {twin['newton_iterations']} and {twin['increment_cuts']} with "
                             f"backward Euler, {r['time'] / twin['time']:.1f} times the time; its load at 4 mm differs "
                             f"from backward Euler's by {abs(r['q'] - twin['q']) / f['q_ref']:.1e} and its K0 by "
                             f"{abs(k_run['q'] - k_twin['q']) / k['q_ref']:.1e}.")
    lines.append(resolution_bullet(ok, f, LOAD_4MM))
    shipped = next((r for r in ok if r["quantity"] == LOAD_4MM and r["degree"] == 2 and math.isclose(r["h"], 0.05)
                    and r["increments"] == 80 and r["integrator"] == BE), None)
    if shipped:
        lines.append(f"* The shipped scene (Q2, h = 0.05, 80 increments) takes {shipped['time']:.3g} s for a load "
                     f"error of {shipped['error']:.1e}.")
    return lines


def write_markdown(path, args, info, rows, references, fronts, defaults):
    build_type, dealii = bench.build_info(args.build)
    lines = ["# FEM with Bouc–Wen plasticity: error versus run time", ""]
    facts = [("Machine", f"{bench.machine()}; hysteron ran with CPU affinity {info['affinity']} "
                         f"(the script does not pin; pin it with taskset for stable times)"),
             ("Build", f"{build_type}, deal.II {dealii}, {args.build}, source {info['source']}"),
             ("Date", f"{info['date']}; the whole study took {info['elapsed'] / 60:.1f} min "
                      f"(1-minute load average {info['load_before']:.2f} before, {info['load_after']:.2f} after)"),
             ("Command", f"`{info['command']}`")]
    for name, text in facts:
        lines += [f"{name}: {text}.", ""]
    lines += [
        f"Time: the `steps` section of hysteron's timer table (set-up and output excluded), median of "
        f"{args.repeats} runs; a setting whose timed part exceeds {bench.LONG_RUN:.0f} s is run once (column "
        "`runs`). Error = |q − q_ref| / |q_ref|. **P** marks the Pareto front of a quantity (no other run is "
        "both faster and more accurate; the reference run is left out). Recommended default: the cheapest run "
        f"with error ≤ {TOLERANCE:g} in every quantity of the scene, among the runs on a Pareto front. Both scenes "
        "are quasi-static with `FEM/Degree`, `FEM/Mesh/Cell size`, `FEM/Number of increments` and "
        "`Material/Bouc-Wen/Integrator` replaced, no VTU output, the `# CHECK` lines dropped. Raw data: "
        "[fem_plastic_error_vs_time.csv](fem_plastic_error_vs_time.csv) (one row per run and quantity); "
        "the script's docstring describes every procedure.", "",
        "![error versus run time](fem_plastic_error_vs_time.png)", ""]

    c = references[TIP_LOAD]
    lines += [
        "## Plastic cantilever (§5.1)", "",
        "Scene: prm/fem_cantilever_plastic.prm (1 m × 0.1 m × 0.05 m, E = 210 GPa, σ_y = 240 MPa, "
        "elastic–perfectly plastic Bouc–Wen, plane stress, the tip node driven down to 30 mm). "
        "q = the tip load −tip_y in the last row of reactions.csv (30 mm, the collapse plateau; the value the "
        "scene's `CHECK-LAST` line tests, 30.97 kN shipped).", "",
        f"Reference: **q_ref = {kn(c['q_ref'])} ± {c['uncertainty']:.0f} N ({c['uncertainty'] / c['q_ref']:.1e})**: "
        f"Richardson extrapolation of Q2 at {c['increments']} increments from h = "
        + ", ".join(f"{h:g}: {kn(v)}" for h, v in zip(c["hs"], c["values"]))
        + f" (observed rate {c['rate']:.2f}) = {kn(c['limit'])}, plus the increment correction measured at "
        f"h = {c['inc_h']:g}, q({c['inc_n'][-1]} increments) − q({c['inc_n'][0]}) = {c['correction']:+.1f} N "
        "(backward Euler is first order in the increment; the h and increment errors are taken as additive). "
        "Uncertainty = max(a, b) + c: "
        + (f"(a) the same with h = {', '.join(f'{h:g}' for h in c['coarse']['hs'])}: {kn(c['coarse']['q_ref'])} "
           f"({c['u_coarse']:.1f} N); " if c.get("coarse") else "(a) not run; ")
        + (f"(b) the same construction with Q1 (h = {', '.join(f'{h:g}' for h in c['q1']['hs'])}, rate "
           f"{c['q1']['rate']:.2f}): {kn(c['q1']['q_ref'])} ({c['u_q1']:.1f} N); " if c.get("q1") else "(b) not run; ")
        + f"(c) the increment error left at {c['inc_n'][-1]} increments, q({c['inc_n'][-1]}) − q({c['inc_n'][1]}) = "
        f"{c['u_increments']:.1f} N. For scale: beam theory's plastic hinge P_u = σ_y b D²/(4L) = {kn(P_U)} "
        f"({(P_U - c['q_ref']) / c['q_ref']:+.1%}; it ignores the clamp's restraint). The tip is a "
        "single prescribed node, so q is the limit of this discretisation family, not of a continuum problem "
        "(a point load on a perfectly plastic body); over the meshes run the sequence is regular.", "",
        "| degree | h [m] | increments | integrator | cells | DoFs | Newton iterations | cuts | time [s] | runs | "
        "q [kN] | error | Pareto |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in (r for r in rows if r["scene"] == CANTILEVER):
        ok = r["status"] == "ok"
        lines.append("| " + " | ".join(run_cells(r) + ([f"{r['q'] / 1e3:.4f}", f"{r['error']:.2e}", mark(r)]
                                                       if ok else ["", "", ""])) + " |")
    lines += ["", f"Pareto front: {front_text(fronts.get(TIP_LOAD, []))}.", ""]
    lines += observations_cantilever(rows, c) + [""]

    k, f = references[STIFFNESS], references[LOAD_4MM]
    lines += [
        "## Perforated plate (§3.7.4)", "",
        "Scene: prm/fem_perforated_plate.prm (quarter model, aluminium, Bouc–Wen a = 0.002, plane stress, the top "
        "edge pulled to 4 mm; the 64-gon hole of `Curved boundary resolution = 0.0123` at every h). Quantities "
        "from reactions.csv: K0 = top_y / (4 mm · t) of the first increment, and the load top_y at 4 mm (t = 1).", "",
        f"Reference of K0: **K_ref = {k['q_ref'] / 1e6:.4f} MN/m**, the independent biquadratic solution with the "
        "exact circle (doc/scripts/perforated_plate_elastic_reference.py, 128 × 64 elements, converged to 2.5e-7; "
        "doc/verification/fem_perforated_plate.md §3); hysteron's polygonal hole keeps the FEM "
        f"{k['floor']:+.1e} above it ({k['floor_setting']}).", "",
        f"Reference of the load at 4 mm: **q_ref = {kn(f['q_ref'])} ± {f['uncertainty']:.0f} N "
        f"({f['uncertainty'] / f['q_ref']:.1e})**: Q2 at the finest mesh h = {f['h']:g}, {f['n']} increments, "
        f"{kn(f['fine'])}, plus the increment correction measured with Q{f['inc_degree']} at h = {f['inc_h']:g}, "
        f"q({f['inc_n'][-1]}) − "
        f"q({f['inc_n'][0]}) = {f['correction']:+.1f} N. Uncertainty: the last mesh change, q(h = {f['h']:g}) − "
        f"q(h = {f['coarse_h']:g}) = {f['u_h']:.1f} N, plus the increment error left at {f['inc_n'][-1]}, "
        f"q({f['inc_n'][-1]}) − q({f['inc_n'][1]}) = {f['u_increments']:.1f} N. For scale: the net-section limit "
        f"load σ_y A_net = 818.75 kN of the a = 0 material; q_ref is {f['q_ref'] / 818.75e3 - 1:+.1%} above it "
        "(the hardening a = 0.002 of the strongly strained band).", "",
        "| degree | h [m] | increments | integrator | cells | DoFs | Newton iterations | cuts | time [s] | runs | "
        "K0 [MN/m] | K0 error | Pareto (K0) | load at 4 mm [kN] | error | Pareto (load) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    runs_seen = []
    for r in (r for r in rows if r["scene"] == PLATE):
        if r["setting"] in runs_seen:
            continue
        runs_seen.append(r["setting"])
        pair = {x["quantity"]: x for x in rows if x["scene"] == PLATE and x["setting"] == r["setting"]}
        cells = run_cells(r)
        for quantity, scale in ((STIFFNESS, 1e6), (LOAD_4MM, 1e3)):
            x = pair[quantity]
            cells += ([f"{x['q'] / scale:.3f}", f"{x['error']:.2e}", mark(x)] if x["status"] == "ok" else ["", "", ""])
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", f"Pareto front, K0: {front_text(fronts.get(STIFFNESS, []))}.", "",
              f"Pareto front, load at 4 mm: {front_text(fronts.get(LOAD_4MM, []))}.", ""]
    lines += observations_plate(rows, references) + [""]

    lines += ["## Recommended defaults", "",
              f"Rule: the cheapest run whose errors are ≤ {TOLERANCE:g} in every quantity of the scene, among the "
              "runs on the Pareto front of at least one quantity.", ""]
    for scene, group in defaults.items():
        if not group:
            lines.append(f"* {scene}: no run meets the rule.")
            continue
        r = group[0]
        text = (f"* {scene}: **{r['setting']}** ({r['time']:.3g} s; "
                + ", ".join(f"{x['quantity']} error {x['error']:.1e}" for x in group) + ").")
        for quantity in QUANTITIES[scene]:
            front = fronts.get(quantity, [])
            cheapest = next((x for x in front if x["error"] <= TOLERANCE), None)
            cheaper = [x for x in front if x["time"] < (cheapest or r)["time"]]
            if len(QUANTITIES[scene]) > 1 and cheapest:
                text += f" For the {quantity} alone: {cheapest['setting']} ({cheapest['time']:.3g} s, {cheapest['error']:.1e})."
            if cheaper:
                miss, bound = cheaper[-1], references[quantity]["uncertainty"] / abs(references[quantity]["q_ref"])
                text += (f" The next cheaper run on the {quantity} front, {short(miss)}, has {miss['error']:.2e}"
                         + (f", within the reference's uncertainty ({bound:.1e}) of the bound: the choice between "
                            "the two is not resolved." if miss["error"] - bound <= TOLERANCE else "."))
        lines.append(text)
    lines.append("")
    with open(path, "w") as out:
        out.write("\n".join(lines))


# ------------------------------------------------------------------------------------------
# Figure

STYLE = {(1, BE): "s", (2, BE): "o", (1, AD): "v", (2, AD): "D"}
INCREMENT_COLOURS = {10: "tab:purple", 15: "tab:blue", 20: "tab:blue", 30: "tab:cyan", 40: "tab:cyan",
                     60: "tab:green", 80: "tab:green", 120: "tab:orange", 160: "tab:orange"}


def plot(path, rows, fronts, references, defaults):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.8))
    panels = ((axes[0], CANTILEVER, "plastic cantilever §5.1: tip load at 30 mm",
               f"|q − q_ref| / q_ref (q_ref = {references[TIP_LOAD]['q_ref'] / 1e3:.3f} kN, Q2 extrapolated)"),
              (axes[1], PLATE, "perforated plate §3.7.4: K0 (open) and load at 4 mm (filled)",
               f"|q − q_ref| / q_ref (K_ref = {references[STIFFNESS]['q_ref'] / 1e6:.2f} MN/m, "
               f"F_ref = {references[LOAD_4MM]['q_ref'] / 1e3:.2f} kN)"))
    for ax, scene, title, ylabel in panels:
        ok = [r for r in rows if r["scene"] == scene and r["status"] == "ok"]
        positive = [r["error"] for r in ok if r["error"] > 0]
        floor = 0.3 * min(positive) if positive else 1e-8
        seen = set()
        for r in ok:
            filled = r["quantity"] != STIFFNESS
            colour = INCREMENT_COLOURS.get(r["increments"], "0.4")
            key = (r["degree"], r["integrator"], r["increments"])
            name = None
            if filled and key not in seen:
                name = f"Q{r['degree']} {r['integrator']}, {r['increments']} inc."
                seen.add(key)
            ax.loglog(r["time"], max(r["error"], floor), STYLE[(r["degree"], r["integrator"])], color=colour,
                      mfc=colour if filled else "none", ms=7, alpha=0.5 if r["reference"] else 1, label=name)
            ax.annotate(f"{r['h']:g}" + (" (ref.)" if r["reference"] else ""), (r["time"], max(r["error"], floor)),
                        textcoords="offset points",
                        xytext=(5, 2), fontsize=5.5, color="0.35")
        for quantity, style in zip(QUANTITIES[scene], ("k--", "k:") if scene == PLATE else ("k--",)):
            front = fronts.get(quantity, [])
            if front:
                front_label = "Pareto front" + (f" ({'K0' if quantity == STIFFNESS else 'load'})" if scene == PLATE else "")
                ax.loglog([r["time"] for r in front], [max(r["error"], floor) for r in front], style, lw=1,
                          label=front_label)
        ax.axhline(TOLERANCE, color="tab:red", lw=0.8, ls="-.", label=f"error {TOLERANCE:g}")
        top = ax.get_ylim()[1]
        for quantity in QUANTITIES[scene]:
            reference = references[quantity]
            bound = reference["uncertainty"] / abs(reference["q_ref"])
            if bound > 0.1 * floor:
                ax.axhspan(1e-30, bound, color="0.85", alpha=0.5, lw=0,
                           label=f"below the reference's uncertainty ({quantity})")
                ax.set_ylim(min(floor, 0.5 * bound), top)
        if scene == PLATE:
            ax.axhline(abs(references[STIFFNESS]["floor"]), color="0.5", lw=0.8, ls=":",
                       label="K0 floor: 64-gon hole")
        chosen = defaults.get(scene)
        if chosen:
            for r in chosen:
                ax.loglog(r["time"], max(r["error"], floor), "*", color="gold", mec="k", ms=15, zorder=0)
            ax.plot([], [], "*", color="gold", mec="k", ms=12, label="recommended default")
        failed = [r for r in rows if r["scene"] == scene and r["status"] != "ok"]
        if failed:
            ax.text(0.02, 0.02, "failed: " + "; ".join(sorted({short(r) for r in failed})), transform=ax.transAxes,
                    fontsize=6.5, color="tab:red")
        ax.set_xlabel("run time of the steps [s]")
        ax.set_ylabel(ylabel, fontsize=8)
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=3)
    fig.suptitle("Quasi-static Bouc–Wen FEM: error versus run time (squares/triangles Q1, circles/diamonds Q2; "
                 "triangles/diamonds adaptive; labels: h [m]; colour: increments)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# ------------------------------------------------------------------------------------------

def source_state(build):
    """The commit of the build's source tree (CMAKE_HOME_DIRECTORY), and whether it is modified."""
    cache = open(os.path.join(build, "CMakeCache.txt")).read()
    home = re.search(r"CMAKE_HOME_DIRECTORY:INTERNAL=(.*)", cache)
    source = home.group(1).strip() if home else ROOT
    try:
        head = subprocess.check_output(["git", "-C", source, "rev-parse", "--short", "HEAD"], text=True).strip()
        dirty = subprocess.check_output(["git", "-C", source, "status", "--porcelain", "--untracked-files=no"],
                                        text=True).strip()
    except (OSError, subprocess.CalledProcessError):
        return f"{source} (not a git tree)"
    return f"{source} at {head}" + (" with uncommitted changes" if dirty else "")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build", help="the build directory of the hysteron executable")
    parser.add_argument("--repeats", type=int, default=3, help="runs per setting (the median time is kept)")
    parser.add_argument("--quick", action="store_true", help="a subset that runs in under a minute")
    parser.add_argument("--workdir", default="/tmp/fem_plastic_bench", help="where the runs are made")
    parser.add_argument("--out", help="where the tables and the figure go (doc/benchmarks; --quick: WORKDIR/quick)")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    args.workdir = os.path.abspath(args.workdir)
    hysteron = os.path.join(args.build, "hysteron")
    out = args.out or (os.path.join(args.workdir, "quick") if args.quick else os.path.join(ROOT, "doc", "benchmarks"))
    os.makedirs(out, exist_ok=True)
    affinity = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    info = dict(date=datetime.date.today().isoformat(), source=source_state(args.build),
                affinity="cores " + ", ".join(map(str, affinity)) if affinity else "unknown",
                load_before=os.getloadavg()[0],
                command="benchmarks/fem_plastic_error_vs_time.py " + " ".join(sys.argv[1:]))
    start = time.perf_counter()
    cantilever_file = os.path.join(ROOT, "prm", "fem_cantilever_plastic.prm")
    plate_file = os.path.join(ROOT, "prm", "fem_perforated_plate.prm")
    workdir = os.path.join(args.workdir, "quick_runs" if args.quick else "runs")
    cant_runs, cant_ref = study(CANTILEVER, cantilever_file, hysteron, workdir, args.repeats, args.quick)
    plate_runs, plate_ref = study(PLATE, plate_file, hysteron, workdir, args.repeats, args.quick)
    info["elapsed"], info["load_after"] = time.perf_counter() - start, os.getloadavg()[0]
    references = dict(cantilever_reference(cant_runs, cant_ref))
    references.update(plate_reference(plate_runs, plate_ref, plate_file))
    rows, fronts = make_rows(cant_runs + plate_runs, references)
    defaults = {scene: recommend(rows, scene) for scene in QUANTITIES}
    write_csv(os.path.join(out, "fem_plastic_error_vs_time.csv"), rows)
    write_markdown(os.path.join(out, "fem_plastic_error_vs_time.md"), args, info, rows, references, fronts, defaults)
    plot(os.path.join(out, "fem_plastic_error_vs_time.png"), rows, fronts, references, defaults)
    for scene, group in defaults.items():
        print(f"recommended default, {scene}: " + (group[0]["setting"] if group else "none"))
    print(f"wrote {out}/fem_plastic_error_vs_time.{{csv,md,png}}; study wall time {info['elapsed']:.0f} s")


if __name__ == "__main__":
    main()
