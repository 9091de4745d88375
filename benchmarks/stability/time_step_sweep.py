#!/usr/bin/python3
"""Stability stress test (issue 7): sweep the fixed time step around the critical one.

Methods and scenes (all linear elastic unless stated; every scene is written by this script):

  MPM           the first axial mode of a fixed-free bar (tests/mpm/vibrating_bar.prm: E = 100 Pa,
                rho = 1, L = 1 m, h = 0.05 m, 2x2 points per cell, v0 = 0.1 sin(pi x / 2)),
                linear and cubic B-spline bases, MUSL and USF, FLIP. dt_crit = h / max_p(c_p + |v_p|)
                at t = 0 (eq. 4.47, what the code checks every step) = 0.05 / (10 + 0.0998) s.
  FEM explicit  the same bar (tests/fem/vibrating_bar_explicit.prm, Q1, lumped mass, central
                differences); dt_crit = 2 / omega_max as the code prints it ("critical step").
                Also a Bouc-Wen bar (sigma_y = 0.5 Pa, half of the elastic peak stress: the root
                yields), where no analytic solution exists.
  FEM implicit  the bar with Newmark average acceleration, dt in multiples of the explicit
                dt_crit up to 100 (unconditionally stable: the error grows, the energy does not).
  RBSN Newmark  one RBSN element (tests/rbsn/variable_order_elastic.prm: two cells of a steel
                plate, the left fixed, a sudden 1000 kN on the right one, no damping),
                u_x = P/k (1 - cos omega t). dt_crit = 2 / omega_max of the element's three
                free DoFs (u_x; v and theta coupled by the shear spring), computed here.
  RBSN IDA      the same element with `variable order` (SUNDIALS IDA): its `Maximum step` is
                swept instead (IDA chooses its own steps under error control).

Each explicit case runs twice: with the code's check (`Maximum CFL number` = 1, the default), and
with the check relaxed (`Maximum CFL number` = 100) to see what the scheme does physically above
the limit and how the run ends.

Recorded per run: outcome (completed / refused / stopped / timeout / crash), exit status, the
message, the energy balance error max|balance| / E_in (E_in = initial kinetic + strain energy +
max |external work| + max |boundary work|), the energy growth max(kinetic + strain) / E_in, the
tip amplitude and period errors against the analytic bar solution, the RBSN displacement error
against P/k (1 - cos omega t), the run time, and the sanity of the output: non-finite values
(nan, inf) in any CSV, repeated or decreasing times in energy.csv, *.tmp files left behind.

Writes (with --output PREFIX, default doc/stability/time_step): PREFIX_results.csv,
PREFIX_results.md (all tables), PREFIX_explicit.png and PREFIX_implicit.png.

Usage: benchmarks/stability/time_step_sweep.py BUILD_DIR [--quick] [--output PREFIX] [--replot]
       (--quick: fewer factors and cases, about a minute; the full sweep, 189 runs: ~3 min;
        --replot: redraw the figures from PREFIX_results.csv)
"""
import argparse
import csv
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FACTORS = [0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2]
RELAXED_EXTRA = [1.5, 2.0, 2.5, 3.0]          # the MPM stays stable above 1.2 h/c
IMPLICIT_FACTORS = FACTORS + [2.0, 5.0, 10.0, 30.0, 100.0]
QUICK_FACTORS = [0.5, 0.95, 1.05, 1.2]
QUICK_IMPLICIT = [0.5, 1.0, 10.0, 100.0]
TIMEOUT = 600

# ---------------------------------------------------------------- the bar (MPM, FEM)
BAR_E, BAR_RHO, BAR_L, BAR_V0 = 100.0, 1.0, 1.0, 0.1
BAR_C = math.sqrt(BAR_E / BAR_RHO)
BAR_OMEGA = math.pi * BAR_C / (2 * BAR_L)
BAR_T = 2 * math.pi / BAR_OMEGA            # 0.4 s
MPM_H = 0.05
MPM_XTIP = 0.9875                           # the point nearest the probe (1, 0.05)
MPM_DT_CRIT = MPM_H / (BAR_C + BAR_V0 * math.sin(math.pi / 2 * MPM_XTIP))

