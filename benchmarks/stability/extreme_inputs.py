#!/usr/bin/python3
"""Extreme but valid inputs (issue 7): does each run, with the right answer, or is it refused?

Cases, each against an exact or a scaled reference:
  * stiffness ratio 1e6 between two bodies in series (a bar 1 m x 0.1 m, the left half
    E = 1e12 Pa, the right half 1e6 Pa, nu = 0, 1 kPa pulling): FEM Q1 and RBSN
    (k_t = k_n). Reference: u = F L1/(E1 A) + F L2/(E2 A) at the end, F L1/(E1 A) at the joint.
  * units: the elastic FEM cantilever of tests/fem/cantilever_tip_load.prm in SI, in mm-N-MPa
    and in micrometres-N (E = 0.21 N/um^2, L = 1e6 um). Reference: the SI deflection, scaled
    by the length unit (1e3 and 1e6).
  * nearly incompressible nu = 0.499: the same cantilever in plane strain, FEM Q1 and Q2.
    Reference: beam theory with E' = E/(1 - nu^2) and shear; Q1 is expected to lock (too
    stiff), Q2 much less.
  * points per cell: the MPM vibrating bar (tests/mpm/vibrating_bar.prm, cubic B-splines)
    with 1 to 5 points per direction (1 to 25 per cell). Reference: the largest |u_x| at the
    free end against the first axial mode's amplitude 2 v0 L / (pi c) = 6.366e-3 m.
  * 3D MPM, 1^3 to 5^3 points per cell: the same bar as a 1 m x 0.1 m x 0.1 m box (grid
    1.2 x 0.15 x 0.15 m, h = 0.05 m, fixed at x-, nu = 0), cubic B-splines and linear.
    Reference: the first axial mode u = v0/omega sin(pi x0/2L) sin(omega t) at the probed point
    x0 (amplitude) and the period 4 L / c = 0.4 s (the second zero crossing of u_x).
  * stiffness ratio 1e6 between two MPM bodies in contact: a soft column (0.1 m x 1 m,
    E = 100 Pa) standing on a stiff block (0.1 m x 0.1 m, E = 1e8 Pa) on the fixed floor of the
    grid, rho = 1, nu = 0, plane stress, sudden gravity g = 1 m/s^2, automatic time step (CFL
    factor 0.5). The two bodies only meet at the shared grid nodes. References: the step
    0.5 h / c_stiff = 2.5e-6 s (the stiff body's c = 1e4 m/s sets it; the soft one would allow
    1000 times more); the top of the column at T/2 = 2 L/c_soft = 0.2 s, where every mode of
    the fixed-free bar under a suddenly applied uniform load is at its extreme, 2 u_s(y0) with
    u_s(y) = rho g (L y - y^2/2) / E (y from the top of the block); its mean over one period
    0.4 s, u_s(y0); the energy balance, max |balance| <= 1e-4 of the largest gravity work. The
    step is measured as 0.4 s / (steps - 1) (the last step is the short one to the end time).
    Linear and cubic B-spline bases (the cubic one is expected to be too stiff: the block's
    points reach two cells into the column).
  * huge units: the FEM cantilever in km-GN-kPa (1 GN/km^2 = 1 kPa: E = 2.1e8 kPa,
    L = 1e-3 km) and in km-PN-GPa (1 PN/km^2 = 1e15 N / 1e6 m^2 = 1 GPa: E = 210 GPa); the RBSN
    beam lattice of tests/rbsn/beam_lattice.prm (exact Euler-Bernoulli chain, tip deflection
    0.2916 m) and the random-cell RBSN cantilever of tests/rbsn/cantilever_mesh_study.py
    (d_m = 0.05 m, seed 1) in km-GN-kPa; the MPM vibrating bar in km-kg-s (1 Pa =
    1e3 kg/(km s^2): E = 1e5, rho = 1e9 kg/km^3, v0 = 1e-4 km/s, h = 5e-5 km, thickness
    1e-3 km; time in s, so the steps are the same). Reference: the SI run, scaled by the
    length unit, to 1e-9 (the FEM: Newton's relative tolerance 1e-8).

Reports: exit status, the quantity against the reference, and whether any table holds a
non-finite value. Writes doc/stability/extreme_inputs.md.
Usage: benchmarks/stability/extreme_inputs.py BUILD_DIR [--output PREFIX] [--cases GROUP,...]
(groups: ratio, units, nu, ppc, mpm3d, contact, huge; default all)
"""
import argparse
import csv
import glob
import math
import os
import re
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

