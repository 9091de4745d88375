#!/usr/bin/python3
"""RBSN dynamics: Newmark versus the variable-order BDF of SUNDIALS IDA, error versus run time.

Scene: the dissertation's §3.6.1 single element (prm/rbsn_single_element_plasticity.prm: two cells
of a 1 m x 0.5 m S235 plate, t = 0.02 m, Bouc-Wen n = 8, beta = gamma = 0.5, a = 5 %,
P(t) = 2700 (t / T) sin(3 pi t) kN, T = 5 s), run dynamically (rho = 7850 kg/m^3), undamped and
with stiffness-proportional damping a1 = 1e-5 s (5 % of critical at the element's elastic
frequency, omega = 1.08e4 rad/s, which the undamped element keeps vibrating at):
- Newmark: Analysis = implicit dynamics (average acceleration, HHT alpha = 0), the springs'
  Bouc-Wen laws by backward Euler over each step (the consistent tangent), several Time steps;
- variable order: Analysis = variable order (IDA on u, v and the springs' z, error-controlled,
  orders 1..5), several Relative tolerances, the automatic absolute tolerance.
Both write the probe (the loaded cell) every 5 ms. Error = max over these 1001 rows of
|u_x - u_ref| / max |u_ref| (u_x the loaded cell's displacement), and the same for the normal
spring force f_n. Reference (per scenario): variable order with Relative tolerance =
REFERENCE_TOLERANCE; the finest Newmark runs converge to it (see the tables).

Time = the `steps` section of hysteron's timer table (set-up and output excluded), the median of
--repeats runs (one run if the first takes longer than 60 s).

Writes OUT/rbsn_newmark_vs_variable_order.{csv,md,png}, OUT = doc/benchmarks.

Usage: rbsn_newmark_vs_variable_order.py BUILD_DIR [--repeats 3] [--workdir /tmp/rbsn_ida_bench]
                                         [--out DIR] [--quick]
"""
import argparse
import csv
import datetime
import os
import pathlib
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "prm", "rbsn_single_element_plasticity.prm")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
OUTPUT_INTERVAL = 0.005
NEWMARK_STEPS = [1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5]
TOLERANCES = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
REFERENCE_TOLERANCE = 1e-10
LONG_RUN = 60


SCENARIOS = [("undamped", 0.0), ("damped", 1e-5)]


def scene_text(analysis, time_step, tolerance=None, damping=0.0):
    """The shipped scene without its assertions, dynamic, with the probe every 5 ms."""
    lines = [line for line in open(SCENE).read().splitlines() if not line.startswith("#")]
    text = "\n".join(lines) + "\n"
    rbsn = f"  set Analysis = {analysis}\n  set Time step = {time_step!r}\n"
    if damping > 0:
        rbsn += f"  subsection Dynamics\n    set Rayleigh stiffness coefficient = {damping!r}\n  end\n"
    if tolerance is not None:
        rbsn += f"  subsection Variable order\n    set Relative tolerance = {tolerance!r}\n  end\n"
    text = text.replace("  set Number of increments = 1000\n", rbsn)
    text = text.replace("  set Write VTU = false\n", f"  set Write VTU = false\n  set Probe interval = {OUTPUT_INTERVAL}\n")
    assert "set Analysis" in text and "Probe interval" in text
    return text


def timers(stdout):
    """Sections of hysteron's timer table {name: seconds}."""
    return {m.group(1): float(m.group(2)) for m in
            re.finditer(r"^\|\s*([^|]+?)\s*\|\s*\d+\s*\|\s*([0-9.e+-]+)s\s*\|", stdout, re.M)}


def read_probe(directory):
    with open(os.path.join(directory, "output", "probe_0.csv")) as f:
        rows = list(csv.DictReader(f))
    return [float(r["time"]) for r in rows], [float(r["u_x"]) for r in rows], [float(r["f_n"]) for r in rows]


def run(hysteron, text, directory, repeats):
    pathlib.Path(directory).mkdir(parents=True, exist_ok=True)
    pathlib.Path(directory, "scene.prm").write_text(text)
    times, steps = [], 0
    while len(times) < repeats and (not times or times[0] <= LONG_RUN):
        done = subprocess.run(["nice", hysteron, "scene.prm"], cwd=directory, env=ENV, capture_output=True,
                              text=True)
        if done.returncode:
            raise RuntimeError(f"{directory}: exit status {done.returncode}: {done.stderr.strip()[:300]}")
        times.append(timers(done.stdout)["steps"])
        found = re.search(r"\((?:\d+ cells, \d+ facets, )?(\d+) steps", done.stdout)
        steps = int(found.group(1)) if found else 0
    return statistics.median(times), len(times), steps


