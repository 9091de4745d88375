#!/usr/bin/python3
"""Stability of the Bouc-Wen laws against the smoothness n (issue 7, stability suite).

For n in {1, 2, 8, 32, 100} and the integrators forward euler, adaptive (Tolerance 1e-6)
and backward euler, on three benches:

  uniaxial   the 1D law (`set Method = uniaxial`),
  ps         the triaxial law in plane stress, uniaxial stress by mixed control (to 1e-10
             E |eps|: the adaptive integrator's response is only piecewise smooth at the level
             of its sub-step decisions, and at the default 1e-12 the n = 100 reference stalled)
             (`set Method = material point`, Stress-free components = yy, xy),
  3d         the triaxial law in 3D, uniaxial stress (yy, zz, xy, yz, xz stress-free),

a triangular strain history eps_xx(t) of amplitude 5 eps_y, and

  np         the triaxial law in 3D under strain control along a non-proportional path,
             eps_xx = 5 eps_y sin(2 pi t), eps_xy = 2.5 eps_y (1 - cos(2 pi t)), other
             components zero (the same number of increments per cycle: 0.079 eps_y and
             0.79 eps_y in the (eps_xx, eps_xy) plane),

(20 cycles, E = 210 GPa,
sigma_y = 235 MPa, a = 0.02, beta = gamma = 0.5, kinematic hardening m = 0 for the
triaxial law so that the loops reach a steady state) is run with increments eps_y/20
(fine) and eps_y/2 (coarse). Measured per run, from history.csv:

  H1 - 1     max(H1) - 1 over the run (yield-surface drift; the exact law keeps H1 <= 1);
  balance    |W_ext - (W_stored + W_diss)| / W_ext, trapezoid rule along the path, where
             W_ext = int sigma : d eps. Uniaxial law: W_stored = a E eps^2/2 + (1-a) E z^2/2
             and W_diss = int (1-a) E z H1 H2 d eps, the dissipation of the rate law
             evaluated on the computed states (so the residual is the integration error of
             z plus the trapezoid error of W_diss). Triaxial law: W_stored =
             sigma : C^-1 : sigma / 2 + C_p eps_p : eps_p / 2 and W_diss =
             int (sigma - alpha) : d eps_p over the state columns; for this law the
             balance checks that stress and plastic strain are mutually consistent
             (sigma = D : (eps - eps_p) along the path);
  area       |A_last - A_ref| / A_ref: the dissipated energy of the last cycle (its loop
             area, closed trapezoid) against the converged solution of the same bench, n
             and increments (adaptive, Tolerance 1e-10), so that the quadrature error of
             the trapezoid rule cancels and the integration error remains; the converged
             areas themselves (eps_y/200) are listed against the bilinear limit;
  closure    max |sigma(last cycle) - sigma(previous cycle)| / sigma_y, row by row, over
             all stress components;
  time       wall time of the hysteron process (CSV output included), one run.

A run that fails must exit with status 2 and a message; the status and the message are
tabulated, and every history.csv is scanned for nan/inf.

Long runs (skipped with --quick): 10^6 updates of the uniaxial law (n = 8, adaptive and
backward euler) and of the plane-stress law (adaptive); the peaks of the last cycle are
compared with those of cycle 5.

Writes doc/stability/bouc_wen_results.md (tables), doc/stability/bouc_wen_*.png.
Usage: benchmarks/stability/bouc_wen_smoothness.py BUILD_DIR [--quick] [--output DIR]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
E, NU, SY, A = 210e9, 0.3, 235e6, 0.02
EY = SY / E
AMP = 5 * EY
HP = A * E / (1 - A)  # H' = a E / (1 - a)
CP = 2.0 / 3.0 * HP
NS = [1, 2, 8, 32, 100]
INTEGRATORS = ["forward euler", "adaptive", "backward euler"]
BENCHES = ["uniaxial", "ps", "3d", "np"]
BENCH_NAMES = {"uniaxial": "uniaxial law", "ps": "triaxial, plane stress",
               "3d": "triaxial, 3D", "np": "triaxial, 3D, non-proportional"}
COMPONENTS = ["xx", "yy", "zz", "xy", "yz", "xz"]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def scene(bench, n, integrator, tolerance, steps_per_cycle, cycles):
    """The .prm text: a triangular eps_xx history, amplitude AMP, period 1 s."""
    strain = f"{AMP!r}*2/pi*asin(sin(2*pi*t))"
    law = (f"    set Yield stress = {SY!r}\n    set Post-yield stiffness ratio = {A}\n"
           f"    set Smoothness n = {n}\n    set Beta = 0.5\n    set Gamma = 0.5\n"
           f"    set Integrator = {integrator}\n    set Tolerance = {tolerance}\n")
    steps = steps_per_cycle * cycles
    if bench == "uniaxial":
        return (f"set Dimension = 2\nset Method = uniaxial\nsubsection Material\n"
                f"  set Young's modulus = {E!r}\n  subsection Bouc-Wen\n{law}  end\nend\n"
                f"subsection Uniaxial\n  set Strain = {strain}\n  set End time = {cycles}\n"
                f"  set Steps = {steps}\nend\nsubsection Output\n  set Directory = out\nend\n")
    dim, free, state = (2, "yy, xy", "  set Stress state = plane stress\n") if bench == "ps" \
        else (3, "yy, zz, xy, yz, xz", "")
    if bench == "np":
        strain = (f"{AMP!r}*sin(2*pi*t)\n  set Strain xy = {0.5 * AMP!r}*(1 - cos(2*pi*t))")
        free = ""
    return (f"set Dimension = {dim}\nset Method = material point\nsubsection Material\n"
            f"  set Model = bouc-wen\n{state}  set Young's modulus = {E!r}\n"
            f"  set Poisson's ratio = {NU}\n  subsection Bouc-Wen\n{law}"
            f"    set Isotropic hardening fraction = 0\n  end\nend\n"
            f"subsection Material point\n  set Strain xx = {strain}\n"
            f"  set Mixed control tolerance = 1e-10\n"
            f"  set Stress-free components = {free}\n  set End time = {cycles}\n"
            f"  set Steps = {steps}\nend\nsubsection Output\n  set Directory = out\nend\n")


def read_csv(path):
    """Columns of a CSV file as a dict of lists (and whether a nan/inf was found)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    cols = {h: [float(r[j]) for r in data] for j, h in enumerate(header)}
    bad = any(not math.isfinite(v) for c in cols.values() for v in c)
    return cols, bad