TWO_BODIES = """set Dimension = 2
set Method = {method}
set Body names = stiff, soft
set Material names = hard, compliant
set Boundary names = clamp
set Load names = pull
subsection Material hard
  set Model = linear elastic
  set Young's modulus = 1e12
  set Poisson's ratio = 0
  set Stress state = plane stress
end
subsection Material compliant
  set Model = linear elastic
  set Young's modulus = 1e6
  set Poisson's ratio = 0
  set Stress state = plane stress
end
subsection Body stiff
  set Shape = rectangle(0, 0, 0.5, 0.1)
  set Material = hard
end
subsection Body soft
  set Shape = rectangle(0.5, 0, 1, 0.1)
  set Material = compliant
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Load pull
  set Type = traction
  set Region = rectangle(0.999, -1, 1.001, 1)
  set Value = 1e3*t; 0
end
{solver}
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = 1, 0.05; 0.5, 0.05
end
"""
FEM_SOLVER = """subsection FEM
  set Degree = 1
  set Number of increments = 1
  subsection Mesh
    set Cell size = 0.05
  end
end"""
RBSN_SOLVER = """subsection RBSN
  set Analysis = static
  set Minimum distance = 0.02
  set Shear stiffness ratio = 1
end"""

CANTILEVER = """set Dimension = 2
set Method = fem
set Body names = beam
set Boundary names = clamp
set Load names = tip
subsection Material
  set Model = linear elastic
  set Young's modulus = {E}
  set Poisson's ratio = {nu}
  set Stress state = {state}
end
subsection Body beam
  set Shape = rectangle(0, {y0}, {L}, {y1})
  set Thickness = {t}
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Load tip
  set Type = traction
  set Region = rectangle({x0}, -{big}, {x1}, {big})
  set Value = 0; -{traction}*t
end
subsection FEM
  set Degree = {degree}
  set Number of increments = 1
  subsection Mesh
    set Cell size = {h}
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = {L}, 0
end
"""


def cantilever(unit=1.0, nu=0.3, state="plane stress", degree=2, force=1.0):
    """The cantilever of tests/fem/cantilever_tip_load.prm with lengths in units of `unit` metres
    and forces in units of `force` newtons (stresses in force/unit^2)."""
    s = 1 / unit  # metres -> the length unit
    p = unit**2 / force  # Pa -> the stress unit
    return CANTILEVER.format(E=210e9 * p, nu=nu, state=state, y0=-0.05 * s, y1=0.05 * s, L=1.0 * s,
                             t=0.05 * s, x0=0.999 * s, x1=1.001 * s, big=1.0 * s, traction=2e5 * p,
                             degree=degree, h=0.0125 * s)


BAR_3D = """set Dimension = 3
set Method = mpm
set Body names = bar
set Boundary names = clamp
subsection Material
  set Model = linear elastic
  set Young's modulus = 100
  set Poisson's ratio = 0
  set Density = 1
end
subsection Body bar
  set Shape = box(0, 0, 0, 1, 0.1, 0.1)
  set Particles per cell = {k}
  set Initial velocity = 0.1*sin(pi/2*x); 0; 0
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection MPM
  subsection Grid
    set Lower corner = 0, 0, 0
    set Upper corner = 1.2, 0.15, 0.15
    set Cell size = 0.05
  end
  set Basis = {basis}
end
subsection Time
  set End time = 0.5
  set CFL factor = 0.2
end
subsection Output
  set Probe interval = 0.001
  set Directory = output
  set Write VTU = false
  set Probe points = 1, 0.05, 0.05
end
"""

