#!/usr/bin/python3
"""Regenerate the RBSN figures of doc/rbsn.md in doc/rbsn/ from the shipped scenes.

  doc/scripts/make_rbsn_figures.py [build/hysteron]

Runs (in a temporary directory, about 2 minutes on one core) the §5.1 cantilever (coupled and
uncoupled springs, d_m = 5 and 3 cm, and the FEM of prm/fem_cantilever_plastic.prm), the §5.2
cantilever with and without fracture, the §5.2 concrete beam (263 and 690 cells), the §3.7.4
perforated plate (d_m = 5, 3, 2 cm against the FEM reference of doc/verification/) and the
§5.3 titanium plate (192 and 1789 cells), and draws load curves and crack patterns (the cell
plots with doc/scripts/plot_rbsn_cells.py). Needs Debian's python3-matplotlib.
"""
import csv
import glob
import math
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "doc", "rbsn")
sys.path.insert(0, os.path.join(ROOT, "doc", "scripts"))


def set_entry(text, name, value):
    new, n = re.subn(rf"(?m)^(\s*set {re.escape(name)}\s*=).*$", rf"\g<1> {value}", text, count=1)
    if n != 1:
        raise RuntimeError(f"no entry '{name}'")
    return new


def end_points(d_m):
    n = max(1, math.ceil(0.1 / d_m - 1e-9))
    return "; ".join(f"{x}, {j * 0.1 / n:.12g}" for x in (0, 1) for j in range(n + 1))


def run(hysteron, work, name, scene, **entries):
    """Run prm/<scene>.prm with entries replaced in WORK/NAME; return the output directory."""
    with open(os.path.join(ROOT, "prm", scene + ".prm")) as f:
        text = f.read()
    for key, value in entries.items():
        text = set_entry(text, key.replace("_", " "), value)
    directory = os.path.join(work, name)
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "scene.prm"), "w") as f:
        f.write(text)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run([hysteron, "scene.prm"], cwd=directory, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{name}: exit {p.returncode}\n{p.stderr}")
    summary = re.search(r"\((\d+) cells", p.stdout)
    print(f"{name}: {summary.group(1) + ' cells' if summary else 'done'}", flush=True)
    return os.path.join(directory, "output")


def table(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def last_vtu(output):
    return sorted(glob.glob(os.path.join(output, "rbsn-*.vtu")))[-1]


def cells(vtu, png, **options):
    args = [sys.executable, os.path.join(ROOT, "doc", "scripts", "plot_rbsn_cells.py"), vtu, png]
    for key, value in options.items():
        args += [f"--{key}"] + ([str(v) for v in value] if isinstance(value, (list, tuple)) else [str(value)])
    subprocess.run(args, check=True)


def finish(fig, ax, name):
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, name), dpi=110)
    plt.close(fig)
    print("wrote doc/rbsn/" + name)


def cantilever(hysteron, work):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for law, style in (("coupled", "-"), ("uncoupled", "--")):
        for d_m, colour in ((0.05, "C1"), (0.03, "C0")):
            o = run(hysteron, work, f"cantilever_{law}_{d_m}", "rbsn_cantilever_plastic",
                    Spring_law=law, Minimum_distance=d_m, Additional_points=end_points(d_m), Write_VTU="false")
            r = table(os.path.join(o, "reactions.csv"))
            ax.plot([50 * t for t in r["time"]], [-v / 1e3 for v in r["tip_y"]], style, color=colour,
                    label=f"RBSN, {law} springs, d_m = {100 * d_m:g} cm")
    fem = os.path.join(work, "fem_cantilever")
    os.makedirs(fem, exist_ok=True)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run([hysteron, "--quiet", os.path.join(ROOT, "prm", "fem_cantilever_plastic.prm")], cwd=fem,
                   env=env, check=True)
    r = table(os.path.join(fem, "output", "reactions.csv"))
    ax.plot([30 * t for t in r["time"]], [-v / 1e3 for v in r["tip_y"]], "k-", lw=1, label="FEM, Q2 (hysteron)")
    for value, text in ((20, "P_y = 20 kN"), (30, "P_u = 30 kN")):
        ax.axhline(value, color="gray", ls=":", lw=1)
        ax.text(1, value + 0.4, text, fontsize=8, color="gray")
    ax.set_xlabel("tip deflection [mm]")
    ax.set_ylabel("tip load [kN]")
    ax.set_title("§5.1 cantilever: RBSN and FEM")
    finish(fig, ax, "cantilever_plastic.png")


