#!/usr/bin/python3
"""Callgrind instruction counts of the MPM time steps for every update scheme and basis.

The scene is the Bouc-Wen block of benchmarks/pay_for_use.py (3,200 points, plane strain,
adaptive integrator, gravity, 40 steps), with `MPM/Scheme` set to each scheme and the basis
linear or cubic B-spline; plus the degradation case and the whole run of pay_for_use.py (MUSL).
Ir are counted inside `MPM::Solver<2>::advance` (`--toggle-collect`), as in pay_for_use.py.
Used for doc/benchmarks/refactor_cost.md (the cost of the update-scheme refactor).

Usage: benchmarks/mpm_scheme_cost.py BUILD_DIR [OUT.json] [--schemes MUSL,USL,USF,USAVG]
"""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pay_for_use as P  # noqa: E402


def with_scheme(text, scheme):
    return text.replace("  set Basis =", f"  set Scheme = {scheme}\n  set Basis =")


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    build = os.path.abspath(args[0] if args else os.path.join(P.ROOT, "build"))
    schemes = (sys.argv[sys.argv.index("--schemes") + 1].split(",") if "--schemes" in sys.argv
               else ["MUSL", "USL", "USF", "USAVG"])
    if "--schemes" in sys.argv:
        args = [a for a in args if a != sys.argv[sys.argv.index("--schemes") + 1]]
    hysteron = os.path.join(build, "hysteron")
    step = "*Solver<2>::advance*"
    cases = []
    for scheme in schemes:
        for basis in ("linear", "cubic B-spline"):
            cases.append((f"{scheme}, {basis}", with_scheme(P.block(basis=basis), scheme), step))
    if "MUSL" in schemes:
        cases.append(("MUSL, linear, degradation", with_scheme(P.block(c_eta=30, c_nu=0.001), "MUSL"), step))
        cases.append(("MUSL, linear, whole run (no VTU)", P.block(), None))
    result = {}
    with tempfile.TemporaryDirectory(prefix="mpm_scheme_cost_") as work:
        for i, (name, text, toggle) in enumerate(cases):
            result[name] = P.callgrind(hysteron, work, f"case{i}", text, toggle)[0]
    if len(args) > 1:
        with open(args[1], "w") as f:
            json.dump(result, f, indent=1)
    for name, ir in result.items():
        print(f"| {name} | {ir:,} |")


if __name__ == "__main__":
    main()
