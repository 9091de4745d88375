#!/usr/bin/python3
"""FEM and MPM: error versus run time on an elastic cantilever and the §5.4 patch (issue 5).

FEM Q1/Q2 against the MPM with the linear and the cubic B-spline basis on two static problems,
across cell sizes (and points per cell), with the Pareto front.

(1) Elastic cantilever, L = 1 m, D = 0.1 m, b = 0.05 m, E = 210 GPa, nu = 0.3, plane stress,
    clamped at x = 0 (every displacement of the face x = 0 zero), a tip load P = 1 kN at x = L.
    Quantity: the tip deflection -u_y(L, 0). Reference: the FEM Q2 tip deflection of this clamped
    cantilever under a uniform end traction, Richardson-extrapolated from D/16, D/32 and D/64
    with the observed rate (the clamp's corners are singular, so Q2 converges at about h^1.4,
    not h^4); the exact Timoshenko-Goodier value (another end condition) is listed for scale.
    FEM: the scene of tests/fem/cantilever_tip_load.prm (uniform shear traction on x = L),
    quasi-static, one increment, Q1 with h = D/2 .. D/32, Q2 with h = D .. D/16.
    MPM: explicit dynamics without damping (rho = 7850 kg/m^3; the quasi-static deflection does
    not depend on it, and neither does the number of steps: T1 / dt = (omega_max / omega_1) / pi
    depends only on L, D, h and the CFL factor). The load rises along the C1 ramp
    P (t/T_r - sin(2 pi t/T_r) / (2 pi)) over T_r = RAMP_PERIODS * T1, T1 = 2 pi / omega_1,
    omega_1 = 1.875^2 sqrt(EI / (rho A L^4)), whose spectrum vanishes at omega_1 when T_r is a
    whole number of periods (little residual vibration), then holds for HOLD_PERIODS * T1; the
    deflection is the mean over the hold. The points carry the load and there is no boundary:
    the outermost column of points lies s/2 inside x = L (s = h / k the point spacing), so the
    load is split 3/2 P on the last column and -1/2 P on the one before (the same force and
    moment about the clamp as P at x = L), and the tip deflection is extrapolated the same way,
    u(L) = 3/2 u_1 - 1/2 u_2 from the mass-weighted mean displacements of the two columns.
    Clamp: a `fixed` boundary on the grid face x- at the beam's end; the grid extends 2h beyond
    the other faces. Bases linear and cubic B-spline, h = D/2, D/4, D/8, 2x2 and 3x3 points.
(2) Square patch, dissertation §5.4, prm/mpm_patch_tension.prm (Bouc-Wen, a rigid block pulls
    it quasi-statically). Quantity: the von Mises stress at A = (0.175, 0.175) at the end
    (t = 10.34 s; it grows monotonically after yield, so it is also the maximum over the
    history). Sampling: the MPM reports the material point that started nearest A; the cell sizes
    and points per cell are chosen so that A is a material point (k h-multiples with A at a point
    of the lattice; the distance is listed). The FEM value is interpolated at A from the
    quadrature points of the cell containing A (tensor-product Lagrange through the (p+1)^2
    Gauss points: exact where A is a Gauss point, i.e. the centre of a Q2 cell; for Q1 the mean
    of the 2x2 Gauss points around the centre); the nearest quadrature point (the FEM probe) is
    listed too. FEM: quasi-static, backward Euler (the consistent tangent), FEM_INCREMENTS
    increments; reference: Q2 on a fine mesh with REFERENCE_INCREMENTS increments (the
    convergence in h and in the increments is shown). MPM: the shipped scene (forward Euler,
    automatic step) with the cell size, points per cell and basis replaced; the cubic basis also
    with `FLIP fraction` = 0.95 (5 % PIC), which damps an instability of the undamped FLIP
    update that grows on fine grids over the ~10^4 steps. Runs that fail (exit status 2) are
    recorded with the first line of their message.

Time = the `steps` section of hysteron's timer table (set-up and output excluded), the median
of --repeats runs; a setting whose timed part takes longer than 60 s is run once (column runs).
Error = |q - q_ref| / |q_ref|. Pin the whole script to one core (taskset -c 1). Before the timed
sweep the script waits (up to --wait-minutes, polling every minute) until the 1-minute load
average is below --wait-load, and it samples the load during the sweep.

Writes OUT/fem_mpm_error_vs_time.{csv,md,png}; OUT = doc/benchmarks (with --quick: WORKDIR/quick).

Usage: fem_mpm_error_vs_time.py BUILD_DIR [--repeats 3] [--quick] [--workdir /tmp/fem_bench]
                                [--out DIR] [--built-from COMMIT] [--wait-load 1.5]
                                [--wait-minutes 20] [--report-only]
"""
import argparse
import csv
import datetime
import json
import math
import os
import pathlib
import re
import statistics
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_error_vs_time as mpm_bench  # noqa: E402  (shared helpers: timers, repeat, Pareto, machine)