def cantilever_fracture(hysteron, work):
    o = run(hysteron, work, "cantilever_fracture", "rbsn_cantilever_fracture")
    p = run(hysteron, work, "cantilever_no_fracture", "rbsn_cantilever_fracture", Enabled="false", Write_VTU="false")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for out, label in ((p, "plasticity only"), (o, "plasticity and fracture")):
        r = table(os.path.join(out, "reactions.csv"))
        ax.plot([100 * t for t in r["time"]], [-v / 1e3 for v in r["tip_y"]], label=label)
    ax.axhline(30, color="gray", ls=":", lw=1)
    ax.set_xlabel("tip deflection [mm]")
    ax.set_ylabel("tip load [kN]")
    ax.set_title("§5.2 cantilever, 95 cells, coupled springs, a = 2 %")
    finish(fig, ax, "cantilever_fracture_curve.png")
    cells(last_vtu(o), os.path.join(OUT, "cantilever_fracture.png"), field="H1", magnify=2, xlim=(-0.02, 0.35),
          ylim=(-0.08, 0.12), title="§5.2 cantilever at the clamp: broken facets (red), H1 at the end",
          label="H1")
    print("wrote doc/rbsn/cantilever_fracture.png")


def concrete(hysteron, work):
    for d_m in (0.025, 0.015):
        o = run(hysteron, work, f"concrete_{d_m}", "rbsn_concrete_beam_fracture", Minimum_distance=d_m)
        cells(last_vtu(o), os.path.join(work, f"concrete_{d_m}.png"), magnify=200,
              title=f"concrete beam, d_m = {1000 * d_m:g} mm: cracks (red)")
    # The two meshes one above the other.
    images = [plt.imread(os.path.join(work, f"concrete_{d}.png")) for d in (0.025, 0.015)]
    fig, axes = plt.subplots(2, 1, figsize=(8, 5.2))
    for ax, image in zip(axes, images):
        ax.imshow(image)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "concrete_beam_cracks.png"), dpi=110)
    plt.close(fig)
    print("wrote doc/rbsn/concrete_beam_cracks.png")


def perforated_plate(hysteron, work):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for d_m in (0.05, 0.03, 0.02):
        o = run(hysteron, work, f"plate_{d_m}", "rbsn_perforated_plate", Minimum_distance=d_m, Write_VTU="false")
        r = table(os.path.join(o, "reactions.csv"))
        ax.plot([4 * t for t in r["time"]], [v / 1e3 for v in r["top_y"]], label=f"RBSN, d_m = {100 * d_m:g} cm")
    with open(os.path.join(ROOT, "doc", "verification", "fem_perforated_plate_reference.csv")) as f:
        ref = [r for r in csv.DictReader(f) if r["control"] == "displacement"]
    ax.plot([1e3 * float(r["v_upper_left_m"]) for r in ref], [float(r["load_N"]) / 1e3 for r in ref], "k-", lw=1,
            label="FEM reference (doc/verification)")
    ax.axhline(818.75, color="gray", ls=":", lw=1)
    ax.text(2.5, 790, "F_lim = 818.75 kN", fontsize=8, color="gray")
    ax.set_xlabel("displacement of the top edge [mm]")
    ax.set_ylabel("load, quarter model [kN]")
    ax.set_title("§3.7.4 perforated plate: RBSN (coupled springs) and FEM")
    finish(fig, ax, "perforated_plate.png")


def titanium(hysteron, work):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for d_m in (0.003, 0.0009):
        o = run(hysteron, work, f"titanium_{d_m}", "rbsn_titanium_plate", Minimum_distance=d_m)
        r = table(os.path.join(o, "reactions.csv"))
        a, b = table(os.path.join(o, "probe_0.csv")), table(os.path.join(o, "probe_1.csv"))
        cod = [1e3 * (ya - yb) for ya, yb in zip(a["u_y"], b["u_y"])]
        ax.plot(cod, [v / 1e3 for v in r["top_y"]], label=f"d_m = {1000 * d_m:g} mm")
        if d_m < 0.001:
            cells(last_vtu(o), os.path.join(OUT, "titanium_plate_cracks.png"), magnify=1,
                  title="§5.3 titanium plate, 1789 cells: crack (red)", width=6)
            print("wrote doc/rbsn/titanium_plate_cracks.png")
    ax.axhline(28.65, color="gray", ls=":", lw=1)
    ax.text(0.05, 27.6, "net-section limit 28.65 kN", fontsize=8, color="gray")
    ax.set_xlabel("crack mouth opening displacement [mm]")
    ax.set_ylabel("load [kN]")
    ax.set_title("§5.3 titanium plate (assumed SENT geometry)")
    finish(fig, ax, "titanium_plate.png")


def main():
    hysteron = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "hysteron"))
    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rbsn_figures_") as work:
        cantilever(hysteron, work)
        cantilever_fracture(hysteron, work)
        concrete(hysteron, work)
        perforated_plate(hysteron, work)
        titanium(hysteron, work)


if __name__ == "__main__":
    main()