def run(hysteron, bench, n, integrator, tolerance, steps_per_cycle, cycles, keep=None):
    """Run one scene; returns (status, message, columns or None, seconds, nonfinite)."""
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "s.prm"), "w") as f:
            f.write(scene(bench, n, integrator, tolerance, steps_per_cycle, cycles))
        t0 = time.perf_counter()
        try:
            p = subprocess.run([hysteron, "--quiet", "s.prm"], cwd=d, env=ENV,
                               capture_output=True, text=True, timeout=900)
            status, message = p.returncode, p.stderr.strip().splitlines()[-1:] or [""]
        except subprocess.TimeoutExpired:
            status, message = "timeout", ["killed after 900 s (hang?)"]
        seconds = time.perf_counter() - t0
        path = os.path.join(d, "out", "history.csv")
        cols, bad = (None, False)
        if os.path.exists(path):
            cols, bad = read_csv(path)
        return status, message[0], cols, seconds, bad


def stress_strain(cols, bench):
    """(strain tensors, stress tensors) per row as 6-lists, and the uniaxial stress."""
    if bench == "uniaxial":
        return [[e] for e in cols["eps"]], [[s] for s in cols["sig"]], cols["sig"]
    eps = list(zip(*[cols["eps_" + c] for c in COMPONENTS]))
    sig = list(zip(*[cols["sig_" + c] for c in COMPONENTS]))
    return eps, sig, cols["sig_xx"]


def double_dot(s, e):
    """s : e for 6-lists in tensor components (shear counted twice)."""
    return sum(s[k] * e[k] * (1 if k < 3 else 2) for k in range(len(s)))


def loop_area(eps, sig, first, last):
    """Closed trapezoid sum of sigma : d eps over rows first..last."""
    return sum(0.5 * double_dot([a + b for a, b in zip(sig[i], sig[i + 1])],
                                [b - a for a, b in zip(eps[i], eps[i + 1])])
               for i in range(first, last))


