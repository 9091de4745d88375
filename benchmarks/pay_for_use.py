#!/usr/bin/python3
"""A scene pays only for what it uses (issue 7): callgrind instruction counts.

Each case runs a small scene under `valgrind --tool=callgrind` and counts the instructions (Ir)
executed inside the time steps only. For the MPM that is `--toggle-collect` on
`MPM::Solver::advance`; set-up, output and MPI start-up are excluded. Instruction counts are
deterministic and independent of the machine's load, so a difference of 2 % is measurable. The
cases compare a scene against the same scene with one feature switched on or off:

  MPM (a 2D block of 3,200 Bouc-Wen points, plane strain, adaptive integrator, under gravity,
  40 steps):
  * degradation: c_eta = c_nu = 0 (off) against c_eta = 30, c_nu = 0.001 (on). The kernel that
    runs is named by its template flags, so the report lists it;
  * hardening: isotropic (m = 1: no back stress in the state) against mixed (m = 0.5) and
    kinematic (m = 0);
  * basis: linear against cubic B-splines;
  * empty grid cells: the block in its 48 x 24-cell grid against the same block in a grid
    with 9 times the cells (every cell outside the block empty);
  * output: VTU every step against no VTU (here the whole run is counted, not just the steps);
  * MPI on one rank: the instructions in MPI_* functions inside the steps, and in the whole run.
  RBSN (the §5.1 cantilever, 95 cells, 100 increments; the whole run is counted):
  * fracture: off against on with strengths that are never reached (the cost of the check);
    and the instructions in the fracture functions when off.

Writes OUT/pay_for_use.md (OUT = doc/benchmarks). Usage: benchmarks/pay_for_use.py BUILD_DIR [--out OUT]
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

BLOCK = """set Dimension = 2
set Method = mpm
set Body names = block
set Boundary names = base
set Gravity = 0, -9.81
subsection Material
  set Model = bouc-wen
  set Young's modulus = 1e6
  set Poisson's ratio = 0.3
  set Density = 1000
  set Stress state = plane strain
  subsection Bouc-Wen
    set Yield stress = 1e3
    set Integrator = adaptive
    set Isotropic hardening fraction = {m}
    subsection Degradation
      set Stiffness degradation c_eta = {c_eta}
      set Strength deterioration c_nu = {c_nu}
    end
  end
end
subsection Body block
  set Shape = rectangle(0, 0, 1, 0.5)
  set Particles per cell = 2
end
subsection Boundary base
  set Type = fixed
  set Faces = y-
end
subsection MPM
  subsection Grid
    set Lower corner = {lower}
    set Upper corner = {upper}
    set Cell size = 0.025
  end
  set Basis = {basis}
end
subsection Time
  set End time = 0.02
  set Time step = 5e-4
end
subsection Output
  set Directory = output
  set Write VTU = {vtu}
  set Interval = {interval}
end
"""


def block(m=1, c_eta=0, c_nu=0, basis="linear", lower="-0.1, 0", upper="1.1, 0.6", vtu="false", interval=0):
    return BLOCK.format(m=m, c_eta=c_eta, c_nu=c_nu, basis=basis, lower=lower, upper=upper, vtu=vtu,
                        interval=interval)


def callgrind(hysteron, work, name, text, toggle=None):
    """Ir of the run (inside `toggle` if given) and the profile's function lines."""
    d = os.path.join(work, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "scene.prm"), "w") as f:
        f.write(text)
    out = os.path.join(d, "callgrind.out")
    command = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
    if toggle:
        command.append(f"--toggle-collect={toggle}")
    p = subprocess.run(command + [hysteron, "--quiet", "scene.prm"], cwd=d, env=ENV, capture_output=True,
                       text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{name}: exit {p.returncode}\n{p.stderr[-3000:]}")
    a = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", out], capture_output=True,
                       text=True, check=True).stdout
    total = int(re.search(r"([0-9,]+) \(100\.0%\)\s+PROGRAM TOTALS", a).group(1).replace(",", ""))
    functions = []
    for line in a.splitlines():
        m = re.match(r"\s*([0-9,]+) \(\s*[0-9.]+%\)\s+\S*:(.*)$", line)
        if m:
            functions.append((int(m.group(1).replace(",", "")), m.group(2)))
    print(f"{name}: {total:,} Ir", flush=True)
    return total, functions


def inclusive(functions, pattern):
    """The largest inclusive count of the functions matching pattern (0 if none ran)."""
    values = [ir for ir, name in functions if re.search(pattern, name)]
    return max(values) if values else 0


