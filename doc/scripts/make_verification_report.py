#!/usr/bin/python3
"""Regenerate doc/verification.md from scratch (issue 7): run every scene of the report, check
its assertions, read each number from the outputs, redraw the figures and fill the template.

  doc/scripts/make_verification_report.py BUILD_DIR [--jobs 2] [--skip-figures] [--workdir DIR]
                                          [--core 0] [--doc FILE]

1. Runs every scene of the report: each .prm through tests/run_prm_test.py --workdir (so every
   `# CHECK` line is asserted again, MPI runs included), the two Python studies
   tests/mpm/velocity_gradient.py and tests/rbsn/cantilever_mesh_study.py with the command lines
   of tests/CMakeLists.txt (plus --markdown and --plot into the work directory), and a few
   variants of shipped RBSN scenes with one entry changed (the cell counts of other d_m, the
   uncoupled springs of §5.1; run without --quiet, which prints the cell counts). Every command
   is pinned with `taskset -c CORE` (core 0; core 1 is kept for timing runs); --jobs 2 runs two
   at a time, both on that core.
2. Any failing run or assertion fails the whole script (exit status 1, naming the scenes and
   their logs); nothing is written then.
3. Reads every number of the "hysteron" column from the CSV outputs, computing each the way the
   scene's `# CHECK` lines do (e.g. the first-yield load of the cantilevers, the von Mises
   max/min of the patch, L_f of the Taylor bar through doc/scripts/taylor_bar_metrics.py).
4. Unless --skip-figures: calls the four figure scripts doc/scripts/make_figures.sh,
   make_compare_figures.sh (on this run's compare-scene outputs), perforated_plate_study.sh
   (table and curves into WORKDIR/perforated_plate_study*) and make_rbsn_figures.py, and copies
   the two studies' figures to doc/mpm/velocity_gradient.png and doc/rbsn/cantilever_mesh_study.png.
5. Fills doc/verification.md.in into doc/verification.md (benchmarks/report_template.py: a field
   that cannot be evaluated stops the script before anything is written; atomic write).

Not re-run (minutes each, stated in the report): the fine MPM collapse beam
(doc/scenes/mpm_beam_collapse_full.prm).

The work directory (default: a new temporary one) keeps every run's output and log.
"""
import argparse
import concurrent.futures
import csv
import datetime
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from report_template import environment, fill, write_atomically  # noqa: E402

PY = "/usr/bin/python3"          # Debian's matplotlib lives here
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1",
           # Both ranks of the MPI checks run inside the one allowed core: no binding to cores.
           OMPI_MCA_hwloc_base_binding_policy="none")

