#!/usr/bin/env python3
"""scripts/i_section_thickness.py: the thickness of the modelled flanges of a 2D I-beam.

1. With the modelled flange as deep as the real one (a = t_f) the band is the section: b = b_f.
2. W30x108 (AISC: D = 29.8 in, b_f = 10.5 in, t_f = 0.760 in, t_w = 0.545 in): the plates give
   I = 0.545 * 28.28^3 / 12 + 2 (10.5 * 0.76^3 / 12 + 10.5 * 0.76 * 29.04^2 / 4) = 4392.8 in^4
   (the table's 4470 in^4 includes the fillets); with the table's I and a = 1 in,
   b = (4470 - 0.545 * 27.8^3 / 12) / (2 (1 / 12 + 28.8^2 / 4)) = 8.4222 in.
2b. With --match-area the web's thickness is solved for too: the band has the table's I and A
   (the W12x120 of prm/compare_portal_frame.prm: b = 0.2797128133 m, t = 0.01523290917 m).
3. The printed expression is a valid `Thickness`: the FEM weight of a 3 m band of that section
   (D = 0.757 m, Q2 elements whose rows end at the flange, gravity) is rho g L times the band's
   area as printed, to 1e-9.

Usage: i_section_thickness.py HYSTERON WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

hysteron, work = sys.argv[1:3]
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
script = os.path.join(root, "scripts", "i_section_thickness.py")
failures = []


def run(*args):
    p = subprocess.run([sys.executable, script, *map(str, args)], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{script} {args}: exit {p.returncode}: {p.stderr}")
    b = float(re.search(r"^b \(flange\)\s*=\s*(\S+)", p.stdout, re.M).group(1))
    I = float(re.search(r"^I\s*=\s*(\S+)", p.stdout, re.M).group(1))
    area = float(re.search(r"area: band (\S+),", p.stdout).group(1))
    expression = re.search(r"^Thickness\s*=\s*(.*)$", p.stdout, re.M).group(1)
    return I, b, area, expression


def close(name, value, expected, tolerance):
    if abs(value - expected) > tolerance * abs(expected):
        failures.append(f"{name}: {value} against {expected} (tolerance {tolerance})")


I, b, _, _ = run(0.3, 0.15, 0.012, 0.008, "--flange-depth", 0.012)
close("a = t_f gives b_f", b, 0.15, 1e-5)

I, b, _, _ = run(29.8, 10.5, 0.76, 0.545, "--flange-depth", 0.76)
close("W30x108 plates I", I, 0.545 * 28.28 ** 3 / 12 + 2 * (10.5 * 0.76 ** 3 / 12 + 10.5 * 0.76 * 29.04 ** 2 / 4), 1e-5)
close("W30x108 plates I (hand)", I, 4392.8, 1e-5)
I, b, _, _ = run(29.8, 10.5, 0.76, 0.545, "--flange-depth", 1, "--I", 4470)
close("W30x108, table I, a = 1 in", b, 8.4222, 1e-4)

# 2b. --match-area: the web's thickness is solved for too, so that the band has the table's I
# and A (W12x120 of prm/compare_portal_frame.prm: D = 1/3 m, a = 1/30 m); its area and second
# moment, recomputed from b and t, are the table's.
out = subprocess.run([sys.executable, script] + [str(v) for v in (
    1 / 3, 0.3124, 0.0281, 0.018, "--flange-depth", 1 / 30, "--I", 4.453676e-4, "--A", 0.02270963,
    "--match-area")], capture_output=True, text=True).stdout
bm = float(re.search(r"^b \(flange\)\s*=\s*(\S+)", out, re.M).group(1))
tm = float(re.search(r"^t \(web\)\s*=\s*(\S+)", out, re.M).group(1))
Dm, am = 1 / 3, 1 / 30
close("match-area: area", tm * (Dm - 2 * am) + 2 * am * bm, 0.02270963, 1e-8)
close("match-area: I", tm * (Dm - 2 * am) ** 3 / 12 + 2 * bm * (am ** 3 / 12 + am * (Dm - am) ** 2 / 4), 4.453676e-4, 1e-8)
close("match-area: b (prm/compare_portal_frame.prm)", bm, 0.2797128133, 1e-8)
close("match-area: t (prm/compare_portal_frame.prm)", tm, 0.01523290917, 1e-8)

# 3. The expression in a scene: D = 0.757 m, a = D / 8 (Q2 elements of D / 8: the flange is
# the outer row of elements), centred on y = 0.
D = 0.757
I, b, area, expression = run(D, 0.267, 0.0193, 0.0138, "--flange-depth", D / 8, "--centre", 0)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
scene = f"""set Dimension = 2
set Method = fem
set Body names = beam
set Boundary names = clamp
set Gravity = 0, -9.81
subsection Material
  set Model = linear elastic
  set Young's modulus = 200e9
  set Poisson's ratio = 0.3
  set Density = 7850
  set Stress state = plane stress
end
subsection Body beam
  set Shape = rectangle(0, {-D / 2!r}, 3, {D / 2!r})
  set Thickness = {expression}
end
subsection Boundary clamp
  set Type = fixed
  set Faces = x-
end
subsection FEM
  set Degree = 2
  set Number of increments = 1
  subsection Mesh
    set Cell size = {D / 8!r}
  end
end
subsection Output
  set Directory = output
  set Write VTU = false
end
"""
with open(os.path.join(work, "scene.prm"), "w") as f:
    f.write(scene)
p = subprocess.run([hysteron, "--quiet", "scene.prm"], cwd=work, capture_output=True, text=True)
if p.returncode != 0:
    sys.exit(f"the scene with Thickness = {expression}: exit {p.returncode}: {p.stderr}")
last = open(os.path.join(work, "output", "reactions.csv")).read().splitlines()
header, row = last[0].split(","), last[-1].split(",")
reaction = float(row[header.index("clamp_y")])
close("weight of the band", reaction, 7850 * 9.81 * 3 * area, 1e-9)

if failures:
    print("FAILED:\n  " + "\n  ".join(failures))
    sys.exit(1)
print("passed")