BAR_COMMON = """set Dimension = 2
set Method = {method}
set Body names = bar
set Boundary names = clamp
subsection Material
{material}
end
subsection Body bar
  set Shape = rectangle(0, 0, 1, 0.1)
  set Particles per cell = 2
  set Initial velocity = 0.1*sin(pi/2*x); 0
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
{method_section}
subsection Time
  set End time = {end}
  set Time step = {dt!r}
end
subsection Output
  set Probe interval = {probe}
  set Directory = output
  set Write VTU = false
  set Probe points = 1, 0.05
end
"""
ELASTIC = """  set Model = linear elastic
  set Young's modulus = 100
  set Poisson's ratio = 0
  set Density = 1
  set Stress state = plane stress"""
BOUC_WEN = """  set Model = bouc-wen
  set Young's modulus = 100
  set Poisson's ratio = 0
  set Density = 1
  set Stress state = plane stress
  subsection Bouc-Wen
    set Yield stress = 0.5
    set Post-yield stiffness ratio = 0.05
    set Smoothness n = 2
    set Beta = 0.5
    set Gamma = 0.5
  end"""


def mpm_scene(basis, scheme, dt, max_cfl, end=0.8):
    section = f"""subsection MPM
  subsection Grid
    set Lower corner = 0, 0
    set Upper corner = 1.2, 0.15
    set Cell size = 0.05
  end
  set Basis = {basis}
  set Scheme = {scheme}
  set Maximum CFL number = {max_cfl}
end"""
    return BAR_COMMON.format(method="mpm", material=ELASTIC, method_section=section, end=end,
                             dt=dt, probe=min(0.01, dt) if dt > 0 else 0.01)


def fem_scene(analysis, dt, max_cfl, material=ELASTIC, end=0.8, probe=0.004):
    section = f"""subsection FEM
  set Analysis = {analysis}
  set Maximum CFL number = {max_cfl}
  subsection Mesh
    set Cell size = 0.05
  end
end"""
    return BAR_COMMON.format(method="fem", material=material, method_section=section, end=end,
                             dt=dt, probe=probe).replace("  set Particles per cell = 2\n", "")


# ---------------------------------------------------------------- the RBSN element
RB_E, RB_NU, RB_RHO, RB_T = 210e9, 0.3, 7850.0, 0.02
RB_P = 1000e3
RB_KN = RB_T * 0.5 / (0.5 / (RB_E / (1 - RB_NU ** 2)))    # t l / (h / E'), 4.6154e9 N/m
RB_KT = RB_T * 0.5 / (0.5 / (RB_E / (2 * (1 + RB_NU))))   # t l / (h / G)
RB_KPHI = RB_KN * 0.5 ** 2 / 12
RB_M = RB_RHO * RB_T * 0.25                              # 39.25 kg
RB_I = RB_RHO * RB_T * 0.5 ** 4 / 6                      # polar moment of the 0.5 m square
RB_OMEGA = math.sqrt(RB_KN / RB_M)                       # the loaded (axial) mode
RB_STATIC = RB_P / RB_KN


def rbsn_omega_max():
    """Largest eigenfrequency of the free cell: u_x alone, and (v, theta) coupled through the
    shear spring at the facet midpoint 0.25 m from the nucleus (v_P = v - 0.25 theta)."""
    r = 0.25
    k11, k12, k22 = RB_KT, -r * RB_KT, r * r * RB_KT + RB_KPHI
    a, b, c = k11 / RB_M, k22 / RB_I, k12 / math.sqrt(RB_M * RB_I)  # M^-1/2 K M^-1/2
    lam = 0.5 * (a + b) + math.sqrt(0.25 * (a - b) ** 2 + c * c)
    return max(RB_OMEGA, math.sqrt(lam))


RB_DT_CRIT = 2 / rbsn_omega_max()

