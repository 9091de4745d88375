#!/usr/bin/env python3
"""The out-of-plane thickness that makes a 2D band of depth D bend like a steel I-section.

A 2D model of an I-beam (MPM, FEM or RBSN, `Body <name>/Thickness`) is a band of depth D in the
plane. Its web keeps the real web thickness t_w; its two outer layers of depth a (the "modelled
flanges": the outermost row of material points, or the outermost elements) get a larger
thickness b chosen so that the band's second moment of area equals the section's:

    I = t_w (D - 2 a)^3 / 12 + 2 b [a^3 / 12 + a (D - a)^2 / 4]
    b = (I - t_w (D - 2 a)^3 / 12) / (2 [a^3 / 12 + a (D - a)^2 / 4])

The section's I is computed from its plates (web t_w (D - 2 t_f)^3 / 12, flanges
2 [b_f t_f^3 / 12 + b_f t_f (D - t_f)^2 / 4]; fillets ignored), or taken from a steel table with
--I. With a = t_f the band is the section itself (b = b_f). The band's area,
t_w (D - 2 a) + 2 a b, is printed beside the section's: the axial stiffness is matched only when
a = t_f.

With --match-area the web's thickness is solved for as well: the two thicknesses (b of the outer
layers, t of the web) give the band both the section's I and its area A (from the plates, or
--A from a steel table), so that its mass and axial stiffness are the section's too:

    t (D - 2 a) + 2 a b = A,   t (D - 2 a)^3 / 12 + 2 b [a^3 / 12 + a (D - a)^2 / 4] = I,

a 2 x 2 linear system (a negative t or b is refused: choose another a).

Prints b and a muParser expression for `Thickness` (the band centred at y = --centre, its axis
along x; --axis y for a column along y).

Usage: i_section_thickness.py D b_f t_f t_w --flange-depth a [--I I] [--A A] [--match-area]
                              [--centre c] [--axis x|y]
Example (W30x108 in metres, a 19 mm modelled flange):
    scripts/i_section_thickness.py 0.757 0.267 0.0193 0.0138 --flange-depth 0.019
"""
import argparse
import sys


def section_inertia(D, b_f, t_f, t_w):
    """Second moment of area of the plates of an I-section about its strong axis."""
    return t_w * (D - 2 * t_f) ** 3 / 12 + 2 * (b_f * t_f ** 3 / 12 + b_f * t_f * (D - t_f) ** 2 / 4)


def equivalent_thickness(I, D, t_w, a):
    """The thickness b of the two outer layers of depth a that gives the band of depth D the
    second moment I, the web keeping t_w."""
    web = t_w * (D - 2 * a) ** 3 / 12
    per_b = 2 * (a ** 3 / 12 + a * (D - a) ** 2 / 4)
    return (I - web) / per_b


def section_area(D, b_f, t_f, t_w):
    """Area of the plates of an I-section."""
    return t_w * (D - 2 * t_f) + 2 * b_f * t_f


def area_and_inertia_thicknesses(A, I, D, a):
    """The thicknesses (b, t) of the outer layers of depth a and of the web that give the band of
    depth D the area A and the second moment I."""
    web_area, flange_area = D - 2 * a, 2 * a
    web_inertia = (D - 2 * a) ** 3 / 12
    flange_inertia = 2 * (a ** 3 / 12 + a * (D - a) ** 2 / 4)
    det = web_area * flange_inertia - flange_area * web_inertia
    t = (A * flange_inertia - flange_area * I) / det
    b = (web_area * I - web_inertia * A) / det
    return b, t


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    for name in ("D", "b_f", "t_f", "t_w"):
        parser.add_argument(name, type=float)
    parser.add_argument("--flange-depth", type=float, required=True,
                        help="depth a of the modelled flanges (the outer layers)")
    parser.add_argument("--I", type=float, help="the section's second moment (steel table); "
                        "default: computed from the plates")
    parser.add_argument("--A", type=float, help="the section's area (steel table); "
                        "default: computed from the plates")
    parser.add_argument("--match-area", action="store_true",
                        help="solve for the web's thickness too, so that the band has the "
                        "section's area as well as its I")
    parser.add_argument("--centre", type=float, default=0.0, help="coordinate of the band's axis")
    parser.add_argument("--axis", choices=("x", "y"), default="x", help="the member's axis")
    args = parser.parse_args(argv)
    D, b_f, t_f, t_w, a = args.D, args.b_f, args.t_f, args.t_w, args.flange_depth
    if not (D > 0 and b_f > 0 and 0 < t_f < D / 2 and 0 < t_w and 0 < a < D / 2):
        sys.exit("i_section_thickness: need D, b_f, t_f, t_w > 0, t_f < D/2 and 0 < a < D/2")
    I = args.I if args.I else section_inertia(D, b_f, t_f, t_w)
    A = args.A if args.A else section_area(D, b_f, t_f, t_w)
    if args.match_area:
        b, t_w = area_and_inertia_thicknesses(A, I, D, a)
        if not (b > 0 and t_w > 0):
            sys.exit(f"i_section_thickness: no positive thicknesses match A = {A:g} and I = {I:g} "
                     f"(b = {b:g}, t = {t_w:g}): choose another flange depth")
    else:
        b = equivalent_thickness(I, D, t_w, a)
    if not b > 0:
        sys.exit(f"i_section_thickness: the web alone is stiffer than the section (I = {I:g}): "
                 "choose a thinner modelled flange")
    across = "y" if args.axis == "x" else "x"
    print(f"I          = {I:.10g}")
    print(f"b (flange) = {b:.10g}")
    if args.match_area:
        print(f"t (web)    = {t_w:.10g}")
    print(f"area: band {t_w * (D - 2 * a) + 2 * a * b:.10g}, section {A:.6g}")
    web = f"{t_w:.10g}" if args.match_area else f"{t_w:g}"
    print(f"Thickness  = abs({across} - {args.centre:g}) > {D / 2 - a:.10g} ? {b:.10g} : {web}")


if __name__ == "__main__":
    main()
