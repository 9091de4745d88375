#!/usr/bin/python3
"""Final shape of an MPM Taylor bar (dissertation §5.8, Table 5-1) from output/particles.csv.

Usage:
    doc/scripts/taylor_bar_metrics.py output/particles.csv 2     # 2D: axis x = 0, wall y = 0
    doc/scripts/taylor_bar_metrics.py output/particles.csv 3     # 3D: axis x = y = 0, wall z = 0
    doc/scripts/taylor_bar_metrics.py output/particles.csv 2 --points --height 0.0025
    doc/scripts/taylor_bar_metrics.py output/particles.csv 3 --initial   # the same at t = 0

Prints three numbers in cm on one line: L_f D_f D (D at --height above the wall, default
0.25 cm), then nothing else, so that the output can be read by other scripts.

Conventions (the scene files prm/mpm_taylor_bar_2d.prm, prm/mpm_taylor_bar_axisymmetric.prm
and doc/scenes/mpm_taylor_bar_3d.prm follow them):
  - the bar axis is x = 0 (2D) or x = y = 0 (3D), the wall is the lowest grid face, the axial
    coordinate is the last one (x_y in 2D, x_z in 3D); half (2D) and quarter (3D) models with
    symmetry planes through the axis as well as full models work, since only the distance
    r = |x| (2D) or sqrt(x^2 + y^2) (3D) from the axis is used;
  - dp is the initial point spacing, the smallest non-zero gap between the initial axial
    coordinates X = x - u of the points;
  - L_f = max(axial) - min(axial) + dp: the distance between the extreme points plus one
    point spacing (each point stands for a cell of size dp, so this is exactly L0 at t = 0);
  - D_f = 2 (max r + dp / 2) over the points of the bottom layer (axial < min(axial) + dp):
    the footprint diameter at the wall;
  - D = 2 (max r + dp / 2) over the points with |axial - (base + height)| <= dp / 2 (if that
    band is empty, the nearest layer of points), base = min(axial) - dp / 2 the bottom surface
    of the bar (not the wall: the bar may have rebounded off it by a fraction of a mm).
With --points the dissertation's convention is used instead: distances between the furthest
material points, no dp added (L_f = max - min of the axial coordinate, diameters 2 max r,
height measured from the lowest point).
The dp / 2 surface allowance is exact for undeformed straight boundaries and a first-order
estimate otherwise (in 3D, on the curved mantle, the point nearest the surface lies less than
dp / 2 inside it only on average). Report which convention was used.
With --initial the metrics are those of the initial positions X = x - u: exactly L0 and D0 in
2D (plane or axisymmetric), but D0 (1 + 0.0425) in 3D with 10 points across the radius, since
the outermost point of a quarter disc filled with a square lattice lies 0.925 dp inside the
mantle, not dp / 2: the 3D diameters carry this bias, and dividing by the --initial values
removes it.
"""
import argparse
import csv
import math
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv", help="particles.csv written with `Write particle table = true`")
    parser.add_argument("dimension", type=int, choices=(2, 3))
    parser.add_argument("--height", type=float, default=0.0025,
                        help="height of the diameter D above the bottom of the bar [m] (default 0.0025)")
    parser.add_argument("--points", action="store_true",
                        help="furthest-point distances (the dissertation's convention), no dp added")
    parser.add_argument("--initial", action="store_true",
                        help="the metrics of the initial positions x - u (the bias of the point lattice)")
    args = parser.parse_args()

    dim = args.dimension
    axial_name = "xyz"[dim - 1]
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{args.csv}: no points")
    for key in ("x_x", "x_" + axial_name, "u_" + axial_name):
        if key not in rows[0]:
            sys.exit(f"{args.csv}: no column {key} (is this a {dim}D particle table?)")

    def position(r, c):
        return float(r["x_" + c]) - (float(r["u_" + c]) if args.initial else 0.0)

    axial = [position(r, axial_name) for r in rows]
    if dim == 2:
        radius = [abs(position(r, "x")) for r in rows]
    else:
        radius = [math.hypot(position(r, "x"), position(r, "y")) for r in rows]

    initial_axial = sorted({round(float(r["x_" + axial_name]) - float(r["u_" + axial_name]), 12)
                            for r in rows})
    gaps = [b - a for a, b in zip(initial_axial, initial_axial[1:]) if b - a > 1e-12]
    dp = min(gaps) if gaps else 0.0
    add = 0.0 if args.points else dp

    bottom = min(axial)
    length = max(axial) - bottom + add
    foot = [r for r, z in zip(radius, axial) if z < bottom + max(dp, 1e-12)]
    footprint = 2 * max(foot) + add
    level = bottom - 0.5 * add + args.height
    band = [r for r, z in zip(radius, axial) if abs(z - level) <= 0.5 * dp]
    if not band:
        nearest = min(abs(z - level) for z in axial)
        band = [r for r, z in zip(radius, axial) if abs(z - level) <= nearest + 1e-12]
    diameter = 2 * max(band) + add
    print(f"{100 * length:.4f} {100 * footprint:.4f} {100 * diameter:.4f}")


if __name__ == "__main__":
    main()