RBSN_SCENE = """set Dimension = 2
set Method = rbsn
set Body names = plate
set Boundary names = fix
set Load names = push
subsection Material
  set Model = linear elastic
  set Young's modulus = 210e9
  set Poisson's ratio = 0.3
  set Density = 7850
  set Stress state = plane stress
end
subsection Body plate
  set Shape = rectangle(0, 0, 1, 0.5)
  set Thickness = 0.02
end
subsection Boundary fix
  set Type = fixed
  set Region = disk(0.25, 0.25, 0.01)
end
subsection Load push
  set Type = force
  set Region = disk(0.75, 0.25, 0.01)
  set Value = 1000e3; 0
end
subsection RBSN
  set Analysis = {analysis}
  set Minimum distance = 1
  set Points on the boundary = false
  set Additional points = 0.25, 0.25; 0.75, 0.25
  set Time step = {dt!r}
  subsection Variable order
    set Relative tolerance = 1e-3
    set Maximum step = {max_step!r}
  end
end
subsection Time
  set End time = {end}
end
subsection Output
  set Directory = output
  set Probe points = 0.75, 0.25
  set Write VTU = false
end
"""


# ---------------------------------------------------------------- running and reading
def read_table(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    cols = {h: [] for h in header}
    for r in data:
        for h, x in zip(header, r):
            cols[h].append(float(x))
    return cols


def output_sanity(directory):
    """Non-finite values in any CSV, and *.tmp files left behind."""
    bad, tmp = [], []
    for root, _, files in os.walk(directory):
        for name in files:
            path = os.path.join(root, name)
            if name.endswith(".tmp"):
                tmp.append(name)
            if name.endswith(".csv"):
                with open(path) as f:
                    text = f.read().lower()
                if re.search(r"\bnan\b|\binf\b", text):
                    bad.append(name)
    return bad, tmp


def run_scene(hysteron, text):
    work = tempfile.mkdtemp(prefix="hysteron-dt-")
    try:
        with open(os.path.join(work, "scene.prm"), "w") as f:
            f.write(text)
        start = time.monotonic()
        try:
            p = subprocess.run([hysteron, "scene.prm"], cwd=work, capture_output=True, text=True,
                               timeout=TIMEOUT)
            code, out, err = p.returncode, p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            code, out, err = None, "", "timeout"
        wall = time.monotonic() - start
        res = {"exit": code, "wall": wall, "stdout": out}
        lines = [l for l in err.strip().splitlines() if l.strip()]
        res["message"] = lines[-1] if lines and code != 0 else ""
        m = re.search(r"critical step ([0-9.eE+-]+) s", out)
        res["printed_critical"] = float(m.group(1)) if m else None
        out_dir = os.path.join(work, "output")
        res["nonfinite"], res["tmp"] = output_sanity(out_dir) if os.path.isdir(out_dir) else ([], [])
        res["tables"] = {}
        for name in ("energy.csv", "probe_0.csv", "ida.csv"):
            path = os.path.join(out_dir, name)
            if os.path.exists(path):
                try:
                    res["tables"][name] = read_table(path)
                except (ValueError, IndexError):
                    res["tables"][name] = None
        if code is None:
            res["outcome"] = "timeout"
        elif code == 0:
            res["outcome"] = "completed"
        elif code in (1, 2):
            res["outcome"] = "refused" if "above the critical step" in err else "stopped"
        else:
            res["outcome"] = "crash"
        return res
    finally:
        shutil.rmtree(work, ignore_errors=True)


def energy_metrics(res):
    e = res["tables"].get("energy.csv")
    if not e or not e["time"]:
        return {}
    t = e["time"]
    e_in = e["kinetic"][0] + e["strain_energy"][0] + max(abs(x) for x in e["external_work"]) + \
        max(abs(x) for x in e["boundary_work"])
    e_in = e_in if e_in > 0 else float("nan")
    mech = [k + s for k, s in zip(e["kinetic"], e["strain_energy"])]
    return {
        "t_last": t[-1],
        "rows": len(t),
        "repeated_times": sum(1 for a, b in zip(t, t[1:]) if b <= a),
        "balance_error": max(abs(x) for x in e["balance"]) / e_in,
        "energy_growth": max(mech) / e_in,
    }


def crossings(t, u):
    return [t[i] - u[i] * (t[i + 1] - t[i]) / (u[i + 1] - u[i])
            for i in range(len(t) - 1) if u[i] * u[i + 1] < 0 and u[i + 1] != u[i]]


def bar_metrics(res, x_probe):
    p = res["tables"].get("probe_0.csv")
    if not p or len(p["time"]) < 3:
        return {}
    amp = BAR_V0 / BAR_OMEGA * math.sin(math.pi / 2 * x_probe)
    t, u = p["time"], p["u_x"]
    out = {"amplitude_error": max(abs(x) for x in u) / amp - 1}
    z = crossings(t, u)
    # The analytic zeros are at k T / 2; the 2nd one is one period.
    if len(z) >= 2 and t[-1] >= BAR_T * 0.99:
        out["period_error"] = z[1] / BAR_T - 1
    out["rms_error"] = math.sqrt(sum((ui - amp * math.sin(BAR_OMEGA * ti)) ** 2 for ti, ui in zip(t, u))
                                 / len(t)) / amp
    return out


def rbsn_metrics(res):
    p = res["tables"].get("probe_0.csv")
    if not p or len(p["time"]) < 2:
        return {}
    t, u = p["time"], p["u_x"]
    errors = [abs(ui - RB_STATIC * (1 - math.cos(RB_OMEGA * ti))) / RB_STATIC for ti, ui in zip(t, u)]
    out = {"displacement_error": max(errors), "peak_ratio": max(u) / RB_STATIC}
    # Over the first five periods only (the phase error accumulates over a long run and the
    # maximum saturates at 2); blank when the step does not resolve them.
    early = [e for ti, e in zip(t, errors) if 0 < ti <= 5 * 2 * math.pi / RB_OMEGA * (1 + 1e-9)]
    if len(early) >= 5:
        out["early_error"] = max(early)
    ida = res["tables"].get("ida.csv")
    if ida and ida.get("step"):
        out["ida_step"] = max(ida["step"]) / RB_DT_CRIT
        out["ida_steps"] = int(ida["steps"][-1])
    return out


# ---------------------------------------------------------------- the sweeps
def fem_critical(hysteron):
    res = run_scene(hysteron, fem_scene("explicit dynamics", 0, 1, end=0.01))
    if res["printed_critical"] is None:
        raise RuntimeError("the FEM did not print its critical step: " + res["message"])
    return res["printed_critical"]


def sweep(hysteron, quick):
    results = []
    f_explicit = QUICK_FACTORS if quick else FACTORS
    f_relaxed = QUICK_FACTORS + [2.0, 3.0] if quick else FACTORS + RELAXED_EXTRA
    f_implicit = QUICK_IMPLICIT if quick else IMPLICIT_FACTORS
    dt_fem = fem_critical(hysteron)
    print(f"critical steps: MPM h/(c + |v|) = {MPM_DT_CRIT:.6g} s, FEM 2/omega_max = {dt_fem:.6g} s, "
          f"RBSN element 2/omega_max = {RB_DT_CRIT:.6g} s (axial mode 2/omega = {2 / RB_OMEGA:.6g} s)",
          flush=True)

    def record(case, check, factor, dt_crit, res, extra):
        row = {"case": case, "check": check, "factor": factor, "dt": factor * dt_crit,
               "dt_crit": dt_crit, "outcome": res["outcome"], "exit": res["exit"],
               "message": res["message"], "wall": res["wall"],
               "nonfinite": " ".join(res["nonfinite"]), "tmp": " ".join(res["tmp"])}
        row.update(energy_metrics(res))
        if row["outcome"] == "refused" and row.get("t_last", 0) > 0:
            row["outcome"] = "stopped (check)"   # the MPM checks every step: |v_p| grew
        row.update(extra(res))
        results.append(row)
        print(f"  {case:24s} {check:8s} {factor:6.3g} {row['outcome']:9s} exit {row['exit']} "
              f"balance {row.get('balance_error', float('nan')):.3g} "
              f"growth {row.get('energy_growth', float('nan')):.3g} "
              f"{row['wall']:.2f} s {row['message'][:90]}", flush=True)

    mpm_cases = [("linear", "MUSL"), ("cubic B-spline", "MUSL"), ("linear", "USF"), ("cubic B-spline", "USF")]
    if quick:
        mpm_cases = [("linear", "MUSL"), ("cubic B-spline", "USF")]
    for basis, scheme in mpm_cases:
        case = f"MPM {'cubic' if basis.startswith('cubic') else 'linear'} {scheme}"
        for check, max_cfl, factors in (("default", 1, f_explicit), ("relaxed", 100, f_relaxed)):
            for f in factors:
                res = run_scene(hysteron, mpm_scene(basis, scheme, f * MPM_DT_CRIT, max_cfl))
                record(case, check, f, MPM_DT_CRIT, res, lambda r: bar_metrics(r, MPM_XTIP))

    fem_cases = [("FEM explicit", ELASTIC)] + ([] if quick else [("FEM explicit Bouc-Wen", BOUC_WEN)])
    for case, material in fem_cases:
        for check, max_cfl, factors in (("default", 1, f_explicit), ("relaxed", 100, f_relaxed)):
            for f in factors:
                res = run_scene(hysteron, fem_scene("explicit dynamics", f * dt_fem, max_cfl, material))
                record(case, check, f, dt_fem, res,
                       (lambda r: bar_metrics(r, 1.0)) if material == ELASTIC else (lambda r: {}))

    for f in f_implicit:
        dt = f * dt_fem
        res = run_scene(hysteron, fem_scene("implicit dynamics", dt, 1, end=2.0, probe=min(0.004, dt)))
        record("FEM Newmark", "-", f, dt_fem, res, lambda r: bar_metrics(r, 1.0))

    for f in f_implicit:
        dt = f * RB_DT_CRIT
        res = run_scene(hysteron, RBSN_SCENE.format(analysis="implicit dynamics", dt=dt, max_step=0.0,
                                                    end=0.1))
        record("RBSN Newmark", "-", f, RB_DT_CRIT, res, rbsn_metrics)
    for f in f_implicit:
        res = run_scene(hysteron, RBSN_SCENE.format(analysis="variable order", dt=1e-5,
                                                    max_step=f * RB_DT_CRIT, end=0.01))
        record("RBSN IDA (max step)", "-", f, RB_DT_CRIT, res, rbsn_metrics)
    return results, dt_fem


# ---------------------------------------------------------------- reports
COLUMNS = ["case", "check", "factor", "dt", "dt_crit", "outcome", "exit", "t_last", "rows",
           "balance_error", "energy_growth", "amplitude_error", "period_error", "rms_error",
           "displacement_error", "early_error", "peak_ratio", "ida_step", "ida_steps", "repeated_times", "nonfinite", "tmp", "wall", "message"]


def fmt(x, digits=3):
    if x is None or x == "":
        return ""
    if isinstance(x, float):
        if math.isnan(x):
            return "nan"
        return f"{x:.{digits}g}"
    return str(x)


def write_csv(path, results):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in results:
            w.writerow([r.get(c, "") for c in COLUMNS])


def write_markdown(path, results, dt_fem, command):
    lines = ["# Time-step sweep: all runs", "",
             f"Generated by `{command}` on {platform.node()} ({platform.processor() or platform.machine()}, "
             f"{os.cpu_count()} cores, Python {platform.python_version()}), "
             f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.", "",
             f"Critical steps: MPM h / max_p(c_p + |v_p|) = {MPM_DT_CRIT:.6g} s; FEM 2 / omega_max = "
             f"{dt_fem:.6g} s (printed by the code); RBSN element 2 / omega_max = {RB_DT_CRIT:.6g} s "
             f"(computed; the loaded axial mode alone: 2 / omega = {2 / RB_OMEGA:.6g} s).", "",
             "balance = max |balance| / E_in, growth = max(kinetic + strain) / E_in "
             "(E_in: initial energy + max |external| + max |boundary work|); amplitude, period, rms: "
             "relative errors of the tip displacement against the analytic bar mode; u error: "
             "max |u_x - P/k (1 - cos omega t)| / (P/k) over the run (saturates at 2 once the phase error "
             "reaches half a period) and over the first 5 periods (u error 5T); peak: max u_x / (P/k) (exact: 2). "
             "'non-finite' lists CSV files containing nan or inf.", ""]
    cases = []
    for r in results:
        if (r["case"], r["check"]) not in cases:
            cases.append((r["case"], r["check"]))
    for case, check in cases:
        rows = [r for r in results if r["case"] == case and r["check"] == check]
        title = case + ("" if check == "-" else f", Maximum CFL number {'= 1 (default)' if check == 'default' else '= 100 (relaxed)'}")
        lines += [f"## {title}", "",
                  "| dt/dt_crit | outcome | exit | t_end | balance | growth | amplitude | period | rms | u error | u error 5T | peak | IDA max step / dt_crit (steps) | non-finite | repeated t | time [s] | message |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            msg = r["message"].replace("|", "/")
            if len(msg) > 160:
                msg = msg[:160] + "..."
            lines.append("| " + " | ".join([
                fmt(r["factor"]), r["outcome"], fmt(r["exit"]), fmt(r.get("t_last")),
                fmt(r.get("balance_error")), fmt(r.get("energy_growth")), fmt(r.get("amplitude_error")),
                fmt(r.get("period_error")), fmt(r.get("rms_error")), fmt(r.get("displacement_error")),
                fmt(r.get("early_error")), fmt(r.get("peak_ratio")),
                (fmt(r.get("ida_step")) + f" ({r['ida_steps']})") if r.get("ida_step") is not None else "", r["nonfinite"] or "-", fmt(r.get("repeated_times")),
                fmt(r["wall"], 2), msg]) + " |")
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines))