# The scenes of the report, run through tests/run_prm_test.py (name = the file's stem).
SCENES = [
    "prm/table_2_1_kinematic.prm", "prm/table_2_1_mixed.prm", "prm/table_2_1_isotropic.prm",
    "prm/table_2_2_degradation.prm",
    "tests/rbsn/beam_lattice.prm", "prm/rbsn_single_element_plasticity.prm",
    "prm/rbsn_single_element_fracture.prm", "prm/rbsn_perforated_plate.prm",
    "prm/fem_perforated_plate.prm",
    "prm/rbsn_cantilever_plastic.prm", "prm/fem_cantilever_plastic.prm",
    "prm/rbsn_concrete_beam_fracture.prm", "prm/rbsn_cantilever_fracture.prm",
    "prm/rbsn_titanium_plate.prm",
    "prm/mpm_patch_tension.prm", "prm/mpm_patch_sinusoidal_isotropic.prm",
    "prm/mpm_patch_sinusoidal_kinematic.prm",
    "prm/compare_patch_tension.prm", "prm/compare_patch_sinusoidal_isotropic.prm",
    "prm/compare_patch_sinusoidal_kinematic.prm", "prm/compare_patch_moving_grid.prm",
    "prm/mpm_beam_collapse.prm", "prm/compare_beam_sinusoidal.prm", "prm/compare_beam_degradation.prm",
    "prm/mpm_taylor_bar_2d.prm", "prm/mpm_taylor_bar_axisymmetric.prm",
    "doc/scenes/mpm_taylor_bar_3d.prm",
    "prm/compare_portal_frame.prm", "prm/compare_frame_corner.prm",
    "tests/compare/portal_frame_elastic.prm", "tests/compare/frame_corner_elastic.prm",
]
# Variants of shipped RBSN scenes: name -> (scene, {entry: value}); Write VTU off throughout.
VARIANTS = {
    "cells_rbsn_perforated_plate_0.05": ("rbsn_perforated_plate", {"Minimum distance": "0.05"}),
    "cells_rbsn_perforated_plate_0.03": ("rbsn_perforated_plate", {}),
    "cells_rbsn_perforated_plate_0.02": ("rbsn_perforated_plate", {"Minimum distance": "0.02"}),
    "cells_rbsn_cantilever_plastic": ("rbsn_cantilever_plastic", {}),
    "rbsn_cantilever_plastic_uncoupled": ("rbsn_cantilever_plastic", {"Spring law": "uncoupled"}),
    "cells_rbsn_concrete_beam_fracture_0.025": ("rbsn_concrete_beam_fracture", {}),
    "cells_rbsn_concrete_beam_fracture_0.015": ("rbsn_concrete_beam_fracture", {"Minimum distance": "0.015"}),
    "cells_rbsn_titanium_plate_0.003": ("rbsn_titanium_plate", {}),
    "cells_rbsn_titanium_plate_0.0009": ("rbsn_titanium_plate", {"Minimum distance": "0.0009"}),
}
# Rough single-core seconds, to start the long runs first.
EXPECTED = {"compare_beam_sinusoidal": 300, "compare_beam_degradation": 300, "cantilever_mesh_study": 90,
            "compare_portal_frame": 100, "compare_frame_corner": 60, "frame_corner_elastic": 25,
            "portal_frame_elastic": 20,
            "velocity_gradient": 30, "compare_patch_tension": 25, "compare_patch_sinusoidal_kinematic": 20,
            "cells_rbsn_titanium_plate_0.0009": 20, "mpm_beam_collapse": 15,
            "compare_patch_sinusoidal_isotropic": 12, "fem_cantilever_plastic": 10,
            "mpm_taylor_bar_2d": 10, "mpm_taylor_bar_3d": 10, "cells_rbsn_concrete_beam_fracture_0.015": 8}


class Job:
    def __init__(self, name, command, cwd=ROOT, log=None):
        self.name, self.command, self.cwd, self.log = name, command, cwd, log
        self.status, self.seconds, self.stdout = "not run", None, ""


def set_entry(text, name, value):
    new, n = re.subn(rf"(?m)^(\s*set {re.escape(name)}\s*=).*$", rf"\g<1> {value}", text, count=1)
    if n != 1:
        raise SystemExit(f"make_verification_report.py: no entry '{name}' to change")
    return new


def jobs_of(args, work):
    exe = os.path.join(args.build, "hysteron")
    mpiexec = re.search(r"HYSTERON_MPIEXEC:STRING=(.*)", open(os.path.join(args.build, "CMakeCache.txt")).read())
    mpiexec = mpiexec.group(1).strip() if mpiexec else "mpirun"      # as tests/CMakeLists.txt passes it
    logs = os.path.join(work, "logs")
    os.makedirs(logs, exist_ok=True)
    jobs = []
    for scene in SCENES:
        name = os.path.splitext(os.path.basename(scene))[0]
        jobs.append(Job(name, [PY, os.path.join(ROOT, "tests", "run_prm_test.py"), "--hysteron", exe,
                               "--mpiexec", mpiexec, "--workdir", os.path.join(work, "runs", name), os.path.join(ROOT, scene)],
                        log=os.path.join(logs, name + ".log")))
    studies = os.path.join(work, "studies")
    for name, script in (("velocity_gradient", "tests/mpm/velocity_gradient.py"),
                         ("cantilever_mesh_study", "tests/rbsn/cantilever_mesh_study.py")):
        jobs.append(Job(name, [PY, os.path.join(ROOT, script), exe, os.path.join(studies, name),
                               "--markdown", os.path.join(studies, name + ".md"),
                               "--plot", os.path.join(studies, name + ".png")],
                        log=os.path.join(logs, name + ".log")))
    for name, (scene, entries) in VARIANTS.items():
        directory = os.path.join(work, "variants", name)
        os.makedirs(directory, exist_ok=True)
        text = open(os.path.join(ROOT, "prm", scene + ".prm")).read()
        for key, value in dict(entries, **{"Write VTU": "false"}).items():
            text = set_entry(text, key, value)
        with open(os.path.join(directory, "scene.prm"), "w") as f:
            f.write(text)
        jobs.append(Job(name, [exe, "scene.prm"], cwd=directory, log=os.path.join(logs, name + ".log")))
    return jobs


