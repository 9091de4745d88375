#!/usr/bin/python3
"""Independent elastic reference for the perforated plate of prm/fem_perforated_plate.prm.

    /usr/bin/python3 doc/scripts/perforated_plate_elastic_reference.py

(numpy and scipy: Debian's python3-numpy, python3-scipy). Plane stress, quarter model
x in [0, b0], y in [0, L] with a hole of radius R at the origin, thickness t. A code of
its own, sharing nothing with hysteron: biquadratic (9-node Lagrange) isoparametric
quadrilaterals on a mapped (transfinite) mesh between the hole and the outer boundary,
graded towards the hole, the hole made of quadratic arcs with every node on the circle
(the geometry converges to the exact circle), 3 x 3 Gauss points.
Symmetry: u = 0 on x = 0, v = 0 on y = 0; loaded edge y = L.

For a sequence of meshes it prints
  K       the stiffness F / delta for a prescribed v = delta on the loaded edge (u free),
  Kt_net  sigma_yy at the hole edge (R, 0) divided by the net-section stress F / (t (b0 - R)),
  P/v(0,L) the stiffness seen at the upper left node under a uniform traction on the loaded
          edge (force control: total force P over the displacement of (0, L)).
"""
import sys
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

E, nu, t = 72e9, 0.22, 0.025
b0, L, R = 0.25, 0.45, 0.125
D = E / (1 - nu * nu) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])


def outer(s):
    """Outer boundary from (b0, 0) up the right edge to (b0, L), then along the top to (0, L); s in [0, 1]."""
    P = L + b0
    d = s * P
    return np.where(d <= L, b0, b0 - (d - L)), np.where(d <= L, d, L)


def mesh(n_theta, n_r, grading=1.6):
    # Angle on the hole matched to the arc length parameter of the outer boundary (a
    # simple transfinite mapping); corner of the outer boundary at s_c = L / (L + b0).
    nt, nr = 2 * n_theta + 1, 2 * n_r + 1          # nodes (quadratic: 2 per element side)
    sc = L / (L + b0)                              # the corner (b0, L) is a node
    n1 = max(1, round(n_theta * sc))
    s = np.concatenate([np.linspace(0, sc, 2 * n1 + 1),
                        np.linspace(sc, 1, 2 * (n_theta - n1) + 1)[1:]])
    theta = s * np.pi / 2
    xo, yo = outer(s)
    xh, yh = R * np.cos(theta), R * np.sin(theta)
    r = np.linspace(0, 1, nr) ** grading           # grade towards the hole
    X = xh[None, :] + r[:, None] * (xo - xh)[None, :]
    Y = yh[None, :] + r[:, None] * (yo - yh)[None, :]
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    idx = np.arange(nr * nt).reshape(nr, nt)
    cells = []
    for i in range(n_r):
        for j in range(n_theta):
            b = idx[2 * i:2 * i + 3, 2 * j:2 * j + 3]
            cells.append(b.ravel())                # lexicographic 3x3 (xi fastest = theta)
    return nodes, np.array(cells), idx


def shape(xi, eta):
    l = lambda z: np.array([z * (z - 1) / 2, 1 - z * z, z * (z + 1) / 2])
    dl = lambda z: np.array([z - 0.5, -2 * z, z + 0.5])
    N = np.outer(l(eta), l(xi)).ravel()
    dNxi = np.outer(l(eta), dl(xi)).ravel()
    dNeta = np.outer(dl(eta), l(xi)).ravel()
    return N, np.vstack([dNxi, dNeta])