ROOT = mpm_bench.ROOT
ENV = mpm_bench.ENV
with_entry = mpm_bench.with_entry
cantilever = mpm_bench.load_module("tests/fem/cantilever_convergence.py", "cantilever_convergence")
L, D, B, E, NU = cantilever.L, cantilever.D, cantilever.B, cantilever.E, cantilever.NU
P = 1000.0                          # tip load [N] (the traction 2e5 Pa of cantilever_tip_load.prm)
RHO = 7850.0                        # MPM mass density [kg/m^3]
I_AREA = B * D**3 / 12
OMEGA_1 = 1.875**2 * math.sqrt(E * I_AREA / (RHO * B * D * L**4))
T1 = 2 * math.pi / OMEGA_1          # first bending period (Euler-Bernoulli) [s]
RAMP_PERIODS, HOLD_PERIODS = 4, 2   # MPM load ramp and hold, in periods T1
A_POINT = (0.175, 0.175)            # point A of the patch
FEM_INCREMENTS = 100                # patch, FEM sweep
REFERENCE_INCREMENTS = 800          # patch, reference
# The patch with the cubic basis also runs with a 5 % PIC blend: on fine grids the undamped FLIP
# update (the shipped scene) lets a velocity instability grow at the free edges over the ~10^4 steps.
PIC_VARIANT, PIC_FLIP = "cubic B-spline, FLIP 0.95", 0.95
METHODS = (("FEM", "Q1"), ("FEM", "Q2"), ("MPM", "linear"), ("MPM", "cubic B-spline"), ("MPM", PIC_VARIANT))
STYLE = {("FEM", "Q1"): ("s", "tab:blue"), ("FEM", "Q2"): ("o", "tab:green"),
         ("MPM", "linear"): ("^", "tab:orange"), ("MPM", "cubic B-spline"): ("D", "tab:red"),
         ("MPM", PIC_VARIANT): ("P", "tab:purple")}

# What the MPM adds to the cantilever scene of tests/fem/cantilever_tip_load.prm.
MPM_CANTILEVER_EXTRA = """subsection Load tip_inner
  set Type = force
  set Region = rectangle({x2}, -1, {x1}, 1)
  set Value = 0; {P_inner}*{ramp}
end
subsection MPM
  subsection Grid
    set Lower corner = 0, {gy0}
    set Upper corner = {gx1}, {gy1}
    set Cell size = {h}
  end
  set Basis = {basis}
end
subsection Time
  set End time = {end}
end
"""

FEM_PATCH = """
subsection FEM
  set Degree = {p}
  set Number of increments = {increments}
  set Write quadrature point table = true
  subsection Mesh
    set Cell size = {h}
  end
end
"""


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def run_scene(hysteron, text, directory):
    """Write scene.prm into directory, run hysteron (timer table on), return the timings."""
    scene = pathlib.Path(directory, "scene.prm")
    scene.parent.mkdir(parents=True, exist_ok=True)
    scene.write_text(text)
    started = time.perf_counter()
    done = subprocess.run([hysteron, scene.name], cwd=directory, env=ENV, capture_output=True, text=True)
    elapsed = time.perf_counter() - started
    if done.returncode:
        raise RuntimeError(f"exit status {done.returncode}: {mpm_bench.first_line(done.stderr or done.stdout)}")
    sections = mpm_bench.timers(done.stdout)
    size = re.search(r"(\d+) material points|(\d+) DoFs", done.stdout)
    steps = re.search(r"\((\d+) steps", done.stdout)
    return dict(wall=elapsed, steps_s=sections.get("steps", sections["total"]), total=sections["total"],
                size=int(size.group(1) or size.group(2)) if size else 0,
                steps=int(steps.group(1)) if steps else 0)


def measure(hysteron, text, directory, repeats, quantity):
    """repeat() the run; quantity(directory) -> dict of the measured values (last run)."""
    r = mpm_bench.repeat(lambda: run_scene(hysteron, text, directory), repeats, "steps_s")
    r.update(quantity(directory))
    return r


# ------------------------------------------------------------------------------------------
# Cantilever

def cantilever_scene():
    text = open(os.path.join(ROOT, "tests/fem/cantilever_tip_load.prm")).read()
    return "".join(l for l in text.splitlines(True) if not l.lstrip().startswith("#"))


def with_line(text, section, line):
    """Add `line` as the first entry of `subsection section` in a .prm text."""
    header = f"subsection {section}\n"
    return text.replace(header, header + f"  {line}\n", 1)


def fem_cantilever_text(p, h):
    text = with_entry(cantilever_scene(), "FEM", "Degree", str(p))
    text = with_entry(text, "FEM", "Number of increments", "1")
    text = with_entry(text, "Mesh", "Cell size", f"{h:.10g}")
    # Only the end face: faces whose centre lies in the region carry the traction, and the
    # test's region (0.999 < x < 1.001) would also catch the top and bottom faces of the last
    # cells once h < 0.002 m.
    return with_entry(text, "Load tip", "Region", "rectangle(0.99999, -1, 1.00001, 1)")


def fem_tip_deflection(directory):
    return dict(q=-float(read_csv(os.path.join(directory, "output", "probe_0.csv"))[-1]["u_y"]))


def mpm_cantilever_text(basis, h, k, ramp_periods=RAMP_PERIODS, hold_periods=HOLD_PERIODS):
    """The test's scene with `Method = mpm`: the tip load as two forces on the two outer columns
    of points (3/2 P and -1/2 P along the ramp), their mean displacements as average regions."""
    s = h / k
    ramp_time = ramp_periods * T1
    ramp = f"if(t < {ramp_time:.8g}, t/{ramp_time:.8g} - sin(2*pi*t/{ramp_time:.8g})/(2*pi), 1)"
    x1, x2 = f"{L - s:.10g}", f"{L - 2 * s:.10g}"
    text = with_entry(cantilever_scene(), None, "Method", "mpm")
    text = with_entry(text, None, "Load names", "tip, tip_inner")
    text = with_line(text, "Material", f"set Density = {RHO:g}")
    text = with_line(text, "Body beam", f"set Particles per cell = {k}")
    text = with_entry(text, "Load tip", "Type", "force")
    text = with_entry(text, "Load tip", "Region", f"rectangle({x1}, -1, {L}, 1)")
    text = with_entry(text, "Load tip", "Value", f"0; {-1.5 * P}*{ramp}")
    text = with_entry(text, "Output", "Probe points", "")
    text = with_line(text, "Output", f"set Probe interval = {T1 / 50:.6g}")
    text = with_line(text, "Output", f"set Average regions = rectangle({x1}, -1, {L}, 1); "
                                     f"rectangle({x2}, -1, {x1}, 1)")
    return text + MPM_CANTILEVER_EXTRA.format(
        x1=x1, x2=x2, P_inner=0.5 * P, ramp=ramp, gy0=f"{-D / 2 - 2 * h:.10g}", gx1=f"{L + 2 * h:.10g}",
        gy1=f"{D / 2 + 2 * h:.10g}", h=f"{h:.10g}", basis=basis, end=f"{(ramp_periods + hold_periods) * T1:.8g}")