def run_jobs(jobs, n, core):
    def one(job):
        start = time.time()
        command = ["taskset", "-c", str(core), *job.command]
        with open(job.log, "w") as f:
            p = subprocess.run(command, cwd=job.cwd, env=ENV, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
            f.write(p.stdout)
        job.stdout, job.seconds = p.stdout, time.time() - start
        job.status = "ok" if p.returncode == 0 else f"failed (exit {p.returncode})"
        print(f"[{datetime.datetime.now():%H:%M:%S}] {job.name}: {job.status}, {job.seconds:.1f} s", flush=True)

    ordered = sorted(jobs, key=lambda j: -EXPECTED.get(j.name, 3))
    with concurrent.futures.ThreadPoolExecutor(max_workers=n) as pool:
        list(pool.map(one, ordered))


def fail_on(jobs):
    failed = [j for j in jobs if j.status != "ok"]
    if not failed:
        return
    for j in failed:
        lines = j.stdout.strip().splitlines()
        tail = lines[lines.index("FAILED:"):] if "FAILED:" in lines else lines[-15:]
        print(f"\n=== {j.name}: {j.status} (log {j.log})\n" + "\n".join(tail[:40]), file=sys.stderr)
    raise SystemExit("make_verification_report.py: failed: " + ", ".join(j.name for j in failed)
                     + "; doc/verification.md not written")


# --------------------------------------------------------------------------------------------
# Reading the outputs
# --------------------------------------------------------------------------------------------
def columns(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"make_verification_report.py: {path}: no data rows")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def markdown_rows(path):
    """The rows of the first Markdown table in path, as lists of stripped cells (header skipped)."""
    lines = [l for l in open(path).read().splitlines() if l.startswith("|")]
    return [[c.strip() for c in l.strip("|").split("|")] for l in lines[2:]]


def cells_of(job):
    m = re.search(r"rbsn: (\d+) cells, (\d+) facets", job.stdout)
    if not m:
        raise SystemExit(f"make_verification_report.py: {job.name}: no 'rbsn: N cells' line in its output")
    return int(m.group(1)), int(m.group(2))


def first_yield(c):
    """The CHECK of the §5.1 cantilevers: the load where the tangent first falls below 95 % of
    the elastic stiffness (reactions.csv tip_y, kN)."""
    t, p = c["time"], c["tip_y"]
    return 1e-3 * [-p[i] for i in range(2, len(t))
                   if (p[i] - p[i - 1]) / (t[i] - t[i - 1]) > 0.95 * p[1] / t[1]][0]


def at_time(c, column, time_value):
    i = next(i for i, t in enumerate(c["time"]) if abs(t - time_value) < 1e-9)
    return c[column][i]


def half_cycle_peaks(c, column="von_mises"):
    """Peaks of each half cycle of the sinusoidal patch (windows of the compare scenes' CHECKs)."""
    windows = ((0, 2.3), (2.3, 4.9), (4.9, 7.6), (7.6, 10.4))
    return [max(v for t, v in zip(c["time"], c[column]) if a <= t < b) for a, b in windows]


def measure(work, jobs):
    runs = os.path.join(work, "runs")
    by_name = {j.name: j for j in jobs}

    def out(scene, *path):
        return columns(os.path.join(runs, scene, "output", *path))

    m = {}
    # Chapter 2.
    s = out("table_2_1_kinematic", "table_2_1_kinematic", "history.csv")["sig_xx"]
    m["kin_peak"], m["kin_reverse"] = max(s) / 1e6, s[500] / 1e6
    s = out("table_2_1_mixed", "table_2_1_mixed", "history.csv")["sig_xx"]
    m["mixed_peaks"] = [max(s[k:k + 501]) / 1e6 for k in (0, 1000, 2000)]
    s = out("table_2_1_isotropic", "table_2_1_isotropic", "history.csv")["sig_xx"]
    m["iso_peak"], m["iso_valley"] = max(s[0:501]) / 1e6, min(s[500:1001]) / 1e6
    c = out("table_2_2_degradation", "table_2_2_degradation", "history.csv")
    m["deg_eta"], m["deg_eh"], m["deg_nu"] = c["eta"][-1], c["e_h"][-1], c["nu_s"][-1]
    m["deg_peaks"] = [max(v for v, t in zip(c["sig"], c["t"]) if a < t <= b) / 1e6
                      for a, b in ((-1, 12), (12, 24), (24, 1e9))]

    # Chapter 3.
    c = out("beam_lattice", "probe_0.csv")
    m["lattice_u"], m["lattice_theta"] = abs(c["u_y"][-1] / -0.2916 - 1), abs(c["theta"][-1] / -0.0486 - 1)
    c = out("rbsn_single_element_plasticity", "probe_0.csv")
    k_n, f, u, h = 4.6153846e9, c["f_n"], c["u_x"], c["H1_n"]
    m["se_yield"] = statistics.median(abs(fi - 0.05 * k_n * ui) / 0.95
                                      for fi, ui, hi in zip(f, u, h) if hi >= 0.999) / 1e3
    m["se_slope"] = 100 * statistics.median(
        (f[i] - f[i - 1]) / (u[i] - u[i - 1]) / k_n for i in range(1, len(f))
        if h[i] > 0.999 and h[i - 1] > 0.999 and (f[i] - f[i - 1]) * (u[i] - u[i - 1]) > 0)
    c = out("rbsn_single_element_fracture", "probe_0.csv")
    # The last row before the break (the cell is released after it and its facet has no force).
    i = max(k for k, b in enumerate(c["broken"]) if b == 0)
    m["sf_yield"] = (c["f_n"][i] - 0.02 * 2.3077e9 * c["u_x"][i]) / 0.98 / 1e3
    m["sf_break"] = 1400 * out("rbsn_single_element_fracture", "fracture.csv")["time"][0]

    rows = markdown_rows(os.path.join(work, "studies", "cantilever_mesh_study.md"))
    study = {}
    for r in rows:
        study.setdefault(float(r[0]), []).append((float(r[2]), int(r[3])))
    m["cms_coarse"] = statistics.mean(d for d, _ in study[0.05])
    m["cms_fine"] = statistics.mean(d for d, _ in study[0.005])
    m["cms_cells_coarse"] = statistics.mean(n for _, n in study[0.05])
    m["cms_cells_fine"] = statistics.mean(n for _, n in study[0.005])

    rbsn, fem = out("rbsn_perforated_plate", "reactions.csv"), out("fem_perforated_plate", "fem_perforated_plate", "reactions.csv")
    k_fem = fem["top_y"][1] / (fem["time"][1] * 4e-3)
    m["fem_plate_k0"] = k_fem / 1e6
    m["fem_plate_2mm"], m["fem_plate_4mm"] = at_time(fem, "top_y", 0.5) / 1e3, fem["top_y"][-1] / 1e3
    m["plate_stiffness"] = rbsn["top_y"][1] / (rbsn["time"][1] * 4e-3) / k_fem
    m["plate_2mm"] = at_time(rbsn, "top_y", 0.5) / 1e3 / m["fem_plate_2mm"] - 1
    m["plate_4mm"] = rbsn["top_y"][-1] / 1e3 / m["fem_plate_4mm"] - 1
    m["plate_cells"] = " / ".join(str(cells_of(by_name[f"cells_rbsn_perforated_plate_{d}"])[0])
                                  for d in ("0.05", "0.03", "0.02"))

    # Chapter 4.
    vg = {(r[0], int(r[1]), r[2]): float(r[4])
          for r in markdown_rows(os.path.join(work, "studies", "velocity_gradient.md"))}
    m["vg_ratio_1"] = vg[("cubic B-spline", 10, "1x1")] / vg[("cubic B-spline", 20, "1x1")]
    m["vg_ratio_2"] = vg[("cubic B-spline", 20, "1x1")] / vg[("cubic B-spline", 40, "1x1")]
    m["vg_linear"] = [vg[("linear", n, "4x4")] / vg[("linear", n, "1x1")] for n in (10, 20, 40)]

    # Chapter 5.
    m["cp_cells"], m["cp_facets"] = cells_of(by_name["cells_rbsn_cantilever_plastic"])
    c = out("rbsn_cantilever_plastic", "reactions.csv")
    m["cp_yield"], m["cp_plateau"] = first_yield(c), -c["tip_y"][-1] / 1e3
    m["cp_uncoupled"] = -columns(os.path.join(work, "variants", "rbsn_cantilever_plastic_uncoupled", "output",
                                              "reactions.csv"))["tip_y"][-1] / 1e3
    c = out("fem_cantilever_plastic", "reactions.csv")
    m["fc_yield"], m["fc_plateau"] = first_yield(c), -c["tip_y"][-1] / 1e3
    m["concrete_cells"] = " / ".join(str(cells_of(by_name[f"cells_rbsn_concrete_beam_fracture_{d}"])[0])
                                     for d in ("0.025", "0.015"))
    c = out("rbsn_concrete_beam_fracture", "reactions.csv")
    first = out("rbsn_concrete_beam_fracture", "fracture.csv")
    # The elastic load at which the first facet reached f_t = 2 MPa (linear up to the break).
    m["concrete_crack"] = -c["load_y"][1] / c["time"][1] * first["time"][0] / (first["s_n"][0] / 2e6) / 1e3
    m["cf_break"] = 100 * out("rbsn_cantilever_fracture", "fracture.csv")["time"][0]
    m["cf_peak"] = max(-v for v in out("rbsn_cantilever_fracture", "reactions.csv")["tip_y"]) / 1e3
    m["titanium_cells"] = " / ".join(str(cells_of(by_name[f"cells_rbsn_titanium_plate_{d}"])[0])
                                     for d in ("0.003", "0.0009"))
    c = out("rbsn_titanium_plate", "reactions.csv")
    m["ti_stiffness"] = c["top_y"][1] / (c["time"][1] * 1.5e-3) / 7.957e7
    m["ti_peak"] = max(c["top_y"]) / 1e3
    c = out("mpm_patch_tension", "particles.csv")
    patch = [v for b, v in zip(c["body"], c["von_mises"]) if b == 0]
    m["patch_max"], m["patch_min"] = max(patch), min(patch)
    iso = half_cycle_peaks(out("mpm_patch_sinusoidal_isotropic", "probe_0.csv"))
    kin = half_cycle_peaks(out("mpm_patch_sinusoidal_kinematic", "probe_0.csv"))
    m["iso_later"], m["kin_later"] = iso[1:], kin[1:]
    m["kin_spread"] = max(abs(v - kin[0]) for v in kin[1:])
    for key, scene in (("cmp_patch_tension", "compare_patch_tension"),
                       ("cmp_patch_iso", "compare_patch_sinusoidal_isotropic"),
                       ("cmp_patch_kin", "compare_patch_sinusoidal_kinematic")):
        c = out(scene, "compare", "probe_0.csv")
        m[key] = 100 * max(abs(d) for d in c["von_mises_diff"]) / max(abs(v) for v in c["von_mises_MPM"])
    # §5.4 fine patch (36 cells x 16 points) on a moving grid against the updated-Lagrangian FEM.
    c = out("compare_patch_moving_grid", "compare", "probe_0.csv")
    m["cmp_patch_moving"] = 100 * max(abs(d) for d in c["von_mises_diff"]) / max(abs(v) for v in c["von_mises_MPM"])
    c = out("compare_patch_moving_grid", "compare", "reactions.csv")
    m["cmp_patch_moving_force"] = 100 * max(abs(d) for d in c["block_x_diff"]) / max(abs(v) for v in c["block_x_MPM"])
    for key, scene in (("cmp_beam_sin", "compare_beam_sinusoidal"), ("cmp_beam_deg", "compare_beam_degradation")):
        c = out(scene, "compare", "average_0.csv")
        m[key] = 100 * max(abs(d) for d in c["u_y_diff"]) / max(abs(v) for v in c["u_y_MPM"])
    m["beam_collapse"] = max(-p for p in out("mpm_beam_collapse", "reactions.csv")["push_y"]) / 1e3
    def taylor(scene, dim, *flags):
        return [float(v) for v in subprocess.run(
            [PY, os.path.join(ROOT, "doc", "scripts", "taylor_bar_metrics.py"),
             os.path.join(runs, scene, "output", "particles.csv"), str(dim), *flags],
            check=True, capture_output=True, text=True).stdout.split()]
    m["taylor_lf"] = taylor("mpm_taylor_bar_2d", 2)[0]
    # Axisymmetric and 3D at the same h and a: L_f, D_f, D (cm), and the 3D diameters over their
    # own t = 0 values (the quarter disc's lattice reads 4.25 % wide at t = 0).
    m["taylor_ax"] = taylor("mpm_taylor_bar_axisymmetric", 2)
    m["taylor_3d"] = taylor("mpm_taylor_bar_3d", 3)
    initial_3d = taylor("mpm_taylor_bar_3d", 3, "--initial")
    m["taylor_3d_corrected"] = [v * 0.782 / i if k > 0 else v
                                for k, (v, i) in enumerate(zip(m["taylor_3d"], initial_3d))]
    # §5.6 and §5.7, the I-section frames (doc/verification/frames.md).
    def period(time, u):
        c = (max(u) + min(u)) / 2
        z = [t0 + (t1 - t0) * (c - u0) / (u1 - u0)
             for t0, t1, u0, u1 in zip(time, time[1:], u, u[1:]) if (u0 - c) * (u1 - c) < 0]
        return 2 * (z[-1] - z[0]) / (len(z) - 1), c
    c = out("portal_frame_elastic", "compare", "average_0.csv")
    m["pf_period_fem"], m["pf_mean_fem"] = period(c["time"], c["u_x_FEM"])
    m["pf_period_mpm"], _ = period(c["time"], c["u_x_MPM"])
    m["pf_period_fem"], m["pf_period_mpm"], m["pf_mean_fem"] = (1e3 * m["pf_period_fem"], 1e3 * m["pf_period_mpm"],
                                                                1e3 * m["pf_mean_fem"])
    c = out("compare_portal_frame", "compare", "average_0.csv")
    m["pf_peaks"] = [1e3 * max(c["u_x_MPM"]), 1e3 * max(c["u_x_FEM"])]
    m["pf_first"] = 100 * max(abs(d) for t, d in zip(c["time"], c["u_x_diff"]) if t < 0.04) / max(c["u_x_FEM"])
    m["pf_all"] = 100 * max(abs(d) for d in c["u_x_diff"]) / max(c["u_x_FEM"])
    def closing(c, method):
        return [-(a + b) / math.sqrt(2) for a, b in zip(c["u_x_" + method], c["u_y_" + method])]
    c = out("frame_corner_elastic", "compare", "average_0.csv")
    m["fc_k_fem"] = 400e3 / closing(c, "FEM")[-1] / 1e7
    m["fc_elastic"] = 100 * (closing(c, "MPM")[-1] / closing(c, "FEM")[-1] - 1)
    c = out("compare_frame_corner", "compare", "average_0.csv")
    mpm, fem = closing(c, "MPM"), closing(c, "FEM")
    m["fc_peaks"] = [1e3 * max(mpm), 1e3 * max(fem)]
    m["fc_set"] = [1e3 * mpm[-1], 1e3 * fem[-1]]
    return m


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------
def figures(args, work):
    exe = os.path.join(args.build, "hysteron")
    scripts = os.path.join(ROOT, "doc", "scripts")
    logs = os.path.join(work, "logs")
    study = os.path.join(work, "perforated_plate_study")
    cases = ["2:0.05:80", "1:0.1:40", "1:0.025:40", "1:0.0125:40", "2:0.1:40", "2:0.0125:40", "2:0.025:320"]
    jobs = [
        Job("make_figures.sh", ["bash", os.path.join(scripts, "make_figures.sh"), exe],
            log=os.path.join(logs, "make_figures.log")),
        Job("make_compare_figures.sh", ["bash", os.path.join(scripts, "make_compare_figures.sh"), exe,
                                        os.path.join(work, "runs")],
            log=os.path.join(logs, "make_compare_figures.log")),
        Job("perforated_plate_study.sh", ["bash", os.path.join(scripts, "perforated_plate_study.sh"), exe, study,
                                          *cases], log=os.path.join(work, "perforated_plate_study.md")),
        Job("make_rbsn_figures.py", [PY, os.path.join(scripts, "make_rbsn_figures.py"), exe],
            log=os.path.join(logs, "make_rbsn_figures.log")),
        Job("make_frame_figures.sh", ["bash", os.path.join(scripts, "make_frame_figures.sh"), exe,
                                      os.path.join(work, "runs")],
            log=os.path.join(logs, "make_frame_figures.log")),
    ]
    run_jobs(jobs, args.jobs, args.core)
    fail_on(jobs)
    # The study's curves (the report's figure also holds a force-controlled run, which the study
    # script does not make, so its curves stay in the work directory).
    subprocess.run([PY, os.path.join(scripts, "plot_perforated_plate.py"), "--out",
                    os.path.join(work, "perforated_plate_study.png"),
                    *[os.path.join(study, "p{}_h{}_N{}".format(*c.split(":"))) for c in cases]],
                   check=True, env=ENV, stdout=subprocess.DEVNULL)
    for name, target in (("velocity_gradient", "doc/mpm/velocity_gradient.png"),
                         ("cantilever_mesh_study", "doc/rbsn/cantilever_mesh_study.png")):
        tmp = os.path.join(ROOT, target + ".tmp.png")
        shutil.copy(os.path.join(work, "studies", name + ".png"), tmp)
        os.replace(tmp, os.path.join(ROOT, target))
    return jobs


# --------------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------------
def f(x, digits):
    """Fixed-point with `digits` decimals ("-0" printed as "0")."""
    text = f"{x:.{digits}f}"
    return text[1:] if re.fullmatch(r"-0\.?0*", text) else text.replace("-", "−")


def e(x, digits):
    """Scientific notation: 1.12546e7, 3e-15; exactly zero prints as 0."""
    if x == 0:
        return "0"
    mantissa, exponent = f"{x:.{digits}e}".split("e")
    return f"{mantissa.replace('-', '−')}e{int(exponent)}"


def pct(x, digits):
    """A signed relative difference in per cent: +2.6 %, −0.5 %."""
    return ("+" if x >= 0 else "−") + f"{abs(100 * x):.{digits}f} %"


def join(values, digits, separator=", "):
    return separator.join(f(v, digits) for v in values)


def machine_info(args, started, jobs, command):
    scenes = [j for j in jobs if j.seconds is not None]
    return dict(
        environment(args.build, ROOT),
        date=started.strftime("%Y-%m-%d %H:%M UTC"), command=command,
        runs=(f"{len(scenes)} runs ({len(SCENES)} scenes with their `# CHECK` lines, 2 studies, "
              f"{len(VARIANTS)} variants), all passed; {sum(j.seconds for j in scenes) / 60:.1f} min of run time, "
              f"{args.jobs} at a time pinned to core {args.core}; whole script {{minutes}} min wall, "
              f"{{cpu}} min CPU"
              + ("; figures not redrawn (--skip-figures)" if args.skip_figures else "; figures redrawn")))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build", help="a build directory holding hysteron (Release for the timings)")
    parser.add_argument("--jobs", type=int, default=1, help="runs at a time (all on --core)")
    parser.add_argument("--core", type=int, default=0, help="the core every run is pinned to (taskset)")
    parser.add_argument("--skip-figures", action="store_true")
    parser.add_argument("--workdir", help="keep every run here (default: a new temporary directory)")
    parser.add_argument("--doc", default=os.path.join(ROOT, "doc", "verification.md"))
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    if not os.access(os.path.join(args.build, "hysteron"), os.X_OK):
        raise SystemExit(f"make_verification_report.py: no hysteron executable in {args.build}")
    start, started = time.time(), datetime.datetime.utcnow()
    work = os.path.abspath(args.workdir) if args.workdir else tempfile.mkdtemp(prefix="hysteron_verification_")
    os.makedirs(work, exist_ok=True)
    template = open(os.path.join(ROOT, "doc", "verification.md.in")).read()
    command = " ".join(["doc/scripts/make_verification_report.py",
                        *[a if a != args.build else os.path.relpath(a, ROOT) if a.startswith(ROOT) else a
                          for a in sys.argv[1:]]])
    print(f"runs, outputs and logs in {work}", flush=True)

    jobs = jobs_of(args, work)
    run_jobs(jobs, args.jobs, args.core)
    fail_on(jobs)
    values = measure(work, jobs)
    if not args.skip_figures:
        figures(args, work)

    info = machine_info(args, started, jobs, command)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    info["runs"] = (info["runs"].replace("{minutes}", f"{(time.time() - start) / 60:.1f}")
                    .replace("{cpu}", f"{(usage.ru_utime + usage.ru_stime) / 60:.1f}"))
    namespace = dict(values, info=info, f=f, e=e, pct=pct, join=join)
    text = fill(template, namespace, "make_verification_report.py")
    write_atomically(os.path.abspath(args.doc), text)
    print(f"wrote {args.doc} in {(time.time() - start) / 60:.1f} min", flush=True)


if __name__ == "__main__":
    main()
