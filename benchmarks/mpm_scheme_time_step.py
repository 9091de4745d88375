#!/usr/bin/python3
"""MPM update scheme and time step: run time versus error of the explicit MPM on the vibrating
bar, across update scheme, basis, cell size, CFL factor and points per cell, with the Pareto front.

Scene: tests/mpm/vibrating_bar.prm (first axial mode of a bar fixed at x = 0 and free at
x = L = 1 m; E = 100 Pa, rho = 1 kg/m^3, nu = 0, plane stress, so c = 10 m/s; initial velocity
v0 sin(pi x / 2L), v0 = 0.1 m/s; FLIP, `MPM/FLIP fraction` = 1), its `# CHECK` and `# MPI`
lines dropped, run over 2 periods (End time = 2T = 0.8 s) with these entries replaced:
  `MPM/Scheme` in {MUSL, USL, USF}; `MPM/Basis` in {linear, cubic B-spline};
  `MPM/Grid/Cell size` h in {L/10, L/20, L/40, L/80}; the bar's height H = max(0.1 m, 2h), so
  that there are at least 2 cells across it (nu = 0: the mode does not depend on H), grid from
  (0, 0) to (1.2, H + h); `Time/CFL factor` in {0.1, 0.2, 0.4, 0.8, 1.0} (Delta t = CFL h /
  max_p(c_p + |v_p|), eq. 4.47), except CFL 0.1 at h = L/80 (2-6 s a run; the error does not
  change below CFL 0.2 there); `Body bar/Particles per cell` k = 2 (k x k points per cell), and
  k in {1, 3} for the cubic basis at CFL 0.8 (all schemes, h in {L/20, L/40, L/80});
  `Output/Probe interval` = 0.001 s, probe point (L, H/2), `Output/Write VTU` = false.
  Two settings with CFL factor 1.2 (above the allowed (0, 1]) show the refusal. 134 settings.
  --quick: h = L/20, CFL 0.8, the 6 scheme x basis pairs, cubic MUSL with 1x1, one refusal.
Error (analytic): the probe is the point nearest (L, H/2) at t = 0, at x0 = L - h/(2k); the exact
  solution there is u(x0, t) = A0 sin(omega t), A0 = v0/omega sin(pi x0 / 2L), omega = pi c / 2L
  (A0 -> 6.3662e-3 m at the tip). error = max over the probe rows (0 <= t <= 2T) of
  |u_x(t) - u(x0, t)| / A0. Also: period error T_num / T - 1 (T_num = the mean time between
  zero crossings of u_x in the same direction before 2T, linearly interpolated) and amplitude error
  (max u_x - min u_x) / (2 A0) - 1 (extremes refined by a parabola through the 3 samples); the
  offset of the mean position (max u_x + min u_x) / (2 A0) is listed too (column error_offset).
Energy: max over energy.csv of (kinetic + strain energy) / its initial value (no external work:
  1 for an exact scheme). A run above ENERGY_LIMIT = 1.1 has status "unstable" (hysteron itself
  exits with status 0) and is left out of the Pareto fronts.
Time: the `steps` section of hysteron's timer table (set-up and output excluded), the median of
  --repeats runs (a setting whose first run takes longer than 60 s is run once).
Failed runs (non-zero exit status: 1 bad input, e.g. a refused CFL factor; 2 run-time failure),
  runs without a usable probe table and runs killed after 600 s are recorded with the exit status
  and the first line of their message; the script never stops on them.
Pareto front: no other run is both at least as fast and more accurate (mark_pareto() of
  mpm_error_vs_time.py), over the stable runs. Recommended default per basis: the cheapest
  stable run of that basis with error <= 1e-2, which is the cheapest point of that basis's own
  Pareto front under 1e-2; also the cheapest one with CFL <= 0.8 (a margin below the limit 1).

Run the script pinned to one core (e.g. taskset -c 1); every hysteron inherits it.
Writes OUT/mpm_scheme_time_step.{csv,md,png}; OUT = doc/benchmarks (with --quick: WORKDIR/quick,
a subset that takes under a minute).

Usage: mpm_scheme_time_step.py BUILD_DIR [--repeats 3] [--quick] [--workdir /tmp/mpm_scheme_bench]
                               [--out DIR]
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
# The shared helpers (timer table, repeats, Pareto front, machine and build lines, .prm editing).
import mpm_error_vs_time as bench  # noqa: E402

ROOT = bench.ROOT
timers, repeat, mark_pareto = bench.timers, bench.repeat, bench.mark_pareto
machine, build_info, with_entry, first_line = bench.machine, bench.build_info, bench.with_entry, bench.first_line
ENV, LONG_RUN = bench.ENV, bench.LONG_RUN

SCENE = "tests/mpm/vibrating_bar.prm"
L, E, RHO, V0 = 1.0, 100.0, 1.0, 0.1
C = math.sqrt(E / RHO)                   # nu = 0, plane stress: the P-wave speed is sqrt(E / rho)
OMEGA = math.pi * C / (2 * L)
PERIOD = 2 * math.pi / OMEGA             # 0.4 s
END_TIME = 2 * PERIOD
PROBE_INTERVAL = 1e-3
TOLERANCE = 1e-2                         # error of the recommended default
ENERGY_LIMIT = 1.1                       # max (kinetic + strain energy) / initial energy of a stable run
TIMEOUT = 600                            # [s] per hysteron run
SCHEMES = ("MUSL", "USL", "USF")
BASES = ("linear", "cubic B-spline")
SHORT = {"linear": "linear", "cubic B-spline": "cubic"}


def settings(quick):
    """(scheme, basis, divisions n (h = L/n), CFL factor, points per cell k) of the study."""
    if quick:
        rows = [(s, b, 20, 0.8, 2) for b in BASES for s in SCHEMES]
        rows += [("MUSL", "cubic B-spline", 20, 0.8, 1), ("MUSL", "cubic B-spline", 20, 1.2, 2)]
        return rows
    # CFL 0.1 at L/80 is left out: 2-6 s per run, and the error no longer changes below CFL 0.2
    rows = [(s, b, n, cfl, 2) for b in BASES for s in SCHEMES for n in (10, 20, 40, 80)
            for cfl in (0.1, 0.2, 0.4, 0.8, 1.0) if (n, cfl) != (80, 0.1)]
    rows += [(s, "cubic B-spline", n, 0.8, k) for s in SCHEMES for n in (20, 40, 80) for k in (1, 3)]
    rows += [("MUSL", b, 20, 1.2, 2) for b in BASES]
    return sorted(rows, key=lambda r: (BASES.index(r[1]), SCHEMES.index(r[0]), r[2], r[4], r[3]))


def with_new_entry(text, section, entry, value):
    """with_entry(), or a new `set entry = value` right after `subsection section`."""
    try:
        return with_entry(text, section, entry, value)
    except KeyError:
        lines = text.splitlines()
        i = next(i for i, line in enumerate(lines) if line.strip() == f"subsection {section}")
        indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())] + "  "
        lines.insert(i + 1, f"{indent}set {entry} = {value}")
        return "\n".join(lines) + "\n"


def scene_text(base, scheme, basis, n, cfl, k):
    h = L / n
    height = max(0.1, 2 * h)
    text = "".join(line for line in base.splitlines(True)
                   if not line.lstrip().startswith(("# CHECK", "# MPI")))
    for section, entry, value in (
            ("Body bar", "Shape", f"rectangle(0, 0, {L:g}, {height:g})"),
            ("Body bar", "Particles per cell", str(k)),
            ("Grid", "Upper corner", f"1.2, {height + h:.6g}"),
            ("Grid", "Cell size", f"{h:.6g}"),
            ("MPM", "Basis", basis),
            ("MPM", "Scheme", scheme),
            ("MPM", "FLIP fraction", "1"),
            ("Time", "End time", f"{END_TIME:.6g}"),
            ("Time", "CFL factor", f"{cfl:g}"),
            ("Output", "Probe interval", f"{PROBE_INTERVAL:g}"),
            ("Output", "Interval", f"{END_TIME:.6g}"),
            ("Output", "Write VTU", "false"),
            ("Output", "Probe points", f"{L:g}, {height / 2:.6g}")):
        text = with_new_entry(text, section, entry, value)
    return text


def read_probe(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return ([float(r["time"]) for r in rows], [float(r["x_x"]) - float(r["u_x"]) for r in rows],
            [float(r["u_x"]) for r in rows])


def extreme(t, u, sign):
    """Largest sign*u, refined by a parabola through the sample and its two neighbours."""
    i = max(range(len(u)), key=lambda j: sign * u[j])
    if 0 < i < len(u) - 1:
        (t0, t1, t2), (u0, u1, u2) = t[i - 1:i + 2], u[i - 1:i + 2]
        # Lagrange parabola; its vertex
        d0, d2 = (u0 - u1) / (t0 - t1), (u2 - u1) / (t2 - t1)
        a = (d2 - d0) / (t2 - t0)
        if a != 0:
            b = d0 - a * (t0 - t1)  # slope at t1 of the parabola u1 + b (t - t1) + a (t - t1)^2
            tv = t1 - b / (2 * a)
            if t0 <= tv <= t2:
                return u1 + b * (tv - t1) + a * (tv - t1) ** 2
    return u[i]


def errors(probe_path):
    """(error, period error, amplitude error, offset, x0) of a probe table against the bar mode."""
    t, x, u = read_probe(probe_path)
    keep = [i for i in range(len(t)) if t[i] <= END_TIME * (1 + 1e-9)]
    t, u = [t[i] for i in keep], [u[i] for i in keep]
    values = u + t
    if not all(math.isfinite(v) for v in values):
        raise ValueError("non-finite value in the probe table")
    if t[-1] < END_TIME * (1 - 1e-3):
        raise ValueError(f"the probe table ends at t = {t[-1]:.4g} s, before 2T = {END_TIME:g} s")
    x0 = x[0]
    a0 = V0 / OMEGA * math.sin(math.pi * x0 / (2 * L))
    error = max(abs(ui - a0 * math.sin(OMEGA * ti)) for ti, ui in zip(t, u)) / a0
    crossings = [t[i] - u[i] * (t[i + 1] - t[i]) / (u[i + 1] - u[i])
                 for i in range(1, len(t) - 1) if u[i] * u[i + 1] < 0 or (u[i + 1] == 0 and u[i] != 0)]
    # mean time between crossings in the same direction (a shift of the mean position or of
    # every other crossing, as USF shows, does not bias it)
    full = [b - a for a, b in zip(crossings, crossings[2:])]
    period = sum(full) / len(full) if full else (2 * crossings[-1] if crossings else math.nan)
    top, bottom = extreme(t, u, 1), extreme(t, u, -1)
    return error, period / PERIOD - 1, (top - bottom) / (2 * a0) - 1, (top + bottom) / (2 * a0), x0


def energy(path):
    """max over the energy table of (kinetic + strain energy), relative to its value at t = 0
    (no external work: 1 for an exact scheme)."""
    with open(path) as f:
        rows = [float(r["kinetic"]) + float(r["strain_energy"]) for r in csv.DictReader(f)]
    return max(rows) / rows[0]


class RunFailed(Exception):
    def __init__(self, status, exit_status, message):
        super().__init__(message)
        self.status, self.exit_status, self.message = status, exit_status, message


def run_once(hysteron, text, directory):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    probe = os.path.join(directory, "output", "probe_0.csv")
    if os.path.exists(probe):
        os.remove(probe)
    start = time.perf_counter()
    try:
        p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=ENV, capture_output=True,
                           text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        raise RunFailed("timeout", "", f"no result after {TIMEOUT} s (killed)")
    wall = time.perf_counter() - start
    if p.returncode != 0:
        status = "refused" if p.returncode == 1 else "failed"
        raise RunFailed(status, p.returncode, first_line(p.stderr) or first_line(p.stdout))
    try:
        t = timers(p.stdout)
        steps = int(re.search(r"\((\d+) steps", p.stdout).group(1))
        points = int(re.search(r"mpm: (\d+) material points", p.stdout).group(1))
        error, error_period, error_amplitude, error_offset, x0 = errors(probe)
        energy_gain = energy(os.path.join(directory, "output", "energy.csv"))
    except Exception as exc:  # a run that finished without a usable output is recorded, too
        raise RunFailed("no result", 0, f"{type(exc).__name__}: {exc}")
    return dict(time=t["steps"], total_s=t.get("total", math.nan), wall_s=wall, steps=steps,
                points=points, error=error, error_period=error_period,
                error_amplitude=error_amplitude, error_offset=error_offset, probe_x=x0, energy_gain=energy_gain)


def label(scheme, basis, n, cfl, k):
    return f"{SHORT[basis]}, {scheme}, h = L/{n}, CFL {cfl:g}, {k}x{k}"


def study(hysteron, workdir, repeats, quick):
    base = open(os.path.join(ROOT, SCENE)).read()
    rows = []
    for scheme, basis, n, cfl, k in settings(quick):
        row = dict(scene="vibrating bar", method="MPM", setting=label(scheme, basis, n, cfl, k),
                   scheme=scheme, basis=basis, h=L / n, h_label=f"L/{n}", n=n, cfl=cfl, k=k,
                   height=max(0.1, 2 * L / n), status="ok", exit_status=0, message="")
        directory = os.path.join(workdir, f"{SHORT[basis]}_{scheme}_L-{n}_cfl{cfl:g}_k{k}")
        text = scene_text(base, scheme, basis, n, cfl, k)
        try:
            r = repeat(lambda: run_once(hysteron, text, directory), repeats, "time")
        except RunFailed as failure:
            row.update(status=failure.status, exit_status=failure.exit_status, message=failure.message)
            print(f"{row['setting']:45s} {failure.status.upper()} (exit status {failure.exit_status}): "
                  f"{failure.message}", flush=True)
            rows.append(row)
            continue
        row.update(r)
        row["runs"] = r["repeats"]
        if not r["energy_gain"] <= ENERGY_LIMIT:
            row.update(status="unstable", message=f"finished with exit status 0, but kinetic + strain energy "
                       f"reached {r['energy_gain']:.3g} times the initial energy")
        print(f"{row['setting']:45s} {r['points']:5d} points {r['steps']:6d} steps {r['time']:8.4f} s "
              f"(x{r['repeats']})  error {r['error']:.3e}  period {r['error_period']:+.2e}  "
              f"amplitude {r['error_amplitude']:+.2e}  energy x{r['energy_gain']:.3g}"
              + ("  UNSTABLE" if row["status"] == "unstable" else ""), flush=True)
        rows.append(row)
    return rows


def recommend(rows):
    """Per basis: its Pareto front (flag pareto_basis) and the cheapest run with error <= TOLERANCE;
    also the cheapest such run with CFL <= 0.8 (a margin below the largest allowed factor)."""
    chosen, margin = {}, {}
    for basis in BASES:
        front = mark_pareto([r for r in rows if r["basis"] == basis], "pareto_basis")
        fine = [r for r in front if r["error"] <= TOLERANCE]
        chosen[basis] = min(fine, key=lambda r: r["time"]) if fine else None
        if chosen[basis]:
            chosen[basis]["recommended"] = True
        safe = [r for r in rows if r["basis"] == basis and r["status"] == "ok" and r["cfl"] <= 0.8
                and r["error"] <= TOLERANCE]
        margin[basis] = min(safe, key=lambda r: r["time"]) if safe else None
    return chosen, margin


COLUMNS = ["scene", "method", "setting", "scheme", "basis", "h_label", "h", "height", "cfl", "k",
           "points", "steps", "status", "exit_status", "time", "total_s", "wall_s", "runs", "error",
           "error_period", "error_amplitude", "error_offset", "energy_gain", "probe_x", "pareto", "pareto_basis",
           "recommended", "message"]


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow({c: (f"{r[c]:.6g}" if isinstance(r.get(c), float) else r.get(c, ""))
                             for c in COLUMNS})


def pct(value):
    return f"{100 * value:+.2f} %"


def find(rows, status=("ok",), **keys):
    return next((r for r in rows if r["status"] in status and all(r[k] == v for k, v in keys.items())), None)


def crossing_fraction(n, k):
    """Share of the points whose analytic displacement amplitude A(x_p) exceeds their distance
    h/(2k) to the nearest cell face along x: they cross a cell face during the run."""
    h = L / n
    xs = [(i + 0.5) * h / k for i in range(n * k)]
    return sum(V0 / OMEGA * math.sin(math.pi * x / (2 * L)) > h / (2 * k) for x in xs) / len(xs)


def describe(r):
    if r is None:
        return "not run"
    if r["status"] in ("ok", "unstable"):
        text = f"{r['error']:.2e}"
        return text + (f" (unstable, energy ×{r['energy_gain']:.3g})" if r["status"] == "unstable" else "")
    return r["status"]


def findings(rows, front):
    """Bullets with the measured numbers."""
    done = [r for r in rows if r["status"] in ("ok", "unstable")]
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        return ["No run finished."]
    k2 = [r for r in rows if r["k"] == 2]
    ns = sorted({r["n"] for r in k2})
    cfls = sorted({r["cfl"] for r in k2 if r["cfl"] <= 1})
    bullets = []
    # 1. scheme and CFL factor: at the finest h where each scheme has all CFL factors
    for basis in BASES:
        parts = []
        for scheme in SCHEMES:
            for n in reversed(ns):
                sel = [find(k2, ("ok",), basis=basis, scheme=scheme, n=n, cfl=c) for c in cfls]
                if all(sel) and len(sel) > 1:
                    parts.append(f"{scheme} at h = L/{n}: error {sel[0]['error']:.2e} → {sel[-1]['error']:.2e}, "
                                 f"period error {pct(sel[0]['error_period'])} → {pct(sel[-1]['error_period'])}")
                    break
        if parts:
            bullets.append(f"**Scheme and CFL factor, {basis}** (CFL {cfls[0]:g} → {cfls[-1]:g}, 2x2 points per cell): "
                           + "; ".join(parts) + ".")
    # 2. cell size at CFL 0.8
    c_ref = 0.8 if 0.8 in cfls else cfls[-1]
    for basis in BASES:
        parts = []
        for scheme in SCHEMES:
            sel = [find(k2, ("ok", "unstable", "failed", "refused", "no result", "timeout"), basis=basis,
                        scheme=scheme, n=n, cfl=c_ref) for n in ns]
            parts.append(f"{scheme} " + " → ".join(describe(r) for r in sel))
        bullets.append(f"**Cell size, {basis}, CFL {c_ref:g}, h = " + " → ".join(f"L/{n}" for n in ns) + ":** "
                       + "; ".join(parts) + ".")
    cubic = [find(k2, basis="cubic B-spline", scheme="MUSL", n=n, cfl=c_ref) for n in ns]
    if all(cubic) and len(cubic) > 1:
        bullets.append(f"**Convergence, cubic MUSL, CFL {c_ref:g}, h = " + " → ".join(f"L/{n}" for n in ns)
                       + ":** period error " + " → ".join(pct(r["error_period"]) for r in cubic)
                       + ", amplitude error " + " → ".join(pct(r["error_amplitude"]) for r in cubic)
                       + ", offset " + " → ".join(pct(r["error_offset"]) for r in cubic)
                       + "; the phase error 4π·|period error| that a wrong period builds up over 2 periods is "
                       + " → ".join(f"{4 * math.pi * abs(r['error_period']) / r['error']:.2f}" for r in cubic)
                       + " of the max error, the rest is a distortion of the wave form that recurs every period. "
                       "Per halving of h the error falls ÷" + "/".join(f"{a['error'] / b['error']:.1f}" for a, b in zip(cubic, cubic[1:]))
                       + ".")
    # USF: an offset of the mean position of first order in the time step
    cub = [r for r in ok if r["basis"] == "cubic B-spline"]
    ratios = sorted(r["error_offset"] / (-OMEGA * END_TIME / r["steps"]) for r in cub if r["scheme"] == "USF")
    others = [abs(r["error_offset"]) for r in cub if r["scheme"] != "USF"]
    if ratios:
        bullets.append("**USF's error is an offset of the mean position, not a period error:** the tip oscillates "
                       "about −Δt · v0(x0) instead of 0, i.e. offset / A0 = −ω Δt × "
                       f"{ratios[len(ratios) // 2]:.2f} (median over the {len(ratios)} cubic USF runs, range "
                       f"{ratios[0]:.2f} … {ratios[-1]:.2f}; Δt = 0.8 s / steps)"
                       + (f", while cubic MUSL and USL stay within {100 * max(others):.2f} %" if others else "")
                       + ". Its first step updates the stress with the initial velocity before any point has "
                       "moved, and the positions never catch up: a permanent strain Δt ∇v0. So USF's error grows "
                       "with the CFL factor at every h; at CFL 0.1–0.2 on fine grids the offset is small and USF "
                       "is as accurate as MUSL or better (it partly cancels the space error).")
    # 3. linear basis: cell crossing
    fractions = ", ".join(f"L/{n}: {100 * crossing_fraction(n, 2):.0f} %" for n in ns)
    bullets.append("**Linear basis and cell crossing.** The share of the points whose displacement amplitude "
                   f"exceeds their distance h/(2k) to the next cell face (2x2 per cell) is {fractions}. Without "
                   "crossings the linear basis is as accurate as the cubic one (it is then the linear FEM with a lumped "
                   "mass); once points cross, a node beyond the moving tip gets a small mass and the "
                   "gradient of the hat function jumps, the error grows as h shrinks, and at large CFL factors the "
                   "runs gain energy (the time step bound h / max(c + |v|) does not cover nodes of small mass).")
    # 4. points per cell
    ks = sorted({r["k"] for r in ok})
    if len(ks) > 1:
        parts = []
        for scheme in SCHEMES:
            n = max(n for n in ns if all(find(ok, basis="cubic B-spline", scheme=scheme, n=n, cfl=c_ref, k=k) for k in ks)) \
                if any(all(find(ok, basis="cubic B-spline", scheme=scheme, n=n, cfl=c_ref, k=k) for k in ks) for n in ns) else None
            if n:
                sel = [find(ok, basis="cubic B-spline", scheme=scheme, n=n, cfl=c_ref, k=k) for k in ks]
                parts.append(f"{scheme} h = L/{n}: " + ", ".join(f"{k}x{k} {s['error']:.2e} ({s['time']:.3f} s)"
                                                               for k, s in zip(ks, sel)))
        if parts:
            bullets.append(f"**Points per cell, cubic, CFL {c_ref:g}:** " + "; ".join(parts)
                           + ". The smooth mode needs no more than one point per cell; the time grows with k².")
    # 5. cost
    for basis in BASES:
        r = max((r for r in k2 if r["basis"] == basis and r["status"] == "ok"),
                key=lambda r: r["points"] * r["steps"], default=None)
        if r:
            bullets.append(f"**Cost, {basis}:** {1e6 * r['time'] / (r['points'] * r['steps']):.2f} µs per point and step "
                           f"({r['setting']}: {r['points']} points, {r['steps']} steps, {r['time']:.3f} s). The time "
                           "goes as 1/CFL and, once H = 0.1 m holds several cells, as 1/h³ (1/h² points, 1/h steps).")
    # 6. front
    if front:
        kinds = sorted({(r["basis"], r["scheme"]) for r in front}, key=lambda s: (BASES.index(s[0]), SCHEMES.index(s[1])))
        bullets.append(f"**Pareto front:** {len(front)} runs, from {front[0]['setting']} ({front[0]['time']:.4f} s, "
                       f"error {front[0]['error']:.2e}) to {front[-1]['setting']} ({front[-1]['time']:.3f} s, "
                       f"error {front[-1]['error']:.2e}); made of "
                       + ", ".join(f"{SHORT[b]} {s}" for b, s in kinds) + " runs.")
    # 7. failures and instabilities
    unstable = [r for r in rows if r["status"] == "unstable"]
    failed = [r for r in rows if r["status"] not in ("ok", "unstable", "refused")]
    refused = [r for r in rows if r["status"] == "refused"]
    if unstable:
        bullets.append(f"**Unstable but exit status 0** ({len(unstable)} runs; kinetic + strain energy above "
                       f"{ENERGY_LIMIT:g} times the initial energy, so left out of the fronts): "
                       + "; ".join(f"{r['setting']} (×{r['energy_gain']:.3g}, error {r['error']:.2g})" for r in unstable)
                       + ". hysteron's MPM stops a run when the kinetic energy plus the internal work exceeds "
                       "twice the energy put in (as the explicit FEM does); a slower growth like this one ends "
                       "with exit status 0 and shows in energy.csv's balance.")
    if failed:
        bullets.append(f"**Stopped with exit status 2** ({len(failed)} runs): "
                       + "; ".join(f"{r['setting']}" for r in failed)
                       + (f". Message, e.g.: \"{failed[0]['message']}\"" if failed else "") + ".")
    if refused:
        bullets.append("**Refused** (exit status 1, before the first step): "
                       + "; ".join(f"{r['setting']}: \"{r['message']}\"" for r in refused) + ".")
    cubic_bad = [r for r in rows if r["basis"] == "cubic B-spline" and r["status"] != "ok" and r["cfl"] <= 1]
    if not cubic_bad and any(r["basis"] == "cubic B-spline" for r in done):
        worst = max((r for r in done if r["basis"] == "cubic B-spline"), key=lambda r: r["energy_gain"])
        bullets.append(f"**Every cubic run with CFL ≤ 1 is stable** (largest energy ratio {worst['energy_gain']:.4f}, "
                       f"{worst['setting']}).")
    return bullets


def write_markdown(path, args, rows, front, chosen, margin, elapsed):
    build_type, dealii = build_info(args.build)
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    source = (head.stdout.strip() or "unknown") + (" with uncommitted changes" if dirty else "")
    command = "benchmarks/mpm_scheme_time_step.py " + " ".join(sys.argv[1:])
    lines = [
        "# MPM: update scheme and time step versus error and run time (vibrating bar)", "",
        f"Machine: {machine()}; run pinned to one core (taskset); {build_type} build, deal.II {dealii}, "
        f"`{args.build}/hysteron`; source tree at {source}; {datetime.date.today().isoformat()}; "
        f"total benchmark wall time {elapsed / 60:.1f} min ({len(rows)} settings).", "",
        f"Command: `{command}`", "",
        f"Scene: [{SCENE}](../../{SCENE}), the first axial mode of a bar fixed at x = 0 and free at "
        "x = L = 1 m (E = 100 Pa, ρ = 1 kg/m³, ν = 0, plane stress: c = 10 m/s, ω = πc/2L, "
        "T = 0.4 s; v(x, 0) = 0.1 sin(πx/2L) m/s), FLIP (`FLIP fraction` = 1), 2 periods "
        "(End time 0.8 s). Replaced: `MPM/Scheme`, `MPM/Basis`, `MPM/Grid/Cell size` h, the bar "
        "height H = max(0.1 m, 2h) (at least 2 cells across; with ν = 0 the mode does not depend "
        "on H) and the grid (0, 0)–(1.2, H + h), `Time/CFL factor` (Δt = CFL · h / max_p(c_p + |v_p|), "
        "recomputed every step), `Particles per cell` k (k×k points per cell), probe every 1 ms at "
        "the point nearest (L, H/2), no VTU.", "",
        "**Error** (against the analytic solution u(x, t) = v0/ω sin(πx/2L) sin(ωt)): the probe "
        "point starts at x0 = L − h/(2k); with A0 = v0/ω sin(πx0/2L) (6.3662e-3 m at the tip), "
        "error = max over the probe rows, 0 ≤ t ≤ 2T, of |u_x(t) − A0 sin(ωt)| / A0. **Period "
        "error** T_num/T − 1, T_num = the mean time between zero crossings of u_x in the same "
        "direction before 2T (linear interpolation). **Amplitude error** (max u_x − min u_x)/(2 A0) − 1 (extremes "
        "refined by a parabola); **offset** (max u_x + min u_x)/(2 A0), the shift of the mean position. **Energy** = max over energy.csv of (kinetic + strain energy) / its "
        f"initial value (no external work: 1 when exact); a run above {ENERGY_LIMIT:g} is marked "
        "*unstable* and left out of the fronts even though hysteron exits with status 0. **Time**: "
        "the `steps` section of hysteron's timer table (set-up and output excluded), median of "
        f"{args.repeats} runs; settings whose first run exceeds {LONG_RUN:.0f} s run once (column "
        "`runs`). **P** marks the Pareto front over all stable runs (no other run is both at least "
        "as fast and more accurate), **b** the front of the run's basis. Failed (exit status 2) and "
        "refused (exit status 1) runs are listed with the first line of their message. Raw data: "
        "[mpm_scheme_time_step.csv](mpm_scheme_time_step.csv).", "",
        "![error versus run time](mpm_scheme_time_step.png)", "",
        "## Recommended defaults", "",
        f"Rule: for each basis, the cheapest stable run (smallest `steps` time) with error ≤ {TOLERANCE:g}; "
        "it is the cheapest point of that basis's own Pareto front (**b**) under the tolerance. The "
        "times of the cheapest runs are a few milliseconds, so the choice between neighbours of similar "
        "cost is within the timing noise; the second line gives the cheapest such run with CFL ≤ 0.8, a "
        "margin below the largest accepted CFL factor.", ""]
    for basis in BASES:
        for title, r in (("", chosen.get(basis)), (" with CFL ≤ 0.8", margin.get(basis))):
            if r is None:
                lines.append(f"* **{basis}{title}**: no stable run reaches error ≤ {TOLERANCE:g}.")
                continue
            if title and r is chosen.get(basis):
                continue
            lines.append(f"* **{basis}{title}**: {r['scheme']}, h = {r['h_label']}, CFL factor {r['cfl']:g}, "
                         f"{r['k']}x{r['k']} points per cell: error {r['error']:.2e} (period "
                         f"{pct(r['error_period'])}, amplitude {pct(r['error_amplitude'])}), "
                         f"{r['time']:.4f} s for {r['steps']} steps of {r['points']} points"
                         + (" (on the overall Pareto front)." if r.get("pareto") else "."))
    lines += ["", "## What the numbers show", ""]
    lines += [f"* {b}" for b in findings(rows, front)]
    cfls = sorted({r["cfl"] for r in rows if r["k"] == 2})
    lines += ["", "## Error at 2x2 points per cell (rows: basis, scheme, h; columns: CFL factor)", "",
              "| basis | scheme | h | " + " | ".join(f"CFL {c:g}" for c in cfls) + " |",
              "|---|---|---|" + "---|" * len(cfls)]
    for basis in BASES:
        for scheme in SCHEMES:
            for n in sorted({r["n"] for r in rows}):
                cells = []
                for c in cfls:
                    r = next((r for r in rows if (r["basis"], r["scheme"], r["n"], r["cfl"], r["k"]) ==
                              (basis, scheme, n, c, 2)), None)
                    cells.append("" if r is None else describe(r).replace("(unstable, energy", "(unstable,"))
                if any(cells):
                    lines.append(f"| {SHORT[basis]} | {scheme} | L/{n} | " + " | ".join(cells) + " |")
    lines += ["", "## All runs", "",
              "| setting | points | steps | time [s] | error | period error | amplitude error | offset | "
              "energy | runs | status | Pareto |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] not in ("ok", "unstable"):
            lines.append(f"| {r['setting']} | | | | | | | | | | {r['status']}, exit status {r['exit_status']}: "
                         f"{r['message']} | |")
            continue
        mark = " ".join(m for m, key in (("**P**", "pareto"), ("**b**", "pareto_basis"),
                                          ("recommended", "recommended")) if r.get(key))
        lines.append(f"| {r['setting']} | {r['points']} | {r['steps']} | {r['time']:.4f} | {r['error']:.3e} | "
                     f"{pct(r['error_period'])} | {pct(r['error_amplitude'])} | {pct(r['error_offset'])} | {r['energy_gain']:.4g} | "
                     f"{r['runs']} | {r['status']} | {mark} |")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(path, rows, front, chosen):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    markers = {"MUSL": "o", "USL": "s", "USF": "^"}
    colours = {("linear", "MUSL"): "tab:blue", ("linear", "USL"): "tab:cyan", ("linear", "USF"): "tab:purple",
               ("cubic B-spline", "MUSL"): "tab:red", ("cubic B-spline", "USL"): "tab:orange",
               ("cubic B-spline", "USF"): "tab:green"}
    fig, ax = plt.subplots(figsize=(10.5, 7.5))
    for basis in BASES:
        for scheme in SCHEMES:
            colour = colours[(basis, scheme)]
            for k, size in ((2, 7), (1, 4.5), (3, 10)):
                sel = [r for r in rows if r["status"] == "ok" and r["basis"] == basis and r["scheme"] == scheme
                       and r["k"] == k]
                if sel:
                    ax.loglog([r["time"] for r in sel], [r["error"] for r in sel], markers[scheme],
                              color=colour, mfc="none" if basis == "linear" else colour, ms=size, alpha=0.8,
                              label=f"{SHORT[basis]}, {scheme}" + ("" if k == 2 else f", {k}x{k} per cell"))
            sel = [r for r in rows if r["status"] == "unstable" and r["basis"] == basis and r["scheme"] == scheme]
            if sel:
                ax.loglog([r["time"] for r in sel], [r["error"] for r in sel], "x", color=colour, ms=8,
                          label=f"{SHORT[basis]}, {scheme}: unstable (energy > {ENERGY_LIMIT:g} E0)")
    for r in front:
        ax.annotate(f"{r['h_label']}, {r['cfl']:g}" + ("" if r["k"] == 2 else f", {r['k']}x{r['k']}"),
                    (r["time"], r["error"]), textcoords="offset points", xytext=(5, 3), fontsize=6.5, color="0.25")
    if front:
        ax.loglog([r["time"] for r in front], [r["error"] for r in front], "k--", lw=1, label="Pareto front")
    for basis, r in chosen.items():
        if r:
            ax.loglog([r["time"]], [r["error"]], "*", color="gold", mec="k", ms=16, zorder=5,
                      label=f"recommended, {SHORT[basis]}: {r['scheme']}, {r['h_label']}, CFL {r['cfl']:g}, "
                            f"{r['k']}x{r['k']}")
    ax.axhline(TOLERANCE, color="0.5", lw=1, ls=":", label=f"error {TOLERANCE:g}")
    failed = [r for r in rows if r["status"] not in ("ok", "unstable")]
    if failed:
        counts = {}
        for r in failed:
            counts[r["status"]] = counts.get(r["status"], 0) + 1
        ax.text(0.01, 0.01, "not shown: " + ", ".join(f"{v} {k}" for k, v in counts.items())
                + " (see the report)", transform=ax.transAxes, fontsize=8, color="tab:red")
    ax.set_xlabel("time of the steps [s]")
    ax.set_ylabel("max |u_x(x0, t) − u_exact(x0, t)| / A0 over 2 periods")
    ax.set_title("MPM vibrating bar: scheme × basis × h × CFL factor\n"
                 "(filled: cubic B-spline, open: linear; labels on the front: h, CFL factor)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build", help="build directory holding the hysteron executable")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="a subset of under a minute, to check the script")
    parser.add_argument("--workdir", default="/tmp/mpm_scheme_bench")
    parser.add_argument("--out", help="output directory (default doc/benchmarks; --quick: WORKDIR/quick)")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    hysteron = os.path.join(args.build, "hysteron")
    if not os.access(hysteron, os.X_OK):
        sys.exit(f"mpm_scheme_time_step.py: no executable {hysteron}")
    out = args.out or (os.path.join(args.workdir, "quick") if args.quick else os.path.join(ROOT, "doc/benchmarks"))
    os.makedirs(out, exist_ok=True)
    start = time.perf_counter()
    rows = study(hysteron, os.path.join(args.workdir, "runs"), args.repeats, args.quick)
    elapsed = time.perf_counter() - start
    front = mark_pareto(rows)
    chosen, margin = recommend(rows)
    write_csv(os.path.join(out, "mpm_scheme_time_step.csv"), rows)
    write_markdown(os.path.join(out, "mpm_scheme_time_step.md"), args, rows, front, chosen, margin, elapsed)
    plot(os.path.join(out, "mpm_scheme_time_step.png"), rows, front, chosen)
    print(f"wrote {out}/mpm_scheme_time_step.{{csv,md,png}}; benchmark wall time {elapsed:.0f} s")


if __name__ == "__main__":
    main()
