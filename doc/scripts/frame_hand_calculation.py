#!/usr/bin/env python3
"""Hand values of the two I-section frame scenes (doc/verification/frames.md).

Portal frame (prm/compare_portal_frame.prm): lateral stiffness of a fixed-base one-bay frame by
slope-deflection on the members' axes, the effective mass of the sway mode by Rayleigh's
quotient with the static deflected shape, the first period, the static and the peak top
displacement under the suddenly applied load, the members' moments at the peak; the two effects
the formula leaves out (shear deformation, the joints' finite size) as separate estimates.

Frame corner (prm/compare_frame_corner.prm): the moment at the corner per unit load, the load at
which the corner's section reaches its plastic moment, the elastic closing stiffness of the knee
(bending of both arms by virtual work).

Usage: doc/scripts/frame_hand_calculation.py        (prints the numbers quoted in the doc)
"""
import math

IN = 0.0254


def section(name, d, A, I, Z, S):
    return dict(name=name, d=d * IN, A=A * IN ** 2, I=I * IN ** 4, Z=Z * IN ** 3, S=S * IN ** 3)


# AISC tables (in, in^2, in^4, in^3).
W12x120 = section("W12x120", 13.1, 35.2, 1070, 186, 163)
W16x36 = section("W16x36", 15.9, 10.6, 448, 64.0, 56.5)
W30x108 = section("W30x108", 29.8, 31.7, 4470, 346, 299)


def simpson(f, n=2000):
    h = 1.0 / n
    return h / 3 * sum((1 if i in (0, n) else 4 if i % 2 else 2) * f(i * h) for i in range(n + 1))


def portal_frame():
    E, nu, rho, sy = 207e9, 0.3, 7850.0, 470e6
    G = E / (2 * (1 + nu))
    P = 444.82e3
    H, L = 3.6, 6.0                      # axes: base to beam axis, column axis to column axis
    H_top, L_clear = 3.8, 6.0 - 1.0 / 3  # outer height, beam between the columns' faces
    c, b = W12x120, W16x36
    Ic, Ib = c["I"], b["I"]
    r = Ib * H / (Ic * L)
    k = 24 * E * Ic / H ** 3 * (1 + 6 * r) / (4 + 6 * r)
    psi = 6 / (4 + 6 * r)                # theta H / Delta: joint rotation per sway
    theta = psi / H                      # per unit sway
    # Rayleigh: column shape u = Delta (N3 + psi N4) on [0, H], rigid translation above H;
    # beam: translation Delta and antisymmetric bending v = theta L (s - 3 s^2 + 2 s^3).
    phi2 = simpson(lambda s: (3 * s * s - 2 * s ** 3 + psi * (-s * s + s ** 3)) ** 2)
    mc, mb = rho * c["A"], rho * b["A"]
    m_total = 2 * mc * H_top + mb * L_clear
    m_eff = 2 * mc * (H * phi2 + (H_top - H)) + mb * L_clear * (1 + (theta * L) ** 2 / 210)
    T = 2 * math.pi * math.sqrt(m_eff / k)
    d_static = P / k
    # Moments per unit sway (slope-deflection), at the elastic peak 2 P / k:
    Mb_end = 6 * E * Ib * theta / L
    Mc_base = E * Ic / H * (6 / H - 2 * theta)
    Mc_top = E * Ic / H * (6 / H - 4 * theta)
    peak = 2 * d_static
    # Shear deformation (virtual work, web shear areas t D of the bands): columns carry P/2 each,
    # the beam 2 M_b / L.
    t_c, D_c, t_b, D_b = 0.01523290917, 1.0 / 3, 0.005402172727, 0.4
    Vb = 2 * Mb_end * d_static / L / P   # beam shear per unit load
    shear = H / (2 * G * t_c * D_c) + L * Vb ** 2 / (G * t_b * D_b)
    k_shear = 1 / (1 / k + shear)
    # Joints of finite size, taken rigid: the formula on the clear lengths (an upper bound).
    Hc, Lc = H_top - D_b, L_clear
    rc = Ib * Hc / (Ic * Lc)
    k_rigid = 24 * E * Ic / Hc ** 3 * (1 + 6 * rc) / (4 + 6 * rc)
    print("Portal frame (W12x120 columns, W16x36 beam, H = 3.6 m, L = 6.0 m on the axes)")
    print(f"  r = Ib H / (Ic L) = {r:.4f}, psi = theta H / Delta = {psi:.4f}")
    print(f"  k = 24 E Ic / H^3 (1 + 6 r) / (4 + 6 r) = {k:.5g} N/m")
    print(f"  mass: total {m_total:.2f} kg, columns {2 * mc * H_top:.1f}, beam {mb * L_clear:.1f}; "
          f"int phi^2 = {phi2:.4f}; effective {m_eff:.1f} kg")
    print(f"  T = 2 pi sqrt(m_eff / k) = {T * 1e3:.3f} ms")
    print(f"  static top displacement P / k = {d_static * 1e3:.3f} mm, elastic peak {peak * 1e3:.3f} mm")
    print(f"  at the peak: beam end moment {Mb_end * peak / 1e3:.1f} kN m (M_y {sy * b['S'] / 1e3:.1f}, "
          f"M_p {sy * b['Z'] / 1e3:.1f}); column base {Mc_base * peak / 1e3:.1f}, top "
          f"{Mc_top * peak / 1e3:.1f} kN m (M_y {sy * c['S'] / 1e3:.1f}, M_p {sy * c['Z'] / 1e3:.1f})")
    print(f"  with shear deformation: k = {k_shear:.5g} N/m ({k_shear / k - 1:+.1%}), "
          f"T {T * math.sqrt(k / k_shear) * 1e3:.3f} ms")
    print(f"  rigid joints (clear lengths {Hc:.3f} m, {Lc:.3f} m): k = {k_rigid:.5g} N/m "
          f"({k_rigid / k - 1:+.1%}), T {T * math.sqrt(k / k_rigid) * 1e3:.3f} ms")