def mpm_tip_deflection(ramp_periods=RAMP_PERIODS):
    def quantity(directory):
        outer = read_csv(os.path.join(directory, "output", "average_0.csv"))
        inner = read_csv(os.path.join(directory, "output", "average_1.csv"))
        u = [-(1.5 * float(a["u_y"]) - 0.5 * float(b["u_y"])) for a, b in zip(outer, inner)
             if float(a["time"]) >= ramp_periods * T1 * (1 - 1e-9)]
        mean = statistics.fmean(u)
        return dict(q=mean, oscillation=(max(u) - min(u)) / 2 / mean,
                    q_last_column=-float(outer[-1]["u_y"]))
    return quantity


def richardson(h, q):
    """Extrapolate q(h) from three sizes halving each time: (limit, observed rate)."""
    ratio = (q[1] - q[0]) / (q[2] - q[1])
    rate = math.log(abs(ratio)) / math.log(h[0] / h[1])
    return q[2] + (q[2] - q[1]) / (ratio - 1), rate


def mpm_row(row, run, extra, describe):
    """Complete an MPM row (problem, variant, h, k) from run() (a measure() result): its size,
    steps, times and the `extra` quantities, or its failure; print one line."""
    name = f"{row['problem']} MPM {row['variant']} {row['h_label']} {row['k']}x{row['k']}"
    row.update(method="MPM", status="ok", message="")
    try:
        r = run()
    except RuntimeError as error:
        row.update(status="failed", message=str(error))
        print(f"{name}: FAILED {error}", flush=True)
        return row
    row.update(size=r["size"], steps=r["steps"], time=r["steps_s"], total_s=r["total"], wall_s=r["wall"],
               repeats=r["repeats"], **{key: r[key] for key in extra})
    print(f"{name}: {r['size']} points, {r['steps']} steps, {r['steps_s']:.3f} s (x{r['repeats']}), "
          + describe(r), flush=True)
    return row


def set_errors(rows, q_ref):
    """error = |q - q_ref| / |q_ref|, and the same for the other measured values of a row."""
    for r in rows:
        for value, error in (("q", "error"), ("q_last_column", "error_last_column"),
                             ("q_nearest", "error_nearest")):
            if r["status"] == "ok" and value in r:
                r[error] = abs(r[value] - q_ref) / abs(q_ref)


def cantilever_study(hysteron, workdir, repeats, quick):
    rows = []
    fem_sizes = {1: (2, 4) if quick else (2, 4, 8, 16, 32), 2: (1, 2) if quick else (1, 2, 4, 8, 16)}
    for p, divisions in fem_sizes.items():
        for n in divisions:
            h = D / n
            r = measure(hysteron, fem_cantilever_text(p, h), os.path.join(workdir, "cantilever", f"fem_q{p}_D{n}"),
                        repeats, fem_tip_deflection)
            rows.append(dict(problem="cantilever", method="FEM", variant=f"Q{p}", h=h, h_label=f"D/{n}", k="",
                             size=r["size"], steps=r["steps"], time=r["steps_s"], total_s=r["total"],
                             wall_s=r["wall"], repeats=r["repeats"], q=r["q"], status="ok", message=""))
            print(f"cantilever FEM Q{p} D/{n}: {r['size']} DoFs, {r['steps_s']:.4f} s, "
                  f"deflection {r['q']:.7e} m", flush=True)
    # The reference: Q2 at D/16 (above), D/32 and D/64, extrapolated.
    ref_divisions = (2, 4, 8) if quick else (16, 32, 64)
    ref_q = []
    for n in ref_divisions:
        directory = os.path.join(workdir, "cantilever", f"reference_q2_D{n}")
        run_scene(hysteron, fem_cantilever_text(2, D / n), directory)
        ref_q.append(fem_tip_deflection(directory)["q"])
    q_ref, rate = richardson([D / n for n in ref_divisions], ref_q)
    reference = dict(divisions=ref_divisions, q=ref_q, q_ref=q_ref, rate=rate,
                     exact_tg=-cantilever.exact_uy(L, 0.0) * P / cantilever.P)
    print(f"cantilever reference: Q2 {ref_q} -> {q_ref:.8e} m (rate {rate:.2f})", flush=True)

    mpm_settings = [(2, 2), (4, 2)] if quick else [(2, 2), (4, 2), (8, 2), (16, 2), (2, 3), (4, 3), (8, 3)]
    for basis in ("linear", "cubic B-spline"):
        for n, k in mpm_settings:
            directory = os.path.join(workdir, "cantilever", f"mpm_{basis.split()[0]}_D{n}_k{k}")
            rows.append(mpm_row(
                dict(problem="cantilever", variant=basis, h=D / n, h_label=f"D/{n}", k=k),
                lambda: measure(hysteron, mpm_cantilever_text(basis, D / n, k), directory, repeats,
                                mpm_tip_deflection()),
                ("q", "oscillation", "q_last_column"),
                lambda r: f"deflection {r['q']:.6e} m, residual oscillation {r['oscillation']:.1e}"))
    # The dynamic procedure's own error: the same run with a ramp and a hold twice as long.
    check_basis, check_n, check_k = "cubic B-spline", (2 if quick else 4), 2
    directory = os.path.join(workdir, "cantilever", "mpm_slow_ramp_check")
    run_scene(hysteron, mpm_cantilever_text(check_basis, D / check_n, check_k, 2 * RAMP_PERIODS,
                                            2 * HOLD_PERIODS), directory)
    slow = mpm_tip_deflection(2 * RAMP_PERIODS)(directory)["q"]
    base = next(r for r in rows if r["method"] == "MPM" and r["variant"] == check_basis
                and r["h_label"] == f"D/{check_n}" and r["k"] == check_k and r["status"] == "ok")
    reference["ramp_check"] = dict(setting=f"{check_basis}, D/{check_n}, {check_k}x{check_k}", q=base["q"], q_slow=slow,
                                   difference=abs(slow - base["q"]) / abs(base["q"]))
    set_errors(rows, q_ref)
    return rows, reference