def errors(directory, reference):
    t, u, f = read_probe(directory)
    t_ref, u_ref, f_ref = reference
    assert len(t) == len(t_ref) and max(abs(a - b) for a, b in zip(t, t_ref)) < 1e-9, directory
    u_scale, f_scale = max(abs(x) for x in u_ref), max(abs(x) for x in f_ref)
    return (max(abs(a - b) for a, b in zip(u, u_ref)) / u_scale,
            max(abs(a - b) for a, b in zip(f, f_ref)) / f_scale)


def machine():
    cpu = open("/proc/cpuinfo").read()
    model = re.search(r"model name\s*:\s*(.*)", cpu)
    return f"{os.cpu_count()} cores, {model.group(1).strip() if model else 'unknown CPU'}"


def pareto(rows):
    best, front = float("inf"), []
    for r in sorted(rows, key=lambda r: (r["time"], r["error_u"])):
        if r["error_u"] < best:
            front.append(r)
            best = r["error_u"]
    return front


def sweep(hysteron, workdir, scenario, damping, steps_list, tolerances, repeats):
    """The reference and the runs of one scenario; rows with errors against the reference."""
    reference_dir = os.path.join(workdir, scenario, "reference")
    reference_time, _, reference_steps = run(
        hysteron, scene_text("variable order", OUTPUT_INTERVAL, REFERENCE_TOLERANCE, damping), reference_dir, 1)
    reference = read_probe(reference_dir)
    print(f"{scenario}: reference IDA rtol {REFERENCE_TOLERANCE:g}, {reference_steps} steps, {reference_time:.3f} s")
    rows = []
    for dt in steps_list:
        directory = os.path.join(workdir, scenario, f"newmark_{dt:g}")
        t, n, steps = run(hysteron, scene_text("implicit dynamics", dt, None, damping), directory, repeats)
        e_u, e_f = errors(directory, reference)
        rows.append(dict(scenario=scenario, method="Newmark", setting=dt, steps=steps, time=t, runs=n,
                         error_u=e_u, error_f=e_f))
        print(f"{scenario}: Newmark dt = {dt:g} s: {steps} steps, {t:.4f} s (x{n}), error u {e_u:.3e}, f_n {e_f:.3e}")
    for rtol in tolerances:
        directory = os.path.join(workdir, scenario, f"ida_{rtol:g}")
        t, n, steps = run(hysteron, scene_text("variable order", OUTPUT_INTERVAL, rtol, damping), directory,
                          repeats)
        e_u, e_f = errors(directory, reference)
        with open(os.path.join(directory, "output", "ida.csv")) as f:
            last = list(csv.DictReader(f))[-1]
        rows.append(dict(scenario=scenario, method="variable order", setting=rtol, steps=steps, time=t, runs=n,
                         error_u=e_u, error_f=e_f, residuals=int(float(last["residuals"])),
                         jacobians=int(float(last["jacobians"])),
                         error_test_failures=int(float(last["error_test_failures"])),
                         convergence_failures=int(float(last["convergence_failures"]))))
        print(f"{scenario}: IDA rtol = {rtol:g}: {steps} steps, {t:.4f} s (x{n}), error u {e_u:.3e}, f_n {e_f:.3e}")
    front = pareto(rows)
    for r in rows:
        r["pareto"] = r in front
    return rows, reference_steps