COLUMN = """set Dimension = 2
set Method = mpm
set Body names = block, column
set Material names = stiff, soft
set Boundary names = floor
set Gravity = 0, -1
subsection Material stiff
  set Model = linear elastic
  set Young's modulus = 1e8
  set Poisson's ratio = 0
  set Density = 1
  set Stress state = plane stress
end
subsection Material soft
  set Model = linear elastic
  set Young's modulus = 100
  set Poisson's ratio = 0
  set Density = 1
  set Stress state = plane stress
end
subsection Body block
  set Shape = rectangle(0, 0, 0.1, 0.1)
  set Material = stiff
end
subsection Body column
  set Shape = rectangle(0, 0.1, 0.1, 1.1)
  set Material = soft
end
subsection Boundary floor
  set Type = fixed
  set Faces = y-
end
subsection MPM
  subsection Grid
    set Lower corner = 0, 0
    set Upper corner = 0.15, 1.2
    set Cell size = 0.05
  end
  set Basis = {basis}
end
subsection Time
  set End time = 0.4
end
subsection Output
  set Probe interval = 0.001
  set Directory = output
  set Write VTU = false
  set Probe points = 0.05, 1.1
end
"""

RBSN_LATTICE = """set Dimension = 2
set Method = rbsn
set Body names = beam
set Boundary names = clamp
set Load names = tip
subsection Material
  set Model = linear elastic
  set Young's modulus = {E!r}
  set Poisson's ratio = 0
  set Stress state = plane stress
end
subsection Body beam
  set Shape = rectangle(0, 0, {L!r}, {b!r})
  set Thickness = {t!r}
end
subsection Boundary clamp
  set Type = fixed
  set Region = disk({c!r}, {c!r}, {r!r})
end
subsection Load tip
  set Type = force
  set Region = disk({xl!r}, {c!r}, {r!r})
  set Value = 0; -{P!r}
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {dm!r}
  set Points on the boundary = false
  set Additional points = {points}
  set Shear stiffness ratio = 1
  set Number of increments = 1
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = {xl!r}, {c!r}
end
"""


def rbsn_lattice(unit=1.0, force=1.0):
    """tests/rbsn/beam_lattice.prm (ten square cells, exact beam chain) in units of `unit` m and
    `force` N."""
    s, p = 1 / unit, unit**2 / force
    points = "; ".join(f"{(i + 0.5) * s!r}, {0.5 * s!r}" for i in range(10))
    return RBSN_LATTICE.format(E=1000 * p, L=10 * s, b=1 * s, t=0.1 * s, c=0.5 * s, r=0.01 * s, xl=9.5 * s,
                               P=0.01 / force, dm=5 * s, points=points)


RBSN_RANDOM = """set Dimension = 2
set Method = rbsn
set Body names = beam
set Boundary names = clamp
set Load names = tip
set Random seed = 1
subsection Material
  set Model = linear elastic
  set Young's modulus = {E!r}
  set Poisson's ratio = 0.3
  set Stress state = plane stress
end
subsection Body beam
  set Shape = rectangle(0, 0, {L!r}, {b!r})
  set Thickness = {t!r}
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection Load tip
  set Type = force
  set Region = rectangle({x0!r}, -{L!r}, {x1!r}, {L!r})
  set Value = 0; -{P!r}
end
subsection RBSN
  set Analysis = static
  set Minimum distance = {dm!r}
  set Points on the boundary = false
  set Additional points = {points}
  set Number of increments = 1
end
subsection Output
  set Directory = output
  set Write VTU = false
  set Probe points = {L!r}, {yp!r}
end
"""


