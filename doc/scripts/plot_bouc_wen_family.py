#!/usr/bin/env python3
"""doc/figures/bouc_wen_family.png: the Bouc-Wen family's uniaxial laws (doc/theory.md).

Left: the four relatives of `Bouc-Wen/Uniaxial law` and the smooth law on the uniaxial bench
under the same growing strain cycles. Right: the storey of prm/oscillator_record.prm (smooth
law) and of prm/oscillator_pinching.prm (pinching) under the synthetic record.

Usage: plot_bouc_wen_family.py HYSTERON [--out doc/figures]. Uses matplotlib's Agg backend.
"""
import argparse
import csv
import os
import shutil
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

LAWS = {
    "smooth": "",
    "pinching": """    set Uniaxial law = pinching
    subsection Pinching
      set alpha = 0.05
      set n = 2
      set zeta_s = 0.85
      set p = 0.3
      set q = 0.1
      set psi_0 = 0.2
      set delta_nu = 0.005
      set delta_eta = 0.005
    end""",
    "asymmetric (r_c = 1.5)": """    set Uniaxial law = asymmetric
    subsection Asymmetric
      set Compression yield ratio = 1.5
    end""",
    "OpenSees BoucWen": """    set Uniaxial law = OpenSees BoucWen
    subsection OpenSees BoucWen
      set alpha = 0.05
      set n = 2
      set gamma = 5e5
      set beta = 5e5
      set deltaNu = 5e-7
      set deltaEta = 5e-7
    end""",
    "OpenSees BoucWenOriginal": """    set Uniaxial law = OpenSees BoucWenOriginal
    subsection OpenSees BoucWenOriginal
      set alphaL = 0.05
      set alphaNL = 20
      set mu = 2
      set eta = 2
    end""",
}


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def bench(hysteron, workdir, name, entries):
    text = f"""set Dimension = 2
set Method = uniaxial
subsection Material
  set Young's modulus = 200e9
  subsection Bouc-Wen
    set Yield stress = 200e6
    set Post-yield stiffness ratio = 0.05
    set Smoothness n = 2
{entries}
  end
end
subsection Uniaxial
  set Strain = 4e-3*t/3*sin(2*pi*t)
  set End time = 3
  set Steps = 3000
end
subsection Output
  set Directory = out_{name}
end
"""
    with open(os.path.join(workdir, name + ".prm"), "w") as f:
        f.write(text)
    subprocess.run([os.path.abspath(hysteron), "--quiet", name + ".prm"], cwd=workdir, check=True)
    return columns(os.path.join(workdir, "out_" + name, "history.csv"))


def storey(hysteron, workdir, scene):
    shutil.copy(os.path.join(ROOT, "prm", scene), workdir)
    os.makedirs(os.path.join(workdir, "records"), exist_ok=True)
    shutil.copy(os.path.join(ROOT, "prm", "records", "synthetic_kanai_tajimi.AT2"), os.path.join(workdir, "records"))
    subprocess.run([os.path.abspath(hysteron), "--quiet", scene], cwd=workdir, check=True)
    return columns(os.path.join(workdir, "output", scene[:-4], "history.csv"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("hysteron")
    parser.add_argument("--out", default=os.path.join(ROOT, "doc", "figures"))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as workdir:
        fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4))
        for i, (name, entries) in enumerate(LAWS.items()):
            h = bench(args.hysteron, workdir, f"law{i}", entries)
            left.plot([e * 1e3 for e in h["eps"]], [s / 1e6 for s in h["sig"]], lw=0.9, label=name)
        left.set_xlabel("strain [‰]")
        left.set_ylabel("stress [MPa]")
        left.set_title("uniaxial bench: E = 200 GPa, σ_y = 200 MPa")
        left.grid(alpha=0.3)
        left.legend(fontsize=8)
        for scene, label in (("oscillator_record.prm", "smooth"), ("oscillator_pinching.prm", "pinching")):
            h = storey(args.hysteron, workdir, scene)
            right.plot([u * 1e3 for u in h["u_1"]], [f / 1e3 for f in h["F_1"]], lw=0.7, label=label)
        right.set_xlabel("storey drift [mm]")
        right.set_ylabel("storey force [kN]")
        right.set_title("storey under the synthetic record (0.3 g)")
        right.grid(alpha=0.3)
        right.legend(fontsize=8)
        fig.tight_layout()
        os.makedirs(args.out, exist_ok=True)
        target = os.path.join(args.out, "bouc_wen_family.png")
        fig.savefig(target + ".tmp.png", dpi=110)
        os.replace(target + ".tmp.png", target)
        print("wrote", target)


if __name__ == "__main__":
    main()