def at_error(method_rows, target):
    """The fastest run of the method whose u_x error is at most target."""
    ok = [r for r in method_rows if r["error_u"] <= target]
    return min(ok, key=lambda r: r["time"]) if ok else None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workdir", default="/tmp/rbsn_ida_bench")
    parser.add_argument("--out", default=os.path.join(ROOT, "doc", "benchmarks"))
    parser.add_argument("--quick", action="store_true", help="three settings per method, one run each")
    args = parser.parse_args()
    hysteron = os.path.join(args.build, "hysteron")
    steps_list, tolerances = NEWMARK_STEPS, TOLERANCES
    if args.quick:
        steps_list, tolerances, args.repeats = NEWMARK_STEPS[1:4], TOLERANCES[1:4], 1
    started, load_before = time.time(), os.getloadavg()[0]
    results = {}
    for scenario, damping in SCENARIOS:
        results[scenario] = sweep(hysteron, args.workdir, scenario, damping, steps_list, tolerances, args.repeats)
    load_after = os.getloadavg()[0]

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    name = "rbsn_newmark_vs_variable_order"
    columns = ["scenario", "method", "setting", "steps", "time", "runs", "error_u", "error_f", "residuals",
               "jacobians", "error_test_failures", "convergence_failures", "pareto"]
    with open(out / f"{name}.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for rows, _ in results.values():
            for r in rows:
                writer.writerow({c: (f"{r[c]:.6g}" if isinstance(r.get(c), float) else r.get(c, ""))
                                 for c in columns})

    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    md = ["# RBSN dynamics: Newmark versus variable order (SUNDIALS IDA)", "",
          f"Generated by `benchmarks/{name}.py` on {datetime.date.today()} ({machine()}, shared with other "
          f"jobs, runs under `nice`; build {args.build}, commit {commit}; load average {load_before:.2f} "
          f"before, {load_after:.2f} after; {time.time() - started:.0f} s).", "",
          "Scene: the §3.6.1 single element (`prm/rbsn_single_element_plasticity.prm`), dynamic (rho = 7850 "
          "kg/m^3), T = 5 s, undamped and with stiffness-proportional damping a1 = 1e-5 s (5 % of critical "
          "at the element's elastic frequency 1.08e4 rad/s), the probe every 5 ms (1001 rows). Error: the "
          "largest deviation over the rows from the reference, relative to the reference's largest value, "
          "of the loaded cell's displacement u_x and of the spring force f_n. Reference: variable order "
          f"with Relative tolerance = {REFERENCE_TOLERANCE:g}. Time: the `steps` section of hysteron's "
          f"timer (set-up and output excluded), median of {args.repeats} runs (one if longer than "
          f"{LONG_RUN} s). Newmark: average acceleration, the springs by backward Euler (Newton with the "
          "consistent tangent); variable order: the automatic absolute tolerance.", ""]
    for scenario, (rows, reference_steps) in results.items():
        md += [f"## {scenario} (reference: {reference_steps} IDA steps)", "",
               "| method | time step / rel. tolerance | steps | time [s] | error u_x | error f_n | residuals | "
               "Jacobians | error test / convergence failures | Pareto |",
               "|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            ida = r["method"] == "variable order"
            md.append(f"| {r['method']} | {r['setting']:g}{'' if ida else ' s'} | {r['steps']} | {r['time']:.4g} | "
                      f"{r['error_u']:.2e} | {r['error_f']:.2e} | {r.get('residuals', '')} | "
                      f"{r.get('jacobians', '')} | "
                      + (f"{r['error_test_failures']} / {r['convergence_failures']}" if ida else "") +
                      f" | {'yes' if r['pareto'] else ''} |")
        newmark = [r for r in rows if r["method"] == "Newmark"]
        ida_rows = [r for r in rows if r["method"] == "variable order"]
        md += ["", "Time to reach a displacement error (the fastest run at or below it):", "",
               "| error u_x <= | Newmark [s] | variable order [s] | speed-up |", "|---|---|---|---|"]
        for target in (1e-2, 1e-3, 1e-4, 1e-5):
            a, b = at_error(newmark, target), at_error(ida_rows, target)
            line = f"| {target:g} | " + (f"{a['time']:.4g} ({a['setting']:g} s)" if a else "-")
            line += " | " + (f"{b['time']:.4g} (rtol {b['setting']:g})" if b else "-")
            line += " | " + (f"{a['time'] / b['time']:.3g}" if a and b else "") + " |"
            md.append(line)
        md.append("")
    md += ["Notes:", "",
           "- Newmark converges at first order here (its error halves with the step): the springs' Bouc-Wen "
           "states are integrated by backward Euler over each step's deformation increment. IDA integrates "
           "them with the motion, at orders up to 5 under its error control.",
           "- Undamped, the element keeps vibrating at its elastic period of 0.58 ms (k_n = 4.6e9 N/m, "
           "m = 39 kg) with an amplitude of about 80 N (2e-8 m) that depends on the integrator (BDF damps "
           "it numerically at large steps, Newmark keeps it): below about 3e-5 (u_x) the errors measure this "
           "vibration, and IDA's steps grow sharply from rtol 1e-7, where it starts to resolve it. With 5 % "
           "damping at that frequency the solution is unique and both methods converge to the reference.",
           "- At some tolerances (damped: 1e-6, 1e-8) IDA fails many error tests and sets up its Jacobian "
           "at most steps (see the columns): the yield transitions of n = 8 switch z' sharply, and its step "
           "and order selection oscillates there; the cost stays far below Newmark's for the same error.",
           "- One cell pair: 6 DoFs (IDA: 12 + 3 spring states + 3 work quadratures), so the sparse "
           "direct solves cost little and the run times measure the per-step work of each integrator.", ""]
    (out / f"{name}.md").write_text("\n".join(md))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(11, 4.4), sharey=True)
    for ax, (scenario, (rows, _)) in zip(axes, results.items()):
        for method, marker, label in (("Newmark", "o-", "Newmark (time step [s])"),
                                      ("variable order", "s-", "variable order, IDA (rel. tolerance)")):
            method_rows = [r for r in rows if r["method"] == method]
            ax.loglog([r["time"] for r in method_rows], [r["error_u"] for r in method_rows], marker, label=label)
            for r in method_rows:
                ax.annotate(f"{r['setting']:g}", (r["time"], r["error_u"]), textcoords="offset points",
                            xytext=(4, 4), fontsize=7)
        ax.set_xlabel("run time of the steps [s]")
        ax.set_title(f"§3.6.1 single element, dynamic, {scenario}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |u_x - u_ref| / max |u_ref|")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / f"{name}.png", dpi=120)
    print(f"wrote {out / name}.{{csv,md,png}}")


if __name__ == "__main__":
    sys.exit(main())