def plot(prefix, results):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not available: no figures")
        return
    markers = {"completed": "o", "stopped": "X", "stopped (check)": "D", "refused": "s", "timeout": "v",
               "crash": "*"}
    explicit = [c for c in dict.fromkeys(r["case"] for r in results if r["check"] != "-")]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), sharey=True)
    lo, hi = 1e-5, 1e4   # refused runs are drawn at lo, values above hi at hi (triangles)
    for ax, check in zip(axes, ("default", "relaxed")):
        for i, case in enumerate(explicit):
            rows = [r for r in results if r["case"] == case and r["check"] == check]
            color = f"C{i}"
            ran = [r for r in rows if r["outcome"] != "refused" and r.get("balance_error") is not None]
            ax.plot([r["factor"] for r in ran], [min(max(r["balance_error"], lo), hi) for r in ran], "-",
                    color=color, lw=1, alpha=0.7, label=case)
            for r in rows:
                if r["outcome"] == "refused":
                    ax.plot(r["factor"], lo * (1.3 ** i), "s", color=color, ms=6, mfc="none")
                    continue
                if r.get("balance_error") is None:
                    continue
                y = r["balance_error"]
                marker = "^" if y > hi else markers.get(r["outcome"], "o")
                ax.plot(r["factor"], min(max(y, lo), hi), marker, color=color,
                        ms=8 if r["outcome"] != "completed" else 4)
        ax.set_ylim(lo / 2, hi * 3)
        ax.axvline(1.0, color="k", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("dt / dt_crit (the code's critical step)")
        ax.set_title("Maximum CFL number = 1 (default check)" if check == "default" else
                     "Maximum CFL number = 100 (check relaxed)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |energy balance| / energy put in")
    from matplotlib.lines import Line2D
    handles, labels = axes[0].get_legend_handles_labels()
    handles += [Line2D([], [], color="k", marker=m, ls="none", mfc="none" if k == "refused" else "k", label=k)
                for k, m in markers.items() if k in ("completed", "stopped", "stopped (check)", "refused")]
    handles.append(Line2D([], [], color="k", marker="^", ls="none", label=f"error > {hi:g} (clipped)"))
    axes[1].legend(handles=handles, fontsize=8, loc="upper left")
    fig.suptitle("Explicit methods: energy error against the fixed time step\n(refused: stopped at t = 0 "
                 "by the critical-step check; stopped: exit status 2 with a message during the run)", fontsize=10)
    fig.tight_layout()
    fig.savefig(prefix + "_explicit.png", dpi=110)
    plt.close(fig)

    implicit = [c for c in dict.fromkeys(r["case"] for r in results if r["check"] == "-")]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for i, case in enumerate(implicit):
        rows = [r for r in results if r["case"] == case and r.get("balance_error") is not None]
        axes[0].plot([r["factor"] for r in rows], [max(r["balance_error"], 1e-17) for r in rows], "o-",
                     color=f"C{i}", label=case)
        key = "rms_error" if case.startswith("FEM") else "early_error"
        rows = [r for r in results if r["case"] == case and r.get(key) is not None]
        axes[1].plot([r["factor"] for r in rows], [r[key] for r in rows], "o-", color=f"C{i}",
                     label=case + (" (RMS tip error / amplitude)" if key == "rms_error" else
                                   " (max |u - exact| / (P/k), first 5 periods)"))
    for ax in axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axvline(1.0, color="k", lw=0.8, ls="--")
        ax.set_xlabel("dt / dt_crit of the explicit scheme (IDA: Maximum step / dt_crit)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("max |energy balance| / energy put in")
    axes[1].set_ylabel("displacement error (bounded by 2 for a bounded solution)")
    fig.suptitle("Implicit methods: Newmark (average acceleration) and IDA beyond the explicit limit")
    fig.tight_layout()
    fig.savefig(prefix + "_implicit.png", dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build_dir")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--output", default=os.path.join(ROOT, "doc", "stability", "time_step"))
    ap.add_argument("--replot", action="store_true",
                    help="only redraw the figures from PREFIX_results.csv (no runs)")
    args = ap.parse_args()
    if args.replot:
        results = []
        with open(args.output + "_results.csv", newline="") as f:
            for r in csv.DictReader(f):
                row = {}
                for k, v in r.items():
                    if v == "" and k not in ("nonfinite", "tmp", "message"):
                        continue
                    try:
                        row[k] = v if k in ("case", "check", "outcome", "nonfinite", "tmp", "message") else float(v)
                    except ValueError:
                        row[k] = v
                results.append(row)
        plot(args.output, results)
        return
    hysteron = os.path.join(os.path.abspath(args.build_dir), "hysteron")
    if not os.access(hysteron, os.X_OK):
        sys.exit(f"no hysteron executable in {args.build_dir}")
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    command = "benchmarks/stability/time_step_sweep.py " + " ".join(sys.argv[1:])
    results, dt_fem = sweep(hysteron, args.quick)
    write_csv(args.output + "_results.csv", results)
    write_markdown(args.output + "_results.md", results, dt_fem, command)
    plot(args.output, results)
    bad = [r for r in results if r["nonfinite"] or r["tmp"] or r["outcome"] in ("timeout", "crash")
           or r.get("repeated_times")]
    print(f"{len(results)} runs; {len(bad)} with non-finite output, leftover files, repeated times, "
          f"a timeout or a crash")
    for r in bad:
        print(f"  {r['case']} {r['check']} {r['factor']}: {r['outcome']} nonfinite={r['nonfinite']} "
              f"tmp={r['tmp']} repeated={r.get('repeated_times')} {r['message'][:120]}")
    print("wrote " + ", ".join(args.output + s for s in ("_results.csv", "_results.md", "_explicit.png",
                                                       "_implicit.png")))


if __name__ == "__main__":
    main()