# ------------------------------------------------------------------------------------------
# Square patch

def patch_base():
    text = open(os.path.join(ROOT, "prm/mpm_patch_tension.prm")).read()
    return "".join(l for l in text.splitlines(True) if not l.lstrip().startswith("# CHECK"))


def fem_patch_text(p, h, increments):
    text = with_entry(patch_base(), None, "Method", "fem")
    text = with_entry(text, "Bouc-Wen", "Integrator", "backward euler")
    text = with_entry(text, "MPM", "Write particle table", "false")
    return text + FEM_PATCH.format(p=p, h=f"{h:.10g}", increments=increments)


def lagrange_weights(nodes, x):
    return [math.prod((x - nodes[j]) / (nodes[i] - nodes[j]) for j in range(len(nodes)) if j != i)
            for i in range(len(nodes))]


def von_mises_plane_stress(sxx, syy, sxy):
    return math.sqrt(sxx * sxx + syy * syy - sxx * syy + 3 * sxy * sxy)


def fem_patch_quantity(h):
    """Von Mises at A: interpolated through the quadrature points of the cell containing A
    (by reference position; the mesh is structured from the origin), and at the nearest one."""
    def quantity(directory):
        points = []
        for row in read_csv(os.path.join(directory, "output", "quadrature_points.csv")):
            if row["body"] != "0":
                continue
            X = float(row["x_x"]) - float(row["u_x"])
            Y = float(row["x_y"]) - float(row["u_y"])
            points.append((X, Y, float(row["s_xx"]), float(row["s_yy"]), float(row["s_xy"]),
                           float(row["von_mises"])))
        i, j = math.floor(A_POINT[0] / h), math.floor(A_POINT[1] / h)
        cell = [q for q in points if math.floor(q[0] / h) == i and math.floor(q[1] / h) == j]
        xs = sorted({round(q[0], 12) for q in cell})
        ys = sorted({round(q[1], 12) for q in cell})
        wx, wy = lagrange_weights(xs, A_POINT[0]), lagrange_weights(ys, A_POINT[1])
        stress = [0.0, 0.0, 0.0]
        for q in cell:
            w = wx[xs.index(round(q[0], 12))] * wy[ys.index(round(q[1], 12))]
            for c in range(3):
                stress[c] += w * q[2 + c]
        nearest = min(points, key=lambda q: math.hypot(q[0] - A_POINT[0], q[1] - A_POINT[1]))
        return dict(q=von_mises_plane_stress(*stress), q_nearest=nearest[5],
                    distance=math.hypot(nearest[0] - A_POINT[0], nearest[1] - A_POINT[1]),
                    cell_points=len(cell))
    return quantity


def kinematic_floor(hysteron, workdir, strain):
    """The small-strain FEM and the MPM (rate of deformation, updated positions) differ by the
    strain measure: in uniaxial stretching the MPM integrates ln(1 + eps). The patch's material
    driven in uniaxial plane stress to eps and to ln(1 + eps) (the `material point` bench,
    adaptive integrator): the two stresses, an estimate of how far the MPM's limit lies from the
    FEM reference at A."""
    stresses = []
    for value in (strain, math.log1p(strain)):
        text = with_entry(patch_base(), None, "Method", "material point")
        text = with_entry(text, "Bouc-Wen", "Integrator", "adaptive")
        text += (f"subsection Material point\n  set Strain xx = {value:.10g}*t\n"
                 "  set Stress-free components = yy, xy\n  set End time = 1\n  set Steps = 2000\nend\n")
        directory = os.path.join(workdir, "patch", f"material_point_{value:.6f}")
        run_scene(hysteron, text, directory)
        stresses.append(float(read_csv(os.path.join(directory, "output", "history.csv"))[-1]["sig_xx"]))
    return dict(strain=strain, log_strain=math.log1p(strain), sigma=stresses[0], sigma_log=stresses[1])


def mpm_patch_text(basis, h, k, flip=None):
    text = with_entry(patch_base(), "Grid", "Cell size", f"{h:.10g}")
    if flip is not None:
        text = text.replace("\n  set Basis = ", f"\n  set FLIP fraction = {flip}\n  set Basis = ", 1)
    text = with_entry(text, "Body patch", "Particles per cell", str(k))
    text = with_entry(text, "Body block", "Particles per cell", str(k))
    text = with_entry(text, "MPM", "Write particle table", "false")
    return with_entry(text, "MPM", "Basis", basis)


def mpm_patch_quantity(directory):
    probe = read_csv(os.path.join(directory, "output", "probe_0.csv"))
    return dict(q=float(probe[-1]["von_mises"]),
                distance=math.hypot(float(probe[0]["x_x"]) - A_POINT[0], float(probe[0]["x_y"]) - A_POINT[1]))