def balance(cols, bench):
    """|W_ext - W_stored - W_diss| / W_ext (see the module doc)."""
    eps, sig, _ = stress_strain(cols, bench)
    rows = len(eps)
    w_ext = loop_area(eps, sig, 0, rows - 1)
    if bench == "uniaxial":
        z, h1 = cols["z"], cols["H1"]
        w_diss = 0.0
        for i in range(rows - 1):
            de = eps[i + 1][0] - eps[i][0]
            g = [(1 - A) * E * z[j] * h1[j] * (0.5 + 0.5 * math.copysign(1, z[j] * de))
                 for j in (i, i + 1)]
            w_diss += 0.5 * (g[0] + g[1]) * de
        w_stored = 0.5 * A * E * eps[-1][0] ** 2 + 0.5 * (1 - A) * E * z[-1] ** 2
    else:
        comps = [c for c in COMPONENTS if "epsp_" + c in cols]
        idx = [COMPONENTS.index(c) for c in comps]
        ep = list(zip(*[cols["epsp_" + c] for c in comps]))
        w_diss = 0.0
        for i in range(rows - 1):
            s = [0.5 * (sig[i][k] + sig[i + 1][k]) - CP * 0.5 * (ep[i][j] + ep[i + 1][j])
                 for j, k in enumerate(idx)]
            d = [ep[i + 1][j] - ep[i][j] for j in range(len(idx))]
            w_diss += sum(s[j] * d[j] * (1 if idx[j] < 3 else 2) for j in range(len(idx)))
        s = sig[-1]
        tr = s[0] + s[1] + s[2]
        w_el = 0.5 * ((1 + NU) / E * double_dot(s, s) - NU / E * tr * tr)
        w_stored = w_el + 0.5 * CP * sum(ep[-1][j] ** 2 * (1 if idx[j] < 3 else 2)
                                         for j in range(len(idx)))
    return abs(w_ext - w_stored - w_diss) / abs(w_ext)


def per_cycle(cols, bench, spc):
    """Per cycle k >= 1: (max sigma, min sigma, closure to the previous cycle / sigma_y)."""
    _, sig, s = stress_strain(cols, bench)
    cycles = (len(s) - 1) // spc
    out = []
    for k in range(cycles):
        c = s[k * spc:(k + 1) * spc + 1]
        closure = (max(abs(x - y) for a, b in zip(sig[k * spc:(k + 1) * spc + 1],
                                                  sig[(k - 1) * spc:k * spc + 1])
                       for x, y in zip(a, b)) / SY if k > 0 else float("nan"))
        out.append((max(c), min(c), closure))
    return out