def rbsn_random(unit=1.0, force=1.0):
    """The random-cell cantilever of tests/rbsn/cantilever_mesh_study.py (d_m = 0.05 m, seed 1:
    1 m x 0.1 m, E = 4e5 Pa, P = 1 N) in units of `unit` m and `force` N."""
    s, p = 1 / unit, unit**2 / force
    points = "; ".join(f"{x * s!r}, {j * 0.1 / 2 * s!r}" for x in (0, 1) for j in range(3))
    return RBSN_RANDOM.format(E=4e5 * p, L=1 * s, b=0.1 * s, t=1 * s, x0=0.999 * s, x1=1.001 * s,
                              P=1 / force, dm=0.05 * s, points=points, yp=0.05 * s)


BAR_2D = """set Dimension = 2
set Method = mpm
set Body names = bar
set Boundary names = clamp
subsection Material
  set Model = linear elastic
  set Young's modulus = {E!r}
  set Poisson's ratio = 0
  set Density = {rho!r}
  set Stress state = plane stress
end
subsection Body bar
  set Shape = rectangle(0, 0, {L!r}, {b!r})
  set Thickness = {t!r}
  set Particles per cell = 2
  set Initial velocity = {v0!r}*sin(pi/2*x/{L!r}); 0
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection MPM
  subsection Grid
    set Lower corner = 0, 0
    set Upper corner = {X!r}, {Y!r}
    set Cell size = {h!r}
  end
  set Basis = cubic B-spline
end
subsection Time
  set End time = 0.8
  set CFL factor = 0.2
end
subsection Output
  set Probe interval = 0.01
  set Directory = output
  set Write VTU = false
  set Probe points = {L!r}, {yp!r}
end
"""


def mpm_bar(unit=1.0, mass=1.0):
    """tests/mpm/vibrating_bar.prm (E = 100 Pa, rho = 1, v0 = 0.1 m/s) in units of `unit` m,
    `mass` kg and s."""
    s = 1 / unit
    pa = unit / mass  # Pa = kg/(m s^2) -> mass/(unit s^2)
    return BAR_2D.format(E=100 * pa, rho=1 * unit**3 / mass, L=1 * s, b=0.1 * s, t=1 * s, v0=0.1 * s, X=1.2 * s,
                         Y=0.15 * s, h=0.05 * s, yp=0.05 * s)


def run(hysteron, work, name, text, quiet=True):
    d = os.path.join(work, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "scene.prm"), "w") as f:
        f.write(text)
    p = subprocess.run([hysteron] + (["--quiet"] if quiet else []) + ["scene.prm"], cwd=d, env=ENV,
                       capture_output=True, text=True, timeout=600)
    run.stdout = p.stdout
    finite = True
    for path in glob.glob(os.path.join(d, "output", "*.csv")):
        with open(path) as f:
            if re.search(r"\b(nan|inf)\b", f.read(), re.I):
                finite = False
    message = p.stderr.strip().splitlines()[-1] if p.returncode else ""
    return d, p.returncode, finite, message


def last(d, table, column):
    with open(os.path.join(d, "output", table)) as f:
        return float(list(csv.DictReader(f))[-1][column])


def column(d, table, name):
    with open(os.path.join(d, "output", table)) as f:
        return [float(r[name]) for r in csv.DictReader(f)]


def crossings(t, u):
    """The times where u changes sign (linear interpolation)."""
    return [t[i] - u[i] * (t[i + 1] - t[i]) / (u[i + 1] - u[i]) for i in range(len(t) - 1) if u[i] * u[i + 1] < 0]