def kernel(functions):
    names = [name for _, name in functions if "BoucWenKernels::Law<" in name]
    if not names:
        return "-"
    m = re.search(r"Law<\(hysteron::Material::StressState\)(\d), (\w+), (\w+)>", names[0])
    return f"Law<stress state {m.group(1)}, {m.group(2)}, {m.group(3)}>" if m else names[0][:60]


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build"))
    hysteron = os.path.join(build, "hysteron")
    rows = []
    with tempfile.TemporaryDirectory(prefix="pay_for_use_") as work:
        step = "*Solver<2>::advance*"
        base, f_base = callgrind(hysteron, work, "base", block(), step)

        on, f_on = callgrind(hysteron, work, "degradation", block(c_eta=30, c_nu=0.001), step)
        rows.append(("degradation", "c_eta = c_nu = 0 (off)", base, kernel(f_base), "c_eta = 30, c_nu = 0.001 (on)", on,
                     kernel(f_on)))
        for m, label in ((0.5, "mixed, m = 0.5"), (0, "kinematic, m = 0")):
            ir, f = callgrind(hysteron, work, f"hardening_{m}", block(m=m), step)
            rows.append(("hardening", "isotropic, m = 1 (no back stress)", base, kernel(f_base), label, ir, kernel(f)))
        cubic, f_cubic = callgrind(hysteron, work, "cubic", block(basis="cubic B-spline"), step)
        rows.append(("basis", "linear", base, f"cubic B-spline code: {inclusive(f_base, 'CubicBSpline'):,} Ir",
                     "cubic B-spline", cubic, ""))
        big, f_big = callgrind(hysteron, work, "empty_cells", block(lower="-1.3, 0", upper="2.3, 1.8"), step)
        rows.append(("empty grid cells", "48 x 24 cells", base, "", "144 x 72 cells (8/9 empty)", big, ""))
        mpi_steps = sum(ir for ir, name in f_base if re.match(r"\s*(P?MPI_|ompi_|mca_)", name))

        # Whole runs: output and MPI.
        quiet, f_quiet = callgrind(hysteron, work, "run_no_vtu", block())
        loud, f_loud = callgrind(hysteron, work, "run_vtu", block(vtu="true", interval=5e-4))
        rows.append(("output (whole run)", "no VTU", quiet, f"write_fields: {inclusive(f_quiet, 'write_fields'):,} Ir",
                     "VTU every step (40 files)", loud, f"write_fields: {inclusive(f_loud, 'write_fields'):,} Ir"))
        mpi_run = inclusive(f_quiet, r"^\s*P?MPI_Allreduce") + inclusive(f_quiet, r"^\s*P?MPI_Bcast")

        # RBSN fracture.
        with open(os.path.join(ROOT, "prm", "rbsn_cantilever_plastic.prm")) as f:
            cantilever = f.read().replace("set Write VTU = true", "set Write VTU = false")
        fracture = cantilever.replace("  set Spring law = coupled",
                                      "  set Spring law = coupled\n  subsection Fracture\n    set Enabled = true\n"
                                      "    set Tensile strength = 1e12\n    set Cohesion = 1e12\n  end")
        off, f_off = callgrind(hysteron, work, "rbsn_fracture_off", cantilever)
        on, f_on = callgrind(hysteron, work, "rbsn_fracture_on", fracture)
        rows.append(("fracture (RBSN, whole run)", "off", off, f"facet_to_break: {inclusive(f_off, 'facet_to_break'):,} Ir",
                     "on, never reached", on, f"facet_to_break: {inclusive(f_on, 'facet_to_break'):,} Ir"))

    lines = ["# A scene pays only for what it uses: instruction counts", "",
             "`benchmarks/pay_for_use.py build` (valgrind's callgrind; scenes and method in the script's "
             "docstring). Ir: instructions executed, inside the MPM time steps unless the row says 'whole run'. "
             "Deterministic: they do not depend on the machine's load. Measured with the Release build "
             "(deal.II 9.4.1, Debian 12, x86-64).", "",
             "| feature | without | Ir | detail | with | Ir | detail | cost of the feature |",
             "|---|---|---|---|---|---|---|---|"]
    for feature, a_label, a, a_detail, b_label, b, b_detail in rows:
        lines.append(f"| {feature} | {a_label} | {a:,} | {a_detail} | {b_label} | {b:,} | {b_detail} | "
                     f"{100 * (b / a - 1):+.2f} % |")
    lines += ["", f"MPI on one rank: {mpi_steps:,} instructions in MPI functions inside the time steps; "
              f"{mpi_run:,} in MPI_Allreduce and MPI_Bcast over the whole run (set-up and output).", ""]
    out_dir = (sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv
               else os.path.join(ROOT, "doc", "benchmarks"))
    os.makedirs(out_dir, exist_ok=True)
    out = os.path.join(out_dir, "pay_for_use.md")
    with open(out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