def fmt(x, digits=2):
    if isinstance(x, str):
        return x
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return f"{x:.{digits}e}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--quick", action="store_true", help="n = 8, 100; 6 cycles; no long runs")
    ap.add_argument("--output", default=os.path.join(ROOT, "doc", "stability"))
    args = ap.parse_args()
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    os.makedirs(args.output, exist_ok=True)
    ns = [8, 100] if args.quick else NS
    cycles = 6 if args.quick else 20
    increments = {"fine": 20, "coarse": 2}  # eps_y / k
    lines = [f"Machine: {os.uname().nodename}, {os.uname().machine}; hysteron at {hysteron}; "
             f"command: `{' '.join(sys.argv)}`", ""]

    # Converged loop areas: at eps_y/200 (the curve), and at each tested increment (the
    # same sample points as the runs, so that the trapezoid error cancels).
    references, floors = {}, {}
    for bench in BENCHES:
        for n in ns:
            for k in [200] + list(increments.values()):
                spc = 20 * k
                st, msg, cols, sec, bad = run(hysteron, bench, n, "adaptive", 1e-10, spc, 6)
                if st != 0:
                    sys.exit(f"reference {bench} n = {n} failed: {msg}")
                eps, sig, _ = stress_strain(cols, bench)
                references[bench, n, k] = loop_area(eps, sig, 5 * spc, 6 * spc)
                floors[bench, n, k] = balance(cols, bench)
            print(f"reference {bench} n={n}: loop area {references[bench, n, 200]:.9e} J/m^3",
                  flush=True)
    # Bilinear (n -> infinity) steady loop: a parallelogram with peaks
    # sigma_max = sigma_y + a E (AMP - eps_y) and the plastic strain range 2 (AMP - sigma_max/E).
    bilinear = 2 * SY * 2 * (AMP - (SY + A * E * (AMP - EY)) / E)
    lines.append(f"Converged loop area per cycle (adaptive, Tolerance 1e-10, eps_y/200; "
                 f"bilinear limit {bilinear:.6e} J/m^3):")
    lines.append("")
    lines.append("| n | " + " | ".join(BENCH_NAMES[b] for b in BENCHES) + " |")
    lines.append("|---:|" + "---:|" * len(BENCHES))
    for n in ns:
        lines.append(f"| {n} | " + " | ".join(f"{references[b, n, 200]:.6e}" for b in BENCHES)
                     + " |")
    lines.append("")
    lines.append("Balance residual of the converged solutions (6 cycles) at the tested "
                 "increments: the floor set by the trapezoid rule (fine / coarse):")
    lines.append("")
    lines.append("| n | " + " | ".join(BENCH_NAMES[b] for b in BENCHES) + " |")
    lines.append("|---:|" + "---:|" * len(BENCHES))
    for n in ns:
        lines.append(f"| {n} | " + " | ".join(
            " / ".join(fmt(floors[b, n, k]) for k in increments.values()) for b in BENCHES)
            + " |")
    lines.append("")

    results = {}
    for bench in BENCHES:
        for inc, k in increments.items():
            spc = 4 * 5 * k  # 4 AMP per cycle in steps of eps_y / k
            for integrator in INTEGRATORS:
                for n in ns:
                    st, msg, cols, sec, bad = run(hysteron, bench, n, integrator, 1e-6, spc,
                                                  cycles)
                    r = dict(status=st, message=msg, seconds=sec, nonfinite=bad)
                    if cols is not None and not bad and len(cols["t"]) == spc * cycles + 1:
                        eps, sig, _ = stress_strain(cols, bench)
                        pc = per_cycle(cols, bench, spc)
                        r.update(h1=max(cols["H1"]) - 1, balance=balance(cols, bench),
                                 area=abs(loop_area(eps, sig, (cycles - 1) * spc, cycles * spc)
                                          - references[bench, n, k]) / references[bench, n, k],
                                 closure=pc[-1][2], cycles=pc)
                    results[bench, inc, integrator, n] = r
                    print(f"{bench:8s} {inc:6s} {integrator:14s} n={n:3d}: status {st} "
                          f"{'NONFINITE ' if bad else ''}H1-1 {fmt(r.get('h1'))} balance "
                          f"{fmt(r.get('balance'))} area {fmt(r.get('area'))} closure "
                          f"{fmt(r.get('closure'))} {sec:.2f} s {msg if st else ''}",
                          flush=True)

    silent = [key for key, r in results.items() if r["nonfinite"]]
    lines.append(f"Runs: {len(results)}; history.csv with a nan/inf: {len(silent)} "
                 f"{silent if silent else ''}")
    lines.append("")
    for bench in BENCHES:
        for inc, k in increments.items():
            size = f"{20 * k} increments per cycle" if bench == "np" else f"increments eps_y/{k}"
            lines.append(f"### {BENCH_NAMES[bench]}, {size}, {cycles} cycles")
            lines.append("")
            lines.append("| integrator | n | status | max H1 − 1 | balance | area error | "
                         "closure / σ_y | time [s] |")
            lines.append("|---|---:|---|---:|---:|---:|---:|---:|")
            for integrator in INTEGRATORS:
                for n in ns:
                    r = results[bench, inc, integrator, n]
                    status = "ok" if r["status"] == 0 else \
                        f"exit {r['status']}: {r['message'][:110]}"
                    lines.append(f"| {integrator} | {n} | {status} | {fmt(r.get('h1'))} | "
                                 f"{fmt(r.get('balance'))} | {fmt(r.get('area'))} | "
                                 f"{fmt(r.get('closure'))} | {r['seconds']:.2f} |")
            lines.append("")

    long_runs = []
    if not args.quick:
        for bench, integrator in [("uniaxial", "adaptive"), ("uniaxial", "backward euler"),
                                  ("ps", "adaptive")]:
            spc, cyc = 400, 2500  # 10^6 updates at eps_y/20
            st, msg, cols, sec, bad = run(hysteron, bench, 8, integrator, 1e-6, spc, cyc)
            if st != 0 or bad:
                long_runs.append((bench, integrator, f"status {st} {msg}", sec))
                continue
            pc = per_cycle(cols, bench, spc)
            early, last = pc[4], pc[-1]
            long_runs.append((bench, integrator, early, last, sec, [c[2] for c in pc[1:]]))
            print(f"long {bench} {integrator}: cycle 5 peaks {early[0]!r} {early[1]!r}, last "
                  f"{last[0]!r} {last[1]!r}, max H1-1 {max(cols['H1']) - 1:.2e}, {sec:.1f} s",
                  flush=True)
            del cols
        lines.append("### Long runs: 10^6 updates (2500 cycles at eps_y/20), n = 8")
        lines.append("")
        lines.append("| bench | integrator | σ_max cycle 5 [Pa] | σ_max cycle 2500 − cycle 5 "
                     "[σ_y] | σ_min cycle 2500 − cycle 5 [σ_y] | last closure [σ_y] | "
                     "time [s] |")
        lines.append("|---|---|---:|---:|---:|---:|---:|")
        for r in long_runs:
            if len(r) == 4:
                lines.append(f"| {BENCH_NAMES[r[0]]} | {r[1]} | {r[2]} | | | | {r[3]:.1f} |")
            else:
                b, i, early, last, sec, _ = r
                lines.append(f"| {BENCH_NAMES[b]} | {i} | {early[0]:.10e} | "
                             f"{(last[0] - early[0]) / SY:.2e} | {(last[1] - early[1]) / SY:.2e}"
                             f" | {last[2]:.2e} | {sec:.1f} |")
        lines.append("")

    with open(os.path.join(args.output, "bouc_wen_results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    plot(args.output, results, long_runs, ns, increments)


def plot(output, results, long_runs, ns, increments):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    styles = {"forward euler": "o", "adaptive": "s", "backward euler": "^"}
    colors = {"forward euler": "C3", "adaptive": "C0", "backward euler": "C2"}
    fig, axes = plt.subplots(1, 4, figsize=(17, 4), sharey=True)
    for ax, bench in zip(axes, BENCHES):
        for inc, k in increments.items():
            for integrator in INTEGRATORS:
                pts = [(n, results[bench, inc, integrator, n].get("h1")) for n in ns]
                pts = [(n, max(h, 1e-16)) for n, h in pts if h is not None]
                if pts:
                    ax.loglog(*zip(*pts), styles[integrator], color=colors[integrator],
                              ls="-" if inc == "fine" else "--", mfc="none" if inc == "coarse"
                              else None, label=f"{integrator}, {20 * k} steps/cycle")
        ax.set_title(BENCH_NAMES[bench])
        ax.set_xlabel("smoothness n")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max(H1 − 1, 1e-16): overshoot of the yield surface")
    fig.suptitle("Yield-surface drift over 20 cycles of ±5 ε_y (Δε = ε_y/20: 400 steps/cycle, "
                 "ε_y/2: 40); a missing point: the run stopped with exit status 2", fontsize=9)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(output, "bouc_wen_h1_drift.png"), dpi=110)

    fig, axes = plt.subplots(1, 4, figsize=(17, 4), sharey=True)
    for ax, bench in zip(axes, BENCHES):
        for integrator in INTEGRATORS:
            for n in (8, 100):
                r = results.get((bench, "fine", integrator, n), {})
                if "cycles" in r:
                    c = [max(x[2], 1e-17) for x in r["cycles"][1:]]
                    ax.semilogy(range(2, len(c) + 2), c, styles[integrator],
                                color=colors[integrator], ls="-" if n == 8 else ":", ms=3,
                                mfc="none" if n == 100 else None,
                                label=f"{integrator}, n = {n}")
        ax.set_title(f"{BENCH_NAMES[bench]}, 400 steps/cycle")
        ax.set_xlabel("cycle k")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |σ_k − σ_{k−1}| / σ_y")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(output, "bouc_wen_loop_closure.png"), dpi=110)

    if any(len(r) == 6 for r in long_runs):
        fig, ax = plt.subplots(figsize=(6.5, 4))
        for r in long_runs:
            if len(r) == 6:
                c = [max(x, 1e-17) for x in r[5]]
                ax.semilogy(range(2, len(c) + 2), c, lw=0.8,
                            label=f"{BENCH_NAMES[r[0]]}, {r[1]}")
        ax.set_xlabel("cycle k (400 updates each)")
        ax.set_ylabel("max |σ_k − σ_{k−1}| / σ_y")
        ax.set_title("10^6 updates, n = 8, Δε = ε_y/20")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(output, "bouc_wen_long_runs.png"), dpi=110)


if __name__ == "__main__":
    main()