def mean(t, u, end):
    """The mean of u over [0, end] (trapezoidal rule over the rows up to end)."""
    pairs = [(a, b) for a, b in zip(t, u) if a <= end + 1e-12]
    return sum((t1 - t0) * (u0 + u1) / 2 for (t0, u0), (t1, u1) in zip(pairs, pairs[1:])) / pairs[-1][0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--output", default=os.path.join(ROOT, "doc", "stability", "extreme_inputs"))
    ap.add_argument("--cases", default="ratio,units,nu,ppc,mpm3d,contact,huge")
    args = ap.parse_args()
    cases = set(args.cases.split(","))
    hysteron = os.path.join(os.path.abspath(args.build), "hysteron")
    rows = []

    def record(case, d, code, finite, message, value, reference, tolerance, note=""):
        """reference None: value is itself the error (a bound: ok if value <= tolerance)."""
        if reference is None:
            error = abs(value) if code == 0 and value is not None else None
        else:
            error = abs(value / reference - 1) if code == 0 and value is not None else None
        ok = code == 0 and finite and error is not None and error <= tolerance
        rows.append((case, code, finite, value, reference, error, tolerance, "yes" if ok else "NO", note or message))
        print(f"{case}: exit {code}, value {value}, error {error}, {'ok' if ok else 'NOT OK'} {message}", flush=True)

    with tempfile.TemporaryDirectory(prefix="extreme_") as work:
        if "ratio" in cases:
            end = 1e3 * 0.5 / 1e12 + 1e3 * 0.5 / 1e6
            joint = 1e3 * 0.5 / 1e12
            for method, solver, tolerance in (("fem", FEM_SOLVER, 1e-9), ("rbsn", RBSN_SOLVER, 0.05)):
                d, code, finite, message = run(hysteron, work, f"ratio_{method}",
                                               TWO_BODIES.format(method=method, solver=solver))
                value = last(d, "probe_0.csv", "u_x") if code == 0 else None
                record(f"E ratio 1e6, {method}: end displacement", d, code, finite, message, value, end, tolerance)
                value = last(d, "probe_1.csv", "u_x") if code == 0 else None
                record(f"E ratio 1e6, {method}: joint displacement", d, code, finite, message, value, joint,
                       max(tolerance, 0.01))

        if "units" in cases or "huge" in cases:
            d, code, finite, message = run(hysteron, work, "units_si", cantilever())
            si = -last(d, "probe_0.csv", "u_y")
            si_reaction = last(d, "reactions.csv", "clamp_y")
        if "units" in cases:
            record("units: SI (m, N, Pa)", d, code, finite, message, si, 3.8392e-4, 3e-3, "beam theory 3.8392e-4 m")
            for unit, label in ((1e-3, "mm, N, MPa"), (1e-6, "um, N, N/um^2")):
                d, code, finite, message = run(hysteron, work, f"units_{unit:g}", cantilever(unit=unit))
                value = -last(d, "probe_0.csv", "u_y") * unit if code == 0 else None
                record(f"units: {label}", d, code, finite, message, value, si, 1e-8,
                       "against the SI run (Newton's relative tolerance 1e-8)")

        if "nu" in cases:
            # nu = 0.499, plane strain: beam theory with E' = E / (1 - nu^2) and shear (k = 5/6).
            E, nu, L, h, t, P = 210e9, 0.499, 1.0, 0.1, 0.05, 2e5 * 0.1 * 0.05
            Ep, G = E / (1 - nu**2), E / (2 * (1 + nu))
            beam = P * L**3 / (3 * Ep * t * h**3 / 12) + P * L / (5 / 6 * G * t * h)
            for degree in (1, 2):
                d, code, finite, message = run(hysteron, work, f"nu_q{degree}",
                                               cantilever(nu=nu, state="plane strain", degree=degree))
                value = -last(d, "probe_0.csv", "u_y") if code == 0 else None
                # Q1 locks: it runs, but far too stiff (accepted between 20 % and 100 % of the beam).
                record(f"nu = 0.499 plane strain, FEM Q{degree}", d, code, finite, message, value, beam,
                       0.8 if degree == 1 else 0.03,
                       "Q1 locks, as expected: use Degree = 2" if degree == 1 else "")

        v0, omega = 0.1, math.pi / 2 * math.sqrt(100 / 1)  # the bar's first mode: omega = pi c / (2 L)
        if "ppc" in cases:
            with open(os.path.join(ROOT, "tests", "mpm", "vibrating_bar.prm")) as f:
                bar = "\n".join(line for line in f.read().splitlines() if not line.startswith("#"))
            amplitude = v0 / omega  # 2 v0 L / (pi c)
            for k in (1, 2, 3, 4, 5):
                text = re.sub(r"set Particles per cell = \d+", f"set Particles per cell = {k}", bar)
                d, code, finite, message = run(hysteron, work, f"ppc_{k}", text)
                value = max(abs(v) for v in column(d, "probe_0.csv", "u_x")) if code == 0 else None
                record(f"MPM bar, {k}x{k} points per cell", d, code, finite, message, value, amplitude, 0.02)

        if "mpm3d" in cases:
            for basis in ("cubic B-spline", "linear"):
                for k in (1, 2, 3, 4, 5):
                    start = time.perf_counter()
                    d, code, finite, message = run(hysteron, work, f"bar3d_{basis[:5]}_{k}",
                                                   BAR_3D.format(k=k, basis=basis))
                    seconds = time.perf_counter() - start
                    amplitude = period = value = x0 = None
                    if code == 0:
                        t, u = column(d, "probe_0.csv", "time"), column(d, "probe_0.csv", "u_x")
                        x0 = column(d, "probe_0.csv", "x_x")[0]
                        amplitude = v0 / omega * math.sin(math.pi / 2 * x0)
                        value = max(abs(v) for v in u)
                        period = crossings(t, u)[1]
                    name = "cubic" if basis.startswith("cubic") else "linear"
                    record(f"3D MPM bar, {name}, {k}^3 points per cell: amplitude", d, code, finite, message,
                           value, amplitude or 1.0, 0.01,
                           f"x0 = {x0:.6g} m, {seconds:.1f} s wall" if code == 0 else "")
                    record(f"3D MPM bar, {name}, {k}^3 points per cell: period", d, code, finite, message,
                           period, 0.4, 0.01)

        if "contact" in cases:
            # The soft column (L = 1 m above the block, c_soft = 10 m/s) on the stiff block (c = 1e4 m/s).
            g, E, L = 1.0, 100.0, 1.0
            for basis, tolerance, note in (
                    ("linear", 0.01, ""),
                    ("cubic B-spline", 0.12,
                     "too stiff: the block's points reach 2 cells into the column (cubic support), "
                     "first order in h (doc/stability.md)")):
                d, code, finite, message = run(hysteron, work, f"contact_{basis[:5]}", COLUMN.format(basis=basis),
                                               quiet=False)
                name = "cubic" if basis.startswith("cubic") else "linear"
                dt = peak = average = balance = None
                us = 1.0
                if code == 0:
                    steps = int(re.search(r"\((\d+) steps", run.stdout).group(1))
                    dt = 0.4 / (steps - 1) if steps > 1 else None  # the last step is a short one up to 0.4 s
                    t, u = column(d, "probe_0.csv", "time"), column(d, "probe_0.csv", "u_y")
                    y0 = column(d, "probe_0.csv", "x_y")[0] - 0.1
                    us = 1 * g * (L * y0 - y0**2 / 2) / E
                    peak = -min(v for a, v in zip(t, u) if 0.15 < a < 0.25)
                    average = -mean(t, u, 0.4)
                    balance = max(abs(v) for v in column(d, "energy.csv", "balance")) / max(
                        abs(v) for v in column(d, "energy.csv", "external_work"))
                record(f"MPM contact E ratio 1e6, {name}: time step", d, code, finite, message, dt,
                       0.5 * 0.05 / 1e4, 1e-3, "0.5 h / c_stiff (0.4 s / (steps - 1); c_soft would allow 2.5e-3 s)")
                record(f"MPM contact E ratio 1e6, {name}: column top at T/2", d, code, finite, message, peak,
                       2 * us, tolerance, note)
                record(f"MPM contact E ratio 1e6, {name}: column top, mean over T", d, code, finite, message,
                       average, us, tolerance, note)
                record(f"MPM contact E ratio 1e6, {name}: max abs(balance) / max W_ext", d, code, finite, message,
                       balance, None, 1e-4, "energy.csv, every row")

        if "huge" in cases:
            for unit, force, label in ((1e3, 1e9, "km, GN, kPa"), (1e3, 1e15, "km, PN, GPa")):
                d, code, finite, message = run(hysteron, work, f"huge_fem_{force:g}",
                                               cantilever(unit=unit, force=force))
                value = -last(d, "probe_0.csv", "u_y") * unit if code == 0 else None
                record(f"huge units, FEM cantilever: {label}", d, code, finite, message, value, si, 1e-8,
                       "against the SI run (Newton's relative tolerance 1e-8)")
                value = last(d, "reactions.csv", "clamp_y") * force if code == 0 else None
                record(f"huge units, FEM cantilever: {label}, reaction", d, code, finite, message, value,
                       si_reaction, 1e-8, "against the SI run")
            for maker, label, exact in ((rbsn_lattice, "RBSN beam lattice", -0.2916),
                                        (rbsn_random, "RBSN random cells", None)):
                d, code, finite, message = run(hysteron, work, f"huge_{maker.__name__}_si", maker())
                reference = last(d, "probe_0.csv", "u_y") if code == 0 else None
                if exact is not None:
                    record(f"huge units, {label}: SI", d, code, finite, message, reference, exact, 1e-10,
                           "beam theory P L^3 / (3 E I) (exact for this chain)")
                d, code, finite, message = run(hysteron, work, f"huge_{maker.__name__}_km",
                                               maker(unit=1e3, force=1e9))
                value = last(d, "probe_0.csv", "u_y") * 1e3 if code == 0 else None
                record(f"huge units, {label}: km, GN, kPa", d, code, finite, message, value, reference or 1.0,
                       1e-9, "against the SI run")
            d, code, finite, message = run(hysteron, work, "huge_mpm_si", mpm_bar())
            si_bar = column(d, "probe_0.csv", "u_x") if code == 0 else []
            si_energy = column(d, "energy.csv", "kinetic") if code == 0 else []
            d, code, finite, message = run(hysteron, work, "huge_mpm_km", mpm_bar(unit=1e3))
            value = error = None
            if code == 0 and si_bar:
                km = [v * 1e3 for v in column(d, "probe_0.csv", "u_x")]
                scale = max(abs(v) for v in si_bar)
                error = max(abs(a - b) for a, b in zip(km, si_bar)) / scale if len(km) == len(si_bar) else math.inf
                value = max(abs(v) for v in km)
            record("huge units, MPM bar: km, kg, s: max abs(u_x)", d, code, finite, message, value,
                   max(abs(v) for v in si_bar) if si_bar else 1.0, 1e-9, "against the SI run")
            record("huge units, MPM bar: km, kg, s: max abs(u_x - u_x,SI) / max abs(u_x,SI)", d, code, finite,
                   message, error, None, 1e-9, "every probe row")
            if code == 0 and si_energy:
                # kinetic energy: J = kg m^2/s^2 = 1e-6 kg km^2/s^2; the thickness (1e-3 km) is the same length.
                km = [v * 1e6 for v in column(d, "energy.csv", "kinetic")]
                error = max(abs(a - b) for a, b in zip(km, si_energy)) / max(si_energy) \
                    if len(km) == len(si_energy) else math.inf
            record("huge units, MPM bar: km, kg, s: kinetic energy against SI", d, code, finite, message, error,
                   None, 1e-9, "every row, relative to the largest")

    lines = ["# Extreme but valid inputs", "",
             "`benchmarks/stability/extreme_inputs.py build` (cases and references in its docstring). "
             "'finite': no nan/inf in any table. 'ok': exit 0, finite, and within the tolerance.", "",
             "| case | exit | finite | value | reference | error | tolerance | ok | note |",
             "|---|---|---|---|---|---|---|---|---|"]
    for case, code, finite, value, reference, error, tolerance, ok, note in rows:
        v = "" if value is None else f"{value:.6g}"
        e = "" if error is None else f"{error:.2e}"
        r = "0 (bound)" if reference is None else f"{reference:.6g}"
        lines.append(f"| {case} | {code} | {finite} | {v} | {r} | {e} | {tolerance:g} | {ok} | {note} |")
    with open(args.output + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