def frame_corner():
    E, rho, sy = 200e9, 7850.0, 248e6
    s = W30x108
    D = 0.75                     # modelled depth
    X = 3.0                      # outer size of the L: arms from the corner's outer faces
    a = X - D / 2                # axis length of each arm, corner axis point to the arm's end
    lever = a / math.sqrt(2)     # distance of the corner's axis point from the load's line
    M_per_P = lever
    Pp = sy * s["Z"] / lever
    Py = sy * s["S"] / lever
    # Closing displacement along the load's line by virtual work (the unit load is the load's
    # direction): in each arm the moment at a distance x from its end is P x / sqrt 2, the shear
    # and the axial force P / sqrt 2, so per unit P
    #   delta = 2 [a^3 / (6 E I) + a / (2 G A_s) + a / (2 E A)],
    # with the web's shear area A_s = t D of the band (t = 0.0114114 m, D = 0.75 m).
    G = E / 2.6
    bending = a ** 3 / (3 * E * s["I"])
    shear = a / (G * 0.01141140772 * D)
    axial = a / (E * s["A"])
    flex = bending + shear + axial
    m_total = rho * s["A"] * (X + (X - D))
    print("Frame corner (W30x108, A36: E = 200 GPa, sigma_y = 248 MPa; outer size 3.0 m x 3.0 m)")
    print(f"  arm axis length {a:.3f} m, lever arm of the corner {lever:.4f} m (M = {M_per_P:.4f} P)")
    print(f"  first yield at P = {Py / 1e3:.1f} kN, plastic moment at P = {Pp / 1e3:.1f} kN "
          "(bending only; the axial force P / sqrt 2 lowers it by a few per cent)")
    print(f"  elastic closing stiffness: bending only {1 / bending:.5g} N/m; with shear and axial "
          f"{1 / flex:.5g} N/m (compliances {bending:.4g}, {shear:.4g}, {axial:.4g} m/N)")
    print(f"  mass {m_total:.2f} kg")


if __name__ == "__main__":
    portal_frame()
    print()
    frame_corner()