def patch_label(h):
    n = round(0.3 / h)
    return f"0.3/{n}"


def patch_study(hysteron, workdir, repeats, quick):
    rows = []
    # A = (0.175, 0.175) is the centre of a cell for 0.3/h = 6, 18, 30, 42, 54 (a Gauss point of
    # Q2) and interior to a cell for 3, 9, 15.
    fem_sizes = {1: (6, 18) if quick else (3, 6, 9, 18, 30, 42), 2: (6,) if quick else (3, 6, 9, 18, 30)}
    for p, divisions in fem_sizes.items():
        for n in divisions:
            h = 0.3 / n
            r = measure(hysteron, fem_patch_text(p, h, FEM_INCREMENTS),
                        os.path.join(workdir, "patch", f"fem_q{p}_{n}"), repeats, fem_patch_quantity(h))
            rows.append(dict(problem="patch", method="FEM", variant=f"Q{p}", h=h, h_label=patch_label(h), k="",
                             size=r["size"], steps=r["steps"], time=r["steps_s"], total_s=r["total"],
                             wall_s=r["wall"], repeats=r["repeats"], q=r["q"], q_nearest=r["q_nearest"],
                             distance=r["distance"], status="ok", message=""))
            print(f"patch FEM Q{p} {patch_label(h)}: {r['size']} DoFs, {r['steps_s']:.3f} s (x{r['repeats']}), "
                  f"von Mises at A {r['q']:.6f} Pa (nearest quadrature point {r['q_nearest']:.6f}, "
                  f"{r['distance']:.2e} m)", flush=True)
    # Reference: Q2, REFERENCE_INCREMENTS, on three fine meshes (convergence shown); the
    # increments at 0.3/6: FEM_INCREMENTS / 2 .. 16 FEM_INCREMENTS.
    reference_sizes = (6, 18) if quick else (18, 30)
    reference_increments = 100 if quick else REFERENCE_INCREMENTS
    convergence = []
    for n in reference_sizes:
        directory = os.path.join(workdir, "patch", f"reference_q2_{n}_N{reference_increments}")
        r = run_scene(hysteron, fem_patch_text(2, 0.3 / n, reference_increments), directory)
        convergence.append(dict(n=n, increments=reference_increments, time=r["steps_s"],
                                q=fem_patch_quantity(0.3 / n)(directory)["q"]))
        reference_directory = directory
    increments = []
    for N in ((50, 100) if quick else (50, 100, 200, 400, 800, 1600)):
        directory = os.path.join(workdir, "patch", f"increments_q2_6_N{N}")
        r = run_scene(hysteron, fem_patch_text(2, 0.05, N), directory)
        increments.append(dict(n=6, increments=N, time=r["steps_s"], q=fem_patch_quantity(0.05)(directory)["q"]))
    q_ref = convergence[-1]["q"]
    # The finest reference's probe is its quadrature point at A (the centre of a Q2 cell).
    strain_at_a = float(read_csv(os.path.join(reference_directory, "output", "probe_0.csv"))[-1]["eps_xx"])
    floor = kinematic_floor(hysteron, workdir, strain_at_a)
    floor["relative"] = abs(floor["sigma"] - floor["sigma_log"]) / q_ref
    reference = dict(q_ref=q_ref, convergence=convergence, increments=increments, floor=floor,
                     label=f"FEM Q2, h = 0.3/{reference_sizes[-1]}, {reference_increments} increments")
    print(f"patch reference: {reference['label']}: {q_ref:.6f} Pa", flush=True)

    # A is a material point for k (0.3/h) = 2 (mod 4) with 0.3/h a multiple of 3.
    mpm_settings = [(3, 2), (6, 3)] if quick else [(3, 2), (9, 2), (15, 2), (21, 2), (6, 1), (18, 1),
                                                   (6, 3), (18, 3), (30, 3)]
    for variant in ("linear", "cubic B-spline", PIC_VARIANT):
        basis, flip = ("cubic B-spline", PIC_FLIP) if variant == PIC_VARIANT else (variant, None)
        for n, k in mpm_settings:
            directory = os.path.join(workdir, "patch", f"mpm_{basis.split()[0]}{'_pic' if flip else ''}_{n}_k{k}")
            rows.append(mpm_row(
                dict(problem="patch", variant=variant, h=0.3 / n, h_label=patch_label(0.3 / n), k=k),
                lambda: measure(hysteron, mpm_patch_text(basis, 0.3 / n, k, flip), directory, repeats,
                                mpm_patch_quantity),
                ("q", "distance"), lambda r: f"von Mises at A {r['q']:.6f} Pa"))
    set_errors(rows, q_ref)
    return rows, reference


# ------------------------------------------------------------------------------------------
# Load, report, plot

def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def wait_for_load(threshold, minutes):
    """Poll the 1-minute load average every minute until it is below threshold (at most
    `minutes`); return (minutes waited, the load when the sweep starts)."""
    start = time.time()
    while os.getloadavg()[0] >= threshold and time.time() - start < 60 * minutes:
        print(f"waiting for the load to fall below {threshold}: {uptime()}", flush=True)
        time.sleep(60)
    return (time.time() - start) / 60, os.getloadavg()[0]


class LoadMonitor(threading.Thread):
    """Samples the 1-minute load average every 20 s while the sweep runs."""

    def __init__(self):
        super().__init__(daemon=True)
        self.samples, self.stop = [], threading.Event()

    def run(self):
        while not self.stop.wait(0 if not self.samples else 20):
            self.samples.append(os.getloadavg()[0])

    def summary(self):
        s = self.samples or [os.getloadavg()[0]]
        return f"min {min(s):.2f}, median {statistics.median(s):.2f}, max {max(s):.2f} ({len(s)} samples)"