def solve(n_theta, n_r):
    nodes, cells, idx = mesh(n_theta, n_r)
    n = len(nodes)
    g = np.array([-np.sqrt(0.6), 0, np.sqrt(0.6)])
    w = np.array([5, 8, 5]) / 9
    rows, cols, vals = [], [], []
    for c in cells:
        xe = nodes[c]
        ke = np.zeros((18, 18))
        for a in range(3):
            for b in range(3):
                N, dN = shape(g[a], g[b])
                J = dN @ xe
                dNx = np.linalg.solve(J, dN)
                B = np.zeros((3, 18))
                B[0, 0::2] = dNx[0]
                B[1, 1::2] = dNx[1]
                B[2, 0::2] = dNx[1]
                B[2, 1::2] = dNx[0]
                ke += B.T @ D @ B * abs(np.linalg.det(J)) * w[a] * w[b] * t
        dofs = np.ravel(np.column_stack([2 * c, 2 * c + 1]))
        rows.append(np.repeat(dofs, 18))
        cols.append(np.tile(dofs, 18))
        vals.append(ke.ravel())
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(2 * n, 2 * n))
    x, y = nodes[:, 0], nodes[:, 1]
    tol = 1e-12
    fixed = {}
    for i in np.where(abs(x) < tol)[0]:
        fixed[2 * i] = 0.0
    for i in np.where(abs(y) < tol)[0]:
        fixed[2 * i + 1] = 0.0
    top = np.where(abs(y - L) < tol)[0]
    for i in top:
        fixed[2 * i + 1] = 1.0                  # delta = 1 m (linear problem)
    fd = np.array(sorted(fixed))
    fv = np.array([fixed[k] for k in fd])
    free = np.setdiff1d(np.arange(2 * n), fd)
    u = np.zeros(2 * n)
    u[fd] = fv
    rhs = -K[free][:, fd] @ fv
    u[free] = spla.spsolve(K[free][:, free].tocsc(), rhs)
    f = K @ u
    F = f[2 * top + 1].sum()
    # sigma_yy at the hole edge (R, 0): node idx[0, 0], corner xi = eta = -1 of the first cell
    c = cells[0]
    N, dN = shape(-1, -1)
    J = dN @ nodes[c]
    dNx = np.linalg.solve(J, dN)
    ue = u[np.ravel(np.column_stack([2 * c, 2 * c + 1]))]
    eps = np.array([dNx[0] @ ue[0::2], dNx[1] @ ue[1::2], dNx[1] @ ue[0::2] + dNx[0] @ ue[1::2]])
    s = D @ eps
    # Uniform traction p = 1 Pa on the top edge instead (force control): consistent
    # nodal forces of the quadratic edges (1/6, 4/6, 1/6 of each edge's force), v at (0, L).
    free2 = np.setdiff1d(np.arange(2 * n), np.array(sorted(k for k in fixed if fixed[k] == 0.0)))
    fext = np.zeros(2 * n)
    row = idx[-1, :]                               # outer ring: right edge then top edge
    for j in range(0, len(row) - 2, 2):
        a, m, b = row[j], row[j + 1], row[j + 2]
        if abs(y[a] - L) < tol and abs(y[b] - L) < tol:
            le = abs(x[a] - x[b]) * t
            for k, wk in ((a, 1 / 6), (m, 4 / 6), (b, 1 / 6)):
                fext[2 * k + 1] += wk * le
    u2 = np.zeros(2 * n)
    u2[free2] = spla.spsolve(K[free2][:, free2].tocsc(), fext[free2])
    corner = np.where((abs(x) < tol) & (abs(y - L) < tol))[0][0]
    P = fext.sum()                                 # = p t b0
    return F, s[1] / (F / (t * (b0 - R))), 2 * n, P / u2[2 * corner + 1]


if __name__ == "__main__":
    prev = None
    for m in [4, 8, 16, 32, 64]:
        F, k_net, ndof, Kc = solve(2 * m, m)
        line = (f"n_theta={2*m:4d} n_r={m:3d} dofs={ndof:7d} K={F:.6e} N/m  Kt_net={k_net:.4f}"
                f"  traction: P/v(0,L)={Kc:.6e} N/m")
        if prev:
            line += f"  dK/K={(F - prev) / F:+.2e}"
        prev = F
        print(line, flush=True)
