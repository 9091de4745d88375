#!/usr/bin/env python3
"""The Bouc-Wen family's laws as RBSN springs (Material/Bouc-Wen/Uniaxial law).

One facet between two cells, pulled and turned back and forth (tests/rbsn_input's single-facet
scene): the asymmetric law with equal yield values is the smooth law with the backward Euler
integrator (the same implicit step), so the two runs give the same tables (to 1e-9 of each
column's largest value); with a compression yield ratio of 2 the facet's normal force at
the largest compression is larger in magnitude than at the largest tension; the pinching law
runs through the same path and its normal force stays within the undegraded bound
(1 - alpha) N_y + alpha k |delta|.

Usage: bouc_wen_family_springs.py HYSTERON WORKDIR
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "oscillator"))
from common import Checks, run, table  # noqa: E402
from table_comparison import compare_tables  # noqa: E402

SCENE = """set Dimension = 2
set Method = rbsn
set Body names = plate
set Boundary names = fix, move
subsection Material
  set Model = bouc-wen
  set Young's modulus = 210e9
  set Poisson's ratio = 0.3
  set Density = 7850
  set Stress state = plane stress
  subsection Bouc-Wen
    set Yield stress = 235e6
    set Post-yield stiffness ratio = 0.02
    set Smoothness n = 4
    set Integrator = backward euler
    set Tolerance = 1e-12
{law}
  end
end
subsection Body plate
  set Shape = rectangle(0, 0, 1, 0.5)
  set Thickness = 0.02
end
subsection Boundary fix
  set Type = fixed
  set Region = disk(0.25, 0.25, 0.01)
end
subsection Boundary move
  set Type = displacement
  set Region = disk(0.75, 0.25, 0.01)
  set Displacement = (5e-3 - 0.02*(y - 0.25))*sin(pi*t/2); 0.02*(x - 0.5)*sin(pi*t/2)
end
subsection RBSN
  set Minimum distance = 1
  set Points on the boundary = false
  set Additional points = 0.25, 0.25; 0.75, 0.25
  set Number of increments = 300
end
subsection Time
  set End time = 3
end
subsection Output
  set Directory = {name}
  set Probe points = 0.75, 0.25
  set Write VTU = false
end
"""


def scene(name, law=""):
    return SCENE.replace("{law}", law).replace("{name}", name)


def main():
    hysteron, workdir = sys.argv[1], sys.argv[2]
    c = Checks()
    run(hysteron, workdir, "smooth", scene("smooth"))
    run(hysteron, workdir, "asymmetric", scene("asymmetric", "    set Uniaxial law = asymmetric"))
    failures = compare_tables("asymmetric r_c = 1", os.path.join(workdir, "smooth"), os.path.join(workdir, "asymmetric"), 1e-9, 1e-12)
    c.check(not failures, "asymmetric with r_c = 1 gives the smooth backward-Euler tables" + "".join("\n  " + f for f in failures))

    run(hysteron, workdir, "asymmetric2", scene("asymmetric2", """    set Uniaxial law = asymmetric
    subsection Asymmetric
      set Compression yield ratio = 2
    end"""))
    probe = table(os.path.join(workdir, "asymmetric2", "probe_0.csv"))
    smooth = table(os.path.join(workdir, "smooth", "probe_0.csv"))
    key = "f_n"  # the facet's normal force
    tension, compression = max(probe[key]), -min(probe[key])
    s_tension, s_compression = max(smooth[key]), -min(smooth[key])
    c.check(abs(tension - s_tension) <= 1e-9 * s_tension and compression > 1.5 * s_compression,
            f"r_c = 2: tension peak {tension:.6e} N as the smooth law's {s_tension:.6e}, compression peak "
            f"{compression:.6e} N beyond 1.5 x the smooth law's {s_compression:.6e}")

    run(hysteron, workdir, "pinching", scene("pinching", """    set Uniaxial law = pinching
    subsection Pinching
      set alpha = 0.02
      set n = 4
      set zeta_s = 0.8
      set delta_nu = 0.01
    end"""))
    pinched = table(os.path.join(workdir, "pinching", "probe_0.csv"))[key]
    c.check(max(abs(x) for x in pinched) <= max(s_tension, s_compression) * (1 + 1e-6) and min(pinched) < 0 < max(pinched),
            f"pinching: peak {max(abs(x) for x in pinched):.6e} N within the smooth law's {max(s_tension, s_compression):.6e} N")
    c.exit()


if __name__ == "__main__":
    main()