COLUMNS = ["problem", "method", "variant", "h_label", "h", "k", "size", "steps", "status", "time", "total_s",
           "wall_s", "repeats", "q", "error", "q_nearest", "error_nearest", "distance", "oscillation",
           "q_last_column", "error_last_column", "pareto", "message"]


def write_csv(path, rows):
    def cell(value):
        return f"{value:.8g}" if isinstance(value, float) else ("" if value is None else value)
    with open(path, "w", newline="") as f:
        table = csv.writer(f)
        table.writerow(COLUMNS)
        table.writerows([cell(r.get(c)) for c in COLUMNS] for r in rows)


def short_message(message):
    m = re.search(r"(a material point left the grid) in the step from t = ([0-9.e+-]+) s", message)
    return f"{m.group(1)} at t = {float(m.group(2)):.2f} s" if m else message[:120]


def setting(r):
    return f"{r['method']} {r['variant']} h = {r['h_label']}" + (f" {r['k']}x{r['k']}" if r["method"] == "MPM" else "")


def front_text(front):
    return " → ".join(f"{setting(r)} ({r['time']:.3g} s, {r['error']:.1e})" for r in front)


def table_rows(rows, q_format, extra):
    """Markdown rows: setting, size, steps, time, q, error, the `extra` (key, format) columns,
    runs and the Pareto mark; a failed run has its message in the time column."""
    lines = []
    for r in rows:
        cells = [r["method"], r["variant"], r["h_label"], f"{r['k']}x{r['k']}" if r["k"] else ""]
        if r["status"] == "ok":
            cells += [str(r["size"]), str(r["steps"]), f"{r['time']:.4g}", q_format.format(r["q"]),
                      f"{r['error']:.2e}"] + [fmt.format(r[key]) if key in r else "" for key, fmt in extra]
            cells += [str(r["repeats"]), "**P**" if r.get("pareto") else ""]
        else:
            cells += ["", "", f"failed: {short_message(r['message'])}"] + [""] * (len(extra) + 4)
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def write_markdown(path, args, info, cant_rows, cant_ref, patch_rows, patch_ref):
    build_type, dealii = mpm_bench.build_info(args.build)
    command = "taskset -c 1 benchmarks/fem_mpm_error_vs_time.py " + " ".join(sys.argv[1:])
    facts = (
        ("Machine", f"{mpm_bench.machine()} (`nproc`: {os.cpu_count()}), the run pinned to one core (taskset -c 1)"),
        ("Build", f"{build_type}, deal.II {dealii}, hysteron built from {args.built_from}"),
        ("Date", f"{info['date']}; the whole benchmark took {info['elapsed'] / 60:.1f} min"),
        ("Load (1-minute average)", f"{info['waited']:.0f} min waited for it to fall below {info['wait_load']} "
                                    f"(it was {info['start_load']:.2f} when the sweep started); during the sweep "
                                    f"{info['load']}; `uptime` before: `{info['uptime_before']}`, after: "
                                    f"`{info['uptime_after']}`"),
        ("Command", f"`{command}`"))
    lines = ["# FEM and MPM: error versus run time", ""]
    for name, value in facts:
        lines += [f"{name}: {value}.", ""]
    lines += [
        f"Times: the `steps` section of hysteron's timer table (set-up and output excluded), median of "
        f"{info['repeats']} runs; a setting whose timed part exceeds {mpm_bench.LONG_RUN:.0f} s was run once "
        "(column `runs`). Error = |q − q_ref| / |q_ref|. **P** marks the Pareto front (no other run is both "
        "faster and more accurate). Raw data: [fem_mpm_error_vs_time.csv](fem_mpm_error_vs_time.csv); the "
        "script's docstring describes every procedure.", "",
        "![error versus run time](fem_mpm_error_vs_time.png)", "",
        "## Cantilever (elastic, tip load)", "",
        f"L = {L:g} m, D = {D:g} m, b = {B:g} m, E = {E / 1e9:g} GPa, ν = {NU:g}, plane stress, clamped at "
        f"x = 0, P = {P / 1e3:g} kN at x = L; q = tip deflection −u_y(L, 0).", "",
        f"Reference: FEM Q2 of this clamped cantilever under a uniform end traction, "
        + ", ".join(f"D/{n}: {q:.8e} m" for n, q in zip(cant_ref["divisions"], cant_ref["q"]))
        + f"; Richardson extrapolation with the observed rate {cant_ref['rate']:.2f} (the clamp's corners "
        f"are singular): **q_ref = {cant_ref['q_ref']:.8e} m** (its correction to the finest run, "
        f"{abs(cant_ref['q_ref'] - cant_ref['q'][-1]) / cant_ref['q_ref']:.1e}, bounds its uncertainty). "
        f"The exact Timoshenko–Goodier deflection {cant_ref['exact_tg']:.6e} m belongs to another end "
        f"condition (only the centroid of the end x = 0 is held; the end face warps) and lies "
        f"{abs(cant_ref['exact_tg'] / cant_ref['q_ref'] - 1):.2%} above it.", "",
        f"MPM procedure: explicit dynamics, no damping, ρ = {RHO:g} kg/m³ (the static deflection and the "
        f"number of steps do not depend on it); ω₁ = 1.875² √(EI/(ρAL⁴)) = {OMEGA_1:.1f} rad/s, T1 = "
        f"{T1 * 1e3:.3f} ms; the load follows P (t/T_r − sin(2πt/T_r)/(2π)) over T_r = {RAMP_PERIODS} T1 "
        f"and holds for {HOLD_PERIODS} T1; q = the mean of the tip deflection over the hold (probe every "
        "T1/50). The load is split 3/2 P on the outermost column of points and −1/2 P on the next "
        "(statically equivalent to P at x = L: the outer column sits s/2 inside the end, s = h/k), and "
        "the deflection is extrapolated the same way to x = L from the two columns' mean displacements "
        "(column `error, last column` is the plain deflection of the outer column, for comparison). "
        "Residual oscillation: (max − min)/2 of the deflection over the hold, relative. "
        f"The procedure's own error: {cant_ref['ramp_check']['setting']} with a ramp and a hold twice as long "
        f"changes q by {cant_ref['ramp_check']['difference']:.1e} "
        f"({cant_ref['ramp_check']['q']:.6e} → {cant_ref['ramp_check']['q_slow']:.6e} m).", "",
        "| method | basis / degree | h | points per cell | DoFs / points | steps | time [s] | q [m] | error | "
        "error, last column | residual oscillation | runs | Pareto |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += table_rows(cant_rows, "{:.6e}", (("error_last_column", "{:.2e}"), ("oscillation", "{:.1e}")))
    lines += ["", f"Pareto front: {front_text(info['cant_front'])}.", ""]

    lines += [
        "## Square patch (§5.4, Bouc–Wen, pulled by a rigid block)", "",
        "Scene: prm/mpm_patch_tension.prm (its `# CHECK` lines dropped); q = von Mises stress at "
        "A = (0.175, 0.175) at t = 10.34 s (the maximum over the history: it grows monotonically after "
        "yield). MPM: the shipped scene (forward Euler, automatic step, CFL 0.5) with `Cell size`, "
        "`Particles per cell` (patch and block) and `Basis` replaced; the value of the material point that "
        "started nearest A (chosen settings put a point on A: column `sample distance`). FEM: the same "
        f"scene with `Method = fem`, backward Euler, {FEM_INCREMENTS} increments, "
        "`Write quadrature point table`; q interpolated at A through the quadrature points of the cell "
        "containing A (tensor-product Lagrange through its (p+1)² Gauss points, on the stress "
        "components; exact where A is a Gauss point, the centre of a Q2 cell for 0.3/h = 6, 18, 30); "
        "column `error, nearest` is the nearest quadrature point's value (what the FEM probe reports), "
        "`sample distance` its distance from A. `cubic B-spline, FLIP 0.95`: the cubic runs again with "
        "`MPM/FLIP fraction = 0.95` (5 % PIC), which damps the velocity instability that the undamped "
        "FLIP update of the shipped scene develops on fine grids (doc/benchmarks.md).", "",
        f"Reference: **{patch_ref['label']}: q_ref = {patch_ref['q_ref']:.6f} Pa**. Convergence in h (Q2, "
        f"{patch_ref['convergence'][0]['increments']} increments): "
        + ", ".join(f"0.3/{c['n']}: {c['q']:.6f} Pa ({c['time']:.3g} s)" for c in patch_ref["convergence"])
        + f"; in the increments (Q2, 0.3/{patch_ref['increments'][0]['n']}): "
        + ", ".join(f"{c['increments']}: {c['q']:.6f}" for c in patch_ref["increments"])
        + " Pa (backward Euler is first order in the increment).", "",
        "Kinematics: the FEM is small-strain, the MPM integrates the rate of deformation on moving points "
        f"(in uniaxial stretching ln(1 + ε)). At A the reference has ε_xx = {patch_ref['floor']['strain']:.4f}; "
        "the patch's material in uniaxial plane stress (`material point` bench) gives "
        f"{patch_ref['floor']['sigma']:.3f} Pa at ε and {patch_ref['floor']['sigma_log']:.3f} Pa at "
        f"ln(1 + ε) = {patch_ref['floor']['log_strain']:.4f}: the MPM's limit is expected about "
        f"{abs(patch_ref['floor']['sigma'] - patch_ref['floor']['sigma_log']):.2f} Pa "
        f"({patch_ref['floor']['relative']:.1e}) below q_ref, so MPM errors below that level are "
        "cancellations, not convergence (dotted line in the figure).", "",
        "MPM points include the rigid block's (a quarter of them).", "",
        "| method | basis / degree | h [m] | points per cell | DoFs / points | steps / increments | time [s] | "
        "q [Pa] | error | error, nearest | sample distance [m] | runs | Pareto |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += table_rows(patch_rows, "{:.5f}", (("error_nearest", "{:.2e}"), ("distance", "{:.1e}")))
    lines += ["", f"Pareto front: {front_text(info['patch_front'])}.", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(path, cant_rows, patch_rows, cant_front, patch_front, cant_ref, patch_ref):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(13, 7))
    panels = ((axes[0], cant_rows, cant_front, "cantilever, elastic: tip deflection",
               f"|q − q_ref| / q_ref (q_ref: FEM Q2 extrapolated, {cant_ref['q_ref']:.5e} m)"),
              (axes[1], patch_rows, patch_front, "square patch §5.4, Bouc–Wen: von Mises at A, t = 10.34 s",
               f"|q − q_ref| / q_ref (q_ref: {patch_ref['label']})"))
    for ax, rows, front, title, ylabel in panels:
        ok = [r for r in rows if r["status"] == "ok"]
        positive = [r["error"] for r in ok if r["error"] > 0]
        floor = 0.3 * min(positive) if positive else 1e-8
        for method, variant in METHODS:
            sel = [r for r in ok if r["method"] == method and r["variant"] == variant]
            if not sel:
                continue
            marker, colour = STYLE[(method, variant)]
            ax.loglog([r["time"] for r in sel], [max(r["error"], floor) for r in sel], marker, color=colour,
                      ms=7, mfc="none" if method == "MPM" else colour, label=f"{method} {variant}")
            left = variant == PIC_VARIANT
            for r in sel:
                label = r["h_label"] + (f" {r['k']}x{r['k']}" if method == "MPM" else "")
                ax.annotate(label, (r["time"], max(r["error"], floor)), textcoords="offset points",
                            xytext=(-5, -8) if left else (5, 2), ha="right" if left else "left",
                            fontsize=5.5, color=colour)
        if front:
            ax.loglog([r["time"] for r in front], [max(r["error"], floor) for r in front], "k--", lw=1,
                      label="Pareto front")
        failed = [r for r in rows if r["status"] != "ok"]
        if failed:
            ax.text(0.02, 0.02, "failed (a point left the grid):\n" + "\n".join(
                f"{r['method']} {r['variant'].replace('cubic B-spline', 'cubic')} {r['h_label']} {r['k']}x{r['k']}"
                for r in failed), transform=ax.transAxes, fontsize=6.5, color="tab:red", va="bottom")
        ax.set_xlabel("run time of the steps [s] (one core)")
        ax.set_ylabel(ylabel, fontsize=8)
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[1].axhline(patch_ref["floor"]["relative"], color="0.4", lw=1, ls=":",
                    label="MPM kinematics vs small-strain FEM (estimate)")
    for ax in axes:
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=3)
    fig.suptitle("FEM (filled) and MPM (open) error versus run time; labels: cell size h (and points per cell)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def write_outputs(out, args, info, cant_rows, cant_ref, patch_rows, patch_ref):
    info["cant_front"], info["patch_front"] = mpm_bench.mark_pareto(cant_rows), mpm_bench.mark_pareto(patch_rows)
    write_csv(os.path.join(out, "fem_mpm_error_vs_time.csv"), cant_rows + patch_rows)
    write_markdown(os.path.join(out, "fem_mpm_error_vs_time.md"), args, info, cant_rows, cant_ref,
                   patch_rows, patch_ref)
    plot(os.path.join(out, "fem_mpm_error_vs_time.png"), cant_rows, patch_rows, info["cant_front"],
         info["patch_front"], cant_ref, patch_ref)


OPTIONS = (  # (flags, argparse keywords) of the command line
    (("build",), dict(help="the build directory of the hysteron executable")),
    (("--repeats",), dict(type=int, default=3, help="runs per setting (the median time is kept)")),
    (("--quick",), dict(action="store_true", help="run a few settings only, to check the script")),
    (("--workdir",), dict(default="/tmp/fem_bench", help="where the runs are made")),
    (("--out",), dict(help="where the tables and the figure go (doc/benchmarks; --quick: WORKDIR/quick)")),
    (("--built-from",), dict(help="the commit of the build, for the report (git HEAD by default)")),
    (("--wait-load",), dict(type=float, default=1.5,
                            help="wait until the 1-minute load average is below this before the sweep")),
    (("--wait-minutes",), dict(type=float, default=None,
                               help="the longest wait for it [min] (default 20; 0 with --quick)")),
    (("--report-only",), dict(action="store_true", help="rewrite the outputs from WORKDIR/results.json "
                              "(--quick: results_quick.json) of the last run, running nothing")),
)


def git_head():
    try:
        return subprocess.check_output(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True).strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    for flags, keywords in OPTIONS:
        parser.add_argument(*flags, **keywords)
    args = parser.parse_args()
    args.built_from = args.built_from or git_head()
    if args.wait_minutes is None:
        args.wait_minutes = 0 if args.quick else 20
    args.build = os.path.abspath(args.build)
    hysteron = os.path.join(args.build, "hysteron")
    out = args.out or os.path.join(*((args.workdir, "quick") if args.quick else (ROOT, "doc", "benchmarks")))
    os.makedirs(out, exist_ok=True)
    results_path = os.path.join(args.workdir, "results_quick.json" if args.quick else "results.json")
    if args.report_only:
        with open(results_path) as f:
            results = json.load(f)
        sys.argv[1:], args.built_from = results["command"], results["built_from"]
        write_outputs(out, args, results["info"], results["cantilever"], results["cantilever_reference"],
                      results["patch"], results["patch_reference"])
        print(f"rewrote {out}/fem_mpm_error_vs_time.{{csv,md,png}} from {results_path}")
        return
    if hasattr(os, "sched_getaffinity") and len(os.sched_getaffinity(0)) > 1:
        print("note: not pinned to one core; run it as `taskset -c 1 ...` for the committed numbers", flush=True)

    info = dict(uptime_before=uptime(), date=datetime.date.today().isoformat(), repeats=args.repeats,
                wait_load=args.wait_load)
    info["waited"], info["start_load"] = wait_for_load(args.wait_load, args.wait_minutes)
    monitor = LoadMonitor()
    monitor.start()
    start = time.perf_counter()
    cant_rows, cant_ref = cantilever_study(hysteron, args.workdir, args.repeats, args.quick)
    patch_rows, patch_ref = patch_study(hysteron, args.workdir, args.repeats, args.quick)
    info["elapsed"] = time.perf_counter() - start
    monitor.stop.set()
    info["load"], info["uptime_after"] = monitor.summary(), uptime()
    results = dict(info=info, cantilever=cant_rows, cantilever_reference=cant_ref, patch=patch_rows,
                   patch_reference=patch_ref, command=sys.argv[1:], built_from=args.built_from)
    with open(results_path, "w") as f:
        json.dump(results, f, indent=1)
    write_outputs(out, args, info, cant_rows, cant_ref, patch_rows, patch_ref)
    print(f"wrote {out}/fem_mpm_error_vs_time.{{csv,md,png}}; benchmark wall time {info['elapsed']:.0f} s; "
          f"load during the sweep: {info['load']}")


if __name__ == "__main__":
    main()
