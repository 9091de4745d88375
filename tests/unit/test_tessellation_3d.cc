// Unit tests of the 3D RBSN geometry (doc/rbsn/geometry_3d.md): the polyhedral
// domain, boundary and Poisson-disk nuclei, and the exactly clipped Voronoi cells
// (volumes and moments add up to the domain's, cells are closed, facets match).
#include <deal.II/base/timer.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/region.h>
#include "rbsn/tessellation.h"

#include "rbsn/polyhedron.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace
{
  using namespace hysteron;
  using dealii::Point;
  using Vector = dealii::Tensor<1, 3>;
  using Matrix = dealii::Tensor<2, 3>;

  Geometry::Region<3>
  parse(const std::string &expression)
  {
    return Geometry::Region<3>::parse(expression, "Body/solid/Shape");
  }

  /// Area times unit normal of a planar loop (ccw side).
  Vector
  area_vector(const std::vector<Point<3>> &loop)
  {
    Vector a;
    for (unsigned int k = 1; k + 1 < loop.size(); ++k)
      a += 0.5 * cross_product_3d(loop[k] - loop[0], loop[k + 1] - loop[0]);
    return a;
  }

  /// The moments int 1, int x, int x x^T of a box [lo, hi].
  struct Integrals
  {
    double volume = 0;
    Vector first;
    Matrix second;

    Integrals &
    operator+=(const Integrals &o)
    {
      volume += o.volume;
      first += o.first;
      second += o.second;
      return *this;
    }

    Integrals &
    operator-=(const Integrals &o)
    {
      volume -= o.volume;
      first -= o.first;
      second -= o.second;
      return *this;
    }
  };

  Integrals
  box_integrals(const Point<3> &lo, const Point<3> &hi)
  {
    // int x_i = V m_i; int x_i x_j = V m_i m_j (i != j); int x_i^2 = (hi^3 - lo^3) / 3 * (others)
    Integrals r;
    r.volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    const Point<3> m = 0.5 * (lo + hi);
    for (unsigned int i = 0; i < 3; ++i)
      {
        r.first[i] = r.volume * m[i];
        for (unsigned int j = 0; j < 3; ++j)
          r.second[i][j] = i == j ? r.volume / (hi[i] - lo[i]) * (std::pow(hi[i], 3) - std::pow(lo[i], 3)) / 3
                                  : r.volume * m[i] * m[j];
      }
    return r;
  }

  /// The inscribed prism of a z-aligned cylinder (centre (cx, cy), z in [z0, z1]) with n sides.
  Integrals
  prism_integrals(const double cx, const double cy, const double r, const double z0, const double z1, const unsigned int n)
  {
    // A regular n-gon of circumradius r: area A = n r^2 sin(a) / 2, polar moment about
    // its centre J = A r^2 (2 + cos a) / 6, a = 2 pi / n (n triangles from the centre);
    // isotropic (n a multiple of 4): int xi xi^T dA = J / 2 I.
    const double a = 2 * M_PI / n, A = 0.5 * n * r * r * std::sin(a), J = A * r * r * (2 + std::cos(a)) / 6;
    const double L = z1 - z0;
    Integrals    p;
    p.volume = A * L;
    const double c[2] = {cx, cy};
    for (unsigned int i = 0; i < 2; ++i)
      {
        p.first[i] = p.volume * c[i];
        for (unsigned int j = 0; j < 2; ++j)
          p.second[i][j] = L * (A * c[i] * c[j] + (i == j ? 0.5 * J : 0.0));
        p.second[i][2] = p.second[2][i] = A * c[i] * 0.5 * (z1 * z1 - z0 * z0);
      }
    p.first[2]     = A * 0.5 * (z1 * z1 - z0 * z0);
    p.second[2][2] = A * (z1 * z1 * z1 - z0 * z0 * z0) / 3;
    return p;
  }

  /// The sums over the cells: volume, int x = V c, int x x^T = S + V c c^T.
  Integrals
  cell_sums(const RBSN::Tessellation<3> &t)
  {
    Integrals s;
    for (const auto &c : t.cells)
      {
        s.volume += c.volume;
        for (unsigned int i = 0; i < 3; ++i)
          {
            s.first[i] += c.volume * c.centroid[i];
            for (unsigned int j = 0; j < 3; ++j)
              s.second[i][j] += c.second_moment[i][j] + c.volume * c.centroid[i] * c.centroid[j];
          }
      }
    return s;
  }

  void
  expect_integrals(const Integrals &a, const Integrals &b, const double tolerance)
  {
    EXPECT_NEAR(a.volume, b.volume, tolerance * std::abs(b.volume));
    const double f = b.first.norm(), s = b.second.norm();
    EXPECT_LT((a.first - b.first).norm(), tolerance * f) << a.first << " vs " << b.first;
    EXPECT_LT((a.second - b.second).norm(), tolerance * s) << a.second << " vs " << b.second;
  }

  /// Nuclei of a saturated network: boundary points, then random points.
  std::vector<Point<3>>
  network(const Geometry::Region<3> &region, const double d, const double h, const std::uint64_t seed)
  {
    const RBSN::Spacing<3> spacing(d);
    const auto             fixed = RBSN::boundary_points(region, spacing, h, seed);
    return RBSN::poisson_disk_points(region, spacing, fixed, seed + 1, "RBSN/Minimum distance", h);
  }

  /// Every cell closed (sum of area vectors 0 over each piece), facets consistent with
  /// the faces of cell b on the bisector, h_a + h_b = h, normals along x_b - x_a.
  void
  expect_consistent(const RBSN::Tessellation<3> &t, const double scale)
  {
    for (const auto &c : t.cells)
      for (const auto &piece : c.pieces)
        {
          Vector sum;
          for (const auto &face : piece)
            sum += area_vector(face);
          EXPECT_LT(sum.norm(), 1e-12 * scale * scale);
        }
    for (const auto &f : t.facets)
      {
        ASSERT_LT(f.a, f.b);
        const Point<3> &xa = t.cells[f.a].nucleus, &xb = t.cells[f.b].nucleus;
        EXPECT_NEAR(f.distance, xa.distance(xb), 1e-14 * scale);
        EXPECT_NEAR(f.h_a + f.h_b, f.distance, 1e-12 * scale);
        EXPECT_LT((f.normal - (xb - xa) / xa.distance(xb)).norm(), 1e-14);
        // The faces of cell b on the bisector, facing a.
        const Point<3> m = 0.5 * (xa + xb);
        double         area_b = 0;
        for (const auto &piece : t.cells[f.b].pieces)
          for (const auto &face : piece)
            {
              bool on = true;
              for (const auto &v : face)
                on = on && std::abs((v - m) * f.normal) < 1e-11 * scale;
              if (on)
                area_b += -(area_vector(face) * f.normal);
            }
        EXPECT_NEAR(f.area, area_b, 1e-12 * scale * scale) << f.a << " " << f.b;
        // The facet's area from its polygons, its centroid in the plane.
        double area = 0;
        for (const auto &p : f.polygons)
          area += area_vector(p) * f.normal;
        EXPECT_NEAR(f.area, area, 1e-13 * scale * scale);
        EXPECT_NEAR((f.midpoint - m) * f.normal, 0, 1e-12 * scale);
        EXPECT_NEAR(f.axis_1 * f.normal, 0, 1e-12);
        EXPECT_LT((cross_product_3d(f.normal, f.axis_1) - f.axis_2).norm(), 1e-12);
        EXPECT_GE(f.second_moment_1, f.second_moment_2);
        EXPECT_GE(f.second_moment_2, -1e-14 * std::pow(scale, 4));
      }
    for (unsigned int k = 1; k < t.facets.size(); ++k)
      EXPECT_TRUE(std::make_pair(t.facets[k - 1].a, t.facets[k - 1].b) < std::make_pair(t.facets[k].a, t.facets[k].b));
  }

  /// Whether some boundary loop of the cell has area on the plane x_axis = value.
  bool
  touches(const RBSN::Cell<3> &c, const unsigned int axis, const double value, const double scale)
  {
    for (const auto &loop : c.boundary)
      {
        bool on = true;
        for (const auto &v : loop)
          on = on && std::abs(v[axis] - value) < 1e-12 * scale;
        if (on && area_vector(loop).norm() > 1e-12 * scale * scale)
          return true;
      }
    return false;
  }
} // namespace



// A box of Poisson nuclei with boundary nuclei: the cells tile it exactly (volume, first
// and second moments), each cell is closed, every facet is the common face of its two
// cells, and every cell on a face of the box has its nucleus on that face.
TEST(Tessellation3D, CellsTileABox)
{
  const Point<3> lo(0.1, -0.2, 0), hi(1.1, 0.4, 0.4);
  const auto     region = parse("box(0.1, -0.2, 0, 1.1, 0.4, 0.4)");
  const auto     nuclei = network(region, 0.1, 0.025, 7);
  const auto     t      = RBSN::voronoi(nuclei, {&region}, 0.025, "Body names");
  ASSERT_EQ(t.cells.size(), nuclei.size());
  EXPECT_GT(nuclei.size(), 200u);
  const double scale = lo.distance(hi);
  expect_integrals(cell_sums(t), box_integrals(lo, hi), 1e-12);
  expect_consistent(t, scale);
  // Every facet is found once and every cell has at least 3 facets (a corner cell's).
  std::vector<unsigned int> count(t.cells.size(), 0);
  for (const auto &f : t.facets)
    ++count[f.a], ++count[f.b];
  for (unsigned int c = 0; c < count.size(); ++c)
    EXPECT_GE(count[c], 3u);
  // Nuclei on the faces of the box own them.
  unsigned int on_faces = 0;
  for (const auto &c : t.cells)
    for (unsigned int axis = 0; axis < 3; ++axis)
      for (const double value : {lo[axis], hi[axis]})
        if (touches(c, axis, value, scale))
          {
            ++on_faces;
            EXPECT_LT(std::abs(c.nucleus[axis] - value), 1e-12) << c.nucleus;
          }
  EXPECT_GT(on_faces, 100u);
  // The boundary loops of all cells cover the surface of the box.
  double surface = 0;
  for (const auto &c : t.cells)
    for (const auto &loop : c.boundary)
      surface += area_vector(loop).norm();
  EXPECT_NEAR(surface, 2 * (1.0 * 0.6 + 1.0 * 0.4 + 0.6 * 0.4), 1e-12);
}



// The boundary nuclei of a box: its 8 corners, the 12 edges at equal steps of at most
// d, and the faces keeping the distance d from every other point.
TEST(Tessellation3D, BoundaryPointsOfABox)
{
  const auto region = parse("box(0, 0, 0, 1, 0.6, 0.4)");
  const auto p      = RBSN::boundary_points(region, RBSN::Spacing<3>(0.1), 0.025, 3);
  const auto on     = [](const double x, const double a) { return std::abs(x - a) < 1e-12; };
  unsigned int corners = 0, edges = 0;
  for (const auto &q : p)
    {
      unsigned int n_on = 0;
      for (unsigned int k = 0; k < 3; ++k)
        n_on += on(q[k], 0) || on(q[k], k == 0 ? 1.0 : k == 1 ? 0.6 : 0.4);
      EXPECT_GE(n_on, 1u) << q; // on the surface
      corners += n_on == 3;
      edges += n_on == 2;
    }
  EXPECT_EQ(corners, 8u);
  // 4 edges of 1 m (9 points inside each), 4 of 0.6 m (5), 4 of 0.4 m (3).
  EXPECT_EQ(edges, 4u * 9 + 4 * 5 + 4 * 3);
  // The face points keep d = 0.1 from all others (corners and edge points may be closer).
  for (unsigned int i = corners + edges; i < p.size(); ++i)
    for (unsigned int j = 0; j < p.size(); ++j)
      if (j != i)
        {
          EXPECT_GE(p[i].distance(p[j]), 0.1 - 1e-14);
        }
}



// A bore through a box (box minus a cylinder): the cells add up to the box minus the
// inscribed prism of n_disk_sides(r, h) sides, n/2 r^2 sin(2 pi / n) L (and its
// moments), and the nuclei on the bore lie on the prism.
TEST(Tessellation3D, CellsTileABoxWithABore)
{
  const double r = 0.2, h = 0.04;
  const auto   region = parse("box(0, 0, 0, 1, 1, 0.5) - cylinder(0.5, 0.45, -1, 0.5, 0.45, 1.5, 0.2)");
  const auto   nuclei = network(region, 0.08, h, 11);
  const auto   t      = RBSN::voronoi(nuclei, {&region}, h, "Body names");
  const unsigned int n = Geometry::Region<3>::n_disk_sides(r, h);
  EXPECT_EQ(n, 32u);
  Integrals expected = box_integrals(Point<3>(0, 0, 0), Point<3>(1, 1, 0.5));
  expected -= prism_integrals(0.5, 0.45, r, 0, 0.5, n);
  expect_integrals(cell_sums(t), expected, 1e-12);
  expect_consistent(t, 1.5);
  // The polyhedral domain's volume by itself, and points on the bore on the prism.
  const RBSN::Polyhedral::Domain domain({&region}, h, "test");
  EXPECT_NEAR(domain.volume(), expected.volume, 1e-13);
  unsigned int on_bore = 0;
  for (const auto &p : nuclei)
    {
      const double rho = std::hypot(p[0] - 0.5, p[1] - 0.45);
      if (rho < r * 1.01)
        {
          ++on_bore;
          EXPECT_GE(rho, r * std::cos(M_PI / n) - 1e-12);
          EXPECT_TRUE(domain.contains(p, 1e-12));
        }
    }
  EXPECT_GT(on_bore, 2 * M_PI * r * 0.5 / (0.08 * 0.08) * 0.5);
  // The bore's surface in the cells' boundaries: the prism's mantle n 2 r sin(pi / n) L.
  double mantle = 0, total = 0;
  for (const auto &c : t.cells)
    for (const auto &loop : c.boundary)
      {
        const Vector a = area_vector(loop);
        total += a.norm();
        if (std::abs(a[2]) < 1e-12)
          {
            Point<3> m;
            for (const auto &v : loop)
              m += v / static_cast<double>(loop.size());
            if (std::hypot(m[0] - 0.5, m[1] - 0.45) < r)
              {
                mantle += a.norm();
                // outward of the domain: into the bore
                EXPECT_LT(a * Vector({m[0] - 0.5, m[1] - 0.45, 0}), 0);
              }
          }
      }
  EXPECT_NEAR(mantle, n * 2 * r * std::sin(M_PI / n) * 0.5, 1e-12);
  // The bore's nuclei own its surface: every cell with a boundary piece on the mantle has
  // its nucleus on the prism (the forbidden balls of every side; each side is a strip
  // 2 r sin(pi / n) = 0.039 wide, too narrow for a Delaunay triangulation of its own nuclei).
  for (unsigned int i = 0; i < t.cells.size(); ++i)
    for (const auto &loop : t.cells[i].boundary)
      {
        const Vector a = area_vector(loop);
        Point<3>     m;
        for (const auto &v : loop)
          m += v / static_cast<double>(loop.size());
        if (std::abs(a[2]) < 1e-12 && std::hypot(m[0] - 0.5, m[1] - 0.45) < r)
          {
            EXPECT_LT(std::hypot(nuclei[i][0] - 0.5, nuclei[i][1] - 0.45), r * (1 + 1e-12))
              << "cell " << i << " at " << nuclei[i] << " owns " << a.norm() << " m^2 of the bore";
          }
      }
  const double A = 0.5 * n * r * r * std::sin(2 * M_PI / n);
  EXPECT_NEAR(total, 2 * (1 - A) + 4 * 0.5 + n * 2 * r * std::sin(M_PI / n) * 0.5, 1e-12);
}



// A union of two overlapping boxes (an L) and a sphere as a second body: the cells add
// up to the L (by inclusion-exclusion) plus the geodesic polyhedron (its volume from its
// own faces, within 1 % of 4/3 pi r^3).
TEST(Tessellation3D, CellsTileAnLAndASphere)
{
  const auto   L      = parse("box(0, 0, 0, 2, 1, 1) + box(0, 0, 0, 1, 2, 1)");
  const auto   ball   = parse("sphere(4, 0.5, 0.5, 0.6)");
  const double h      = 0.1;
  auto         nuclei = network(L, 0.2, h, 5);
  const auto   more   = network(ball, 0.2, h, 6);
  nuclei.insert(nuclei.end(), more.begin(), more.end());
  const auto t = RBSN::voronoi(nuclei, {&L, &ball}, h, "Body names");

  Integrals expected = box_integrals(Point<3>(0, 0, 0), Point<3>(2, 1, 1));
  expected += box_integrals(Point<3>(0, 0, 0), Point<3>(1, 2, 1));
  expected -= box_integrals(Point<3>(0, 0, 0), Point<3>(1, 1, 1));
  // The sphere's polyhedron: tetrahedra from the centre to its triangles.
  const RBSN::Polyhedral::Domain sphere({&ball}, h, "test");
  ASSERT_EQ(sphere.primitives().size(), 1u);
  const Point<3> c(4, 0.5, 0.5);
  Integrals      s;
  double         longest = 0;
  for (const auto &f : sphere.primitives()[0].faces)
    {
      ASSERT_EQ(f.size(), 3u);
      const Vector a = f[0] - c, b = f[1] - c, e = f[2] - c, sum = a + b + e;
      const double V = a * cross_product_3d(b, e) / 6;
      EXPECT_GT(V, 0);
      s.volume += V;
      for (unsigned int i = 0; i < 3; ++i)
        {
          s.first[i] += V * (c[i] + sum[i] / 4);
          for (unsigned int j = 0; j < 3; ++j)
            s.second[i][j] += V / 20 * (a[i] * a[j] + b[i] * b[j] + e[i] * e[j] + sum[i] * sum[j]) +
                              V * (c[i] * sum[j] + sum[i] * c[j]) / 4 + V * c[i] * c[j];
        }
      for (unsigned int k = 0; k < 3; ++k)
        {
          longest = std::max(longest, f[k].distance(f[(k + 1) % 3]));
          EXPECT_NEAR(f[k].distance(c), 0.6, 1e-14);
        }
    }
  EXPECT_LE(longest, h);
  EXPECT_NEAR(s.volume, 4.0 / 3 * M_PI * 0.216, 0.01 * 4.0 / 3 * M_PI * 0.216);
  // Convex: every vertex inside every face's plane.
  for (unsigned int p = sphere.primitives()[0].first_plane; p < sphere.n_planes(); ++p)
    for (const auto &f : sphere.primitives()[0].faces)
      for (const auto &v : f)
        EXPECT_LE(sphere.plane(p)(v), 1e-14);
  expected += s;
  expect_integrals(cell_sums(t), expected, 1e-12);
  expect_consistent(t, 5);
  // The domain's own volume and boundary (each area once, closed: sum of area vectors 0).
  const RBSN::Polyhedral::Domain both({&L, &ball}, h, "test");
  EXPECT_NEAR(both.volume(), expected.volume, 1e-12 * expected.volume);
  Vector sum;
  double area = 0;
  for (const auto &b : both.boundary())
    {
      const Vector a = area_vector(b.polygon.vertices);
      EXPECT_GT(a * b.polygon.normal, 0);
      sum += a;
      area += a.norm();
    }
  EXPECT_LT(sum.norm(), 1e-12);
  double sphere_area = 0;
  for (const auto &f : sphere.primitives()[0].faces)
    sphere_area += area_vector(f).norm();
  EXPECT_NEAR(area, 2 * 3 + 8 + sphere_area, 1e-12); // the L: top and bottom 3 m^2, sides 8 m^2
  // The cells' boundary faces cover that surface once (none on the plane y = 1 inside the L).
  double cells_area = 0;
  for (const auto &c : t.cells)
    for (const auto &loop : c.boundary)
      {
        cells_area += area_vector(loop).norm();
        bool   on_plane = true;
        double x        = 0;
        for (const auto &v : loop)
          {
            on_plane = on_plane && std::abs(v[1] - 1) < 1e-12;
            x += v[0] / loop.size();
          }
        EXPECT_FALSE(on_plane && x < 1);
      }
  EXPECT_NEAR(cells_area, area, 1e-12);
  // The sphere's nuclei own its surface: every cell with a boundary piece on the sphere
  // has its nucleus on the geodesic polyhedron (within the inradius 0.6 cos(beta) of the
  // centre), not inside it.
  const double inradius = 0.6 * std::cos(h / 0.6); // well below it: edges <= h
  for (unsigned int i = 0; i < t.cells.size(); ++i)
    if (nuclei[i].distance(c) < 1)
      {
        for (const auto &loop : t.cells[i].boundary)
          EXPECT_GT(nuclei[i].distance(c), inradius)
            << "cell " << i << " at " << nuclei[i] << " owns " << area_vector(loop).norm()
            << " m^2 of the sphere";
      }
}




// Unions and differences of inclined cylinders, spheres and boxes (nested): three
// independent volumes agree. The cells (pieces from clipping) add up to the domain's
// volume by the divergence theorem over its boundary (to 1e-12), which is within 2 % of
// a midpoint rule with contains() on 60^3 points; the cells' boundary faces add up to
// the domain's surface, and every cell is closed.
TEST(Tessellation3D, CellsTileCsgShapes)
{
  for (const std::string expression :
       {"box(0, 0, 0, 1, 1, 1) - sphere(0.5, 0.5, 1, 0.3) - cylinder(0, 0, 0, 1, 1, 1, 0.15)",
        "cylinder(0, 0, 0, 1, 0.3, 0.2, 0.3) + sphere(1, 0.3, 0.2, 0.35) + box(-0.2, -0.2, -0.2, 0.3, 0.3, 0.3)",
        "(box(0, 0, 0, 1, 1, 1) - box(0.25, 0.25, -1, 0.75, 0.75, 2)) + cylinder(0.5, 0.5, 0, 0.5, 0.5, 1, 0.2)",
        "sphere(0, 0, 0, 1) - sphere(0, 0, 0, 0.7) - box(0, 0, 0, 2, 2, 2)",
        "box(0, 0, 0, 1, 1, 1) + box(1, 0, 0, 2, 1, 1) + box(0.5, 0.5, 1, 1.5, 1.5, 1.5)"})
    {
      const auto                     region = parse(expression);
      const double                   h      = 0.05;
      const RBSN::Polyhedral::Domain domain({&region}, h, "test");
      const auto                     surface = domain.boundary();
      const double                   V       = RBSN::Polyhedral::Domain::volume(surface);
      const auto                    &b       = domain.box;
      const int                      n       = 60;
      double                         inside  = 0;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k)
            inside += domain.contains(Point<3>(b.lo[0] + (i + 0.5) * (b.hi[0] - b.lo[0]) / n,
                                               b.lo[1] + (j + 0.5) * (b.hi[1] - b.lo[1]) / n,
                                               b.lo[2] + (k + 0.5) * (b.hi[2] - b.lo[2]) / n));
      const double grid = inside / (n * n * n) * (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]) * (b.hi[2] - b.lo[2]);
      const auto   t    = RBSN::voronoi(network(region, 0.1, h, 3), {&region}, h, "Body names");
      double       cells = 0, area = 0, cell_area = 0;
      for (const auto &c : t.cells)
        {
          cells += c.volume;
          for (const auto &loop : c.boundary)
            cell_area += area_vector(loop).norm();
        }
      for (const auto &p : surface)
        area += area_vector(p.polygon.vertices).norm();
      EXPECT_NEAR(cells, V, 1e-12 * V) << expression;
      EXPECT_NEAR(grid, V, 0.02 * V) << expression;
      EXPECT_NEAR(cell_area, area, 1e-12 * area) << expression;
      expect_consistent(t, 2);
    }
}


// Building only some cells from their nuclei and a halo of the nuclei within H of them
// gives the same cells and facets as the full tessellation when 2 reach <= H.
TEST(Tessellation3D, WantedCellsFromAHalo)
{
  const auto region = parse("box(0, 0, 0, 1, 0.8, 0.6) - sphere(0.5, 0.4, 0.3, 0.15)");
  const auto nuclei = network(region, 0.1, 0.05, 21);
  const auto full   = RBSN::voronoi(nuclei, {&region}, 0.05, "Body names");
  // Wanted: every 7th cell (interior, boundary and around the hole).
  std::vector<unsigned int> wanted;
  double                    H = 0;
  for (unsigned int i = 0; i < nuclei.size(); i += 7)
    {
      wanted.push_back(i);
      H = std::max(H, 2 * full.cells[i].reach);
    }
  for (const unsigned int w : {wanted[0], wanted[wanted.size() / 2], wanted.back()})
    {
      // The halo of one wanted cell, in the original order.
      std::vector<unsigned int> halo;
      for (unsigned int j = 0; j < nuclei.size(); ++j)
        if (nuclei[j].distance(nuclei[w]) <= 2 * full.cells[w].reach)
          halo.push_back(j);
      std::vector<Point<3>> local;
      std::vector<bool>     flag;
      for (const unsigned int j : halo)
        {
          local.push_back(nuclei[j]);
          flag.push_back(j == w);
        }
      const auto part = RBSN::voronoi(local, {&region}, 0.05, "Body names", flag);
      const auto k    = std::find(halo.begin(), halo.end(), w) - halo.begin();
      const auto &a = part.cells[k], &b = full.cells[w];
      EXPECT_NEAR(a.volume, b.volume, 1e-12 * b.volume);
      EXPECT_LT(a.centroid.distance(b.centroid), 1e-12);
      EXPECT_LT((a.second_moment - b.second_moment).norm(), 1e-12 * b.second_moment.norm());
      EXPECT_NEAR(a.reach, b.reach, 1e-12);
      std::vector<const RBSN::Facet<3> *> expected;
      for (const auto &f : full.facets)
        if (f.a == w)
          expected.push_back(&f);
      ASSERT_EQ(part.facets.size(), expected.size());
      for (unsigned int m = 0; m < expected.size(); ++m)
        {
          const auto &f = part.facets[m];
          EXPECT_EQ(halo[f.a], expected[m]->a);
          EXPECT_EQ(halo[f.b], expected[m]->b);
          EXPECT_NEAR(f.area, expected[m]->area, 1e-12);
          EXPECT_LT(f.midpoint.distance(expected[m]->midpoint), 1e-12);
          EXPECT_NEAR(f.second_moment_1, expected[m]->second_moment_1, 1e-12);
          EXPECT_NEAR(f.second_moment_2, expected[m]->second_moment_2, 1e-12);
        }
      // The other cells stay empty.
      for (unsigned int j = 0; j < part.cells.size(); ++j)
        if (static_cast<long>(j) != k)
          {
            EXPECT_EQ(part.cells[j].volume, 0);
          }
    }
  // A subset with the full set of nuclei gives the same cells bit for bit.
  std::vector<bool> flag(nuclei.size(), false);
  for (const unsigned int w : wanted)
    flag[w] = true;
  const auto some = RBSN::voronoi(nuclei, {&region}, 0.05, "Body names", flag);
  for (const unsigned int w : wanted)
    EXPECT_EQ(some.cells[w].volume, full.cells[w].volume);
  EXPECT_GT(H, 0);
}



// The saturated density of random points in a large box with a constant d: n d^3 / V
// of the points away from the faces within 5 % of Spacing<3>::density.
TEST(Tessellation3D, DensityOfASaturatedSet)
{
  const double d      = 0.05;
  const auto   region = parse("box(0, 0, 0, 1, 1, 1)");
  const auto   p      = RBSN::poisson_disk_points(region, RBSN::Spacing<3>(d), {}, 4, "RBSN", 0.025);
  unsigned int inner  = 0;
  for (const auto &q : p)
    inner += q[0] > 0.1 && q[0] < 0.9 && q[1] > 0.1 && q[1] < 0.9 && q[2] > 0.1 && q[2] < 0.9;
  const double density = inner * d * d * d / (0.8 * 0.8 * 0.8);
  std::cout << "n d^3 / V = " << density << " (" << inner << " inner points, " << p.size() << " in all)" << std::endl;
  EXPECT_NEAR(density, RBSN::Spacing<3>::density, 0.05 * RBSN::Spacing<3>::density);
  // The distance rule.
  for (unsigned int i = 0; i < p.size(); i += 13)
    for (unsigned int j = 0; j < p.size(); ++j)
      if (j != i)
        {
          EXPECT_GE(p[i].distance(p[j]), d);
        }
}



// A graded d(x): every pair keeps min(d(p), d(q)), finer where d is smaller.
TEST(Tessellation3D, GradedSpacing)
{
  const auto      region = parse("box(0, 0, 0, 1, 0.4, 0.4)");
  const auto      f      = [](const Point<3> &x) { return 0.04 + 0.08 * x[0]; };
  RBSN::Spacing<3> d(f, "0.04 + 0.08 x", "RBSN/Minimum distance");
  d.sample({&region});
  EXPECT_NEAR(d.min, 0.04, 1e-3);
  EXPECT_NEAR(d.gradient, 0.08, 1e-6);
  const auto b = RBSN::boundary_points(region, d, 0.01, 1);
  const auto p = RBSN::poisson_disk_points(region, d, b, 2, "RBSN", 0.01);
  for (unsigned int i = b.size(); i < p.size(); ++i)
    for (unsigned int j = 0; j < p.size(); ++j)
      if (j != i)
        {
          EXPECT_GE(p[i].distance(p[j]), std::min(f(p[i]), f(p[j])) - 1e-14);
        }
  const auto   left  = std::count_if(p.begin(), p.end(), [](const Point<3> &x) { return x[0] < 0.5; });
  const auto   right = static_cast<long>(p.size()) - left;
  EXPECT_GT(left, 2 * right);
  const auto t = RBSN::voronoi(p, {&region}, 0.01, "Body names");
  expect_integrals(cell_sums(t), box_integrals(Point<3>(0, 0, 0), Point<3>(1, 0.4, 0.4)), 1e-12);
}



// The same seed gives the same nuclei and cells, bit for bit; another seed others.
TEST(Tessellation3D, Deterministic)
{
  const auto region = parse("box(0, 0, 0, 0.6, 0.4, 0.4) - cylinder(0.3, -1, 0.2, 0.3, 1, 0.2, 0.1)");
  const auto a = network(region, 0.07, 0.02, 9), b = network(region, 0.07, 0.02, 9), c = network(region, 0.07, 0.02, 10);
  ASSERT_EQ(a.size(), b.size());
  for (unsigned int i = 0; i < a.size(); ++i)
    for (unsigned int k = 0; k < 3; ++k)
      EXPECT_EQ(a[i][k], b[i][k]);
  EXPECT_NE(a.back(), c.back());
  const auto ta = RBSN::voronoi(a, {&region}, 0.02, "x"), tb = RBSN::voronoi(b, {&region}, 0.02, "x");
  ASSERT_EQ(ta.facets.size(), tb.facets.size());
  for (unsigned int i = 0; i < ta.cells.size(); ++i)
    {
      EXPECT_EQ(ta.cells[i].volume, tb.cells[i].volume);
      EXPECT_EQ(ta.cells[i].centroid, tb.cells[i].centroid);
    }
  for (unsigned int f = 0; f < ta.facets.size(); ++f)
    {
      EXPECT_EQ(ta.facets[f].area, tb.facets[f].area);
      EXPECT_EQ(ta.facets[f].axis_1, tb.facets[f].axis_1);
    }
}



// Errors name their place: a nucleus outside (with its coordinates), coincident
// nuclei, a single nucleus, an unbounded body, a minimum distance <= 0.
TEST(Tessellation3D, Errors)
{
  const auto region = parse("box(0, 0, 0, 1, 1, 1)");
  const auto message = [](const std::function<void()> &f) {
    try
      {
        f();
      }
    catch (const InputError &e)
      {
        return std::string(e.what());
      }
    return std::string("no error");
  };
  EXPECT_EQ(message([&]() { RBSN::voronoi({Point<3>(0.5, 0.5, 0.5), Point<3>(1.5, 0.5, 0.25)}, {&region}, 0.1, "Body names"); }),
            "Body names: the point (1.5, 0.5, 0.25) lies outside the bodies");
  EXPECT_EQ(message([&]() {
              RBSN::voronoi({Point<3>(0.5, 0.5, 0.5), Point<3>(0.2, 0.5, 0.5), Point<3>(0.5, 0.5, 0.5)}, {&region}, 0.1, "B");
            }),
            "B: two points coincide at (0.5, 0.5, 0.5)");
  EXPECT_EQ(message([&]() { RBSN::voronoi({Point<3>(0.5, 0.5, 0.5)}, {&region}, 0.1, "B"); }),
            "B: a network needs at least two cells");
  // A nucleus just outside a face (within the tolerance 1e-9 of the box's size) whose
  // cell is cut off by the face: no volume.
  EXPECT_EQ(message([&]() { RBSN::voronoi({Point<3>(1 + 1e-10, 0.5, 0.5), Point<3>(1 - 1e-10, 0.5, 0.5)}, {&region}, 0.1, "B"); }),
            "B: the cell of the point (1, 0.5, 0.5) has no volume in the bodies");
  const auto all = parse("all - box(0, 0, 0, 1, 1, 1)");
  EXPECT_NE(message([&]() { RBSN::poisson_disk_points(all, RBSN::Spacing<3>(0.1), {}, 1, "RBSN/Minimum distance"); })
              .find("RBSN/Minimum distance: the shape 'all - box(0, 0, 0, 1, 1, 1)' contains 'all'"),
            std::string::npos);
  EXPECT_EQ(message([&]() { RBSN::poisson_disk_points(region, RBSN::Spacing<3>(0.0), {}, 1, "RBSN/Minimum distance"); }),
            "RBSN/Minimum distance: the minimum distance must be > 0");
  EXPECT_NE(message([&]() { RBSN::poisson_disk_points(region, RBSN::Spacing<3>(0.005), {}, 1, "RBSN/Minimum distance"); })
              .find("points predicted at this minimum distance"),
            std::string::npos);
}



// Nuclei at the centres of an a x a x a lattice of cubes (given directly): every cell a
// cube, every facet an a x a square, A = a^2, I_1 = I_2 = a^4 / 12, h = a; a lattice of
// a x b x c boxes gives rectangles whose principal axes are the lattice's.
TEST(Tessellation3D, LatticeFacets)
{
  for (const std::array<double, 3> &size : {std::array<double, 3>{{0.1, 0.1, 0.1}}, std::array<double, 3>{{0.1, 0.15, 0.25}}})
    {
      const unsigned int    n[3] = {4, 3, 5};
      std::vector<Point<3>> nuclei;
      for (unsigned int k = 0; k < n[2]; ++k)
        for (unsigned int j = 0; j < n[1]; ++j)
          for (unsigned int i = 0; i < n[0]; ++i)
            nuclei.emplace_back((i + 0.5) * size[0], (j + 0.5) * size[1], (k + 0.5) * size[2]);
      std::ostringstream box;
      box << "box(0, 0, 0, " << n[0] * size[0] << ", " << n[1] * size[1] << ", " << n[2] * size[2] << ")";
      const auto region = parse(box.str());
      const auto t      = RBSN::voronoi(nuclei, {&region}, 0.01, "Body names");
      for (const auto &c : t.cells)
        {
          EXPECT_NEAR(c.volume, size[0] * size[1] * size[2], 1e-15);
          EXPECT_LT(c.centroid.distance(c.nucleus), 1e-14);
          for (unsigned int d = 0; d < 3; ++d)
            EXPECT_NEAR(c.second_moment[d][d], c.volume * size[d] * size[d] / 12, 1e-16);
        }
      // (n0 - 1) n1 n2 + n0 (n1 - 1) n2 + n0 n1 (n2 - 1) facets
      ASSERT_EQ(t.facets.size(), 3u * 3 * 5 + 4 * 2 * 5 + 4 * 3 * 4);
      for (const auto &f : t.facets)
        {
          unsigned int d = 0;
          while (std::abs(f.normal[d]) < 0.5)
            ++d;
          EXPECT_NEAR(std::abs(f.normal[d]), 1, 1e-15);
          const double w = size[(d + 1) % 3], v = size[(d + 2) % 3]; // the rectangle's sides
          EXPECT_NEAR(f.area, w * v, 1e-15);
          EXPECT_NEAR(f.distance, size[d], 1e-15);
          EXPECT_NEAR(f.h_a, 0.5 * size[d], 1e-15);
          EXPECT_NEAR(f.h_b, 0.5 * size[d], 1e-15);
          EXPECT_NEAR(f.second_moment_1, w * v * std::max(w, v) * std::max(w, v) / 12, 1e-17);
          EXPECT_NEAR(f.second_moment_2, w * v * std::min(w, v) * std::min(w, v) / 12, 1e-17);
          if (w != v)
            {
              // I_1 about axis_1: axis_1 along the shorter side, axis_2 along the longer.
              const unsigned int shorter = w < v ? (d + 1) % 3 : (d + 2) % 3;
              EXPECT_NEAR(std::abs(f.axis_1[shorter]), 1, 1e-12);
            }
          EXPECT_NEAR(cross_product_3d(f.normal, f.axis_1) * f.axis_2, 1, 1e-14);
        }
    }
}



// Collinear and coplanar nuclei (CGAL's triangulation of dimension 1 and 2): a bar of
// three cells and a plate of 2 x 2 cells.
TEST(Tessellation3D, DegenerateNuclei)
{
  const auto bar = parse("box(0, 0, 0, 3, 1, 1)");
  const auto t   = RBSN::voronoi({Point<3>(2.5, 0.5, 0.5), Point<3>(0.5, 0.5, 0.5), Point<3>(1.5, 0.5, 0.5)}, {&bar}, 0.1, "B");
  ASSERT_EQ(t.facets.size(), 2u);
  EXPECT_EQ(t.facets[0].a, 0u);
  EXPECT_EQ(t.facets[0].b, 2u);
  EXPECT_EQ(t.facets[1].a, 1u);
  EXPECT_EQ(t.facets[1].b, 2u);
  for (const auto &f : t.facets)
    EXPECT_NEAR(f.area, 1, 1e-14);
  for (const auto &c : t.cells)
    EXPECT_NEAR(c.volume, 1, 1e-14);
  const auto two = RBSN::voronoi({Point<3>(0.5, 0.5, 0.5), Point<3>(1.5, 0.5, 0.5)}, {&bar}, 0.1, "B");
  ASSERT_EQ(two.facets.size(), 1u);
  EXPECT_NEAR(two.cells[1].volume, 2, 1e-14);
  const auto plate = parse("box(0, 0, 0, 2, 2, 0.2)");
  const auto p     = RBSN::voronoi(
    {Point<3>(0.5, 0.5, 0.1), Point<3>(1.5, 0.5, 0.1), Point<3>(0.5, 1.5, 0.1), Point<3>(1.5, 1.5, 0.1)}, {&plate}, 0.1, "B");
  double area = 0;
  for (const auto &f : p.facets)
    area += f.area;
  EXPECT_NEAR(area, 4 * 0.2, 1e-14); // the diagonal neighbours share no area
  for (const auto &c : p.cells)
    EXPECT_NEAR(c.volume, 0.2, 1e-14);
}



// The timings of the set-up (boundary nuclei, random nuclei, cells) of networks of
// about 20,000 and 100,000 cells in a box; run with
//   hysteron_unit_tests --gtest_also_run_disabled_tests --gtest_filter='Tessellation3D.DISABLED_Timing'
TEST(Tessellation3D, DISABLED_Timing)
{
  for (const double d : {0.04, 0.024})
    {
      const auto             region = parse("box(0, 0, 0, 2, 1, 1)");
      const RBSN::Spacing<3> spacing(d);
      dealii::Timer          timer;
      const auto             fixed = RBSN::boundary_points(region, spacing, 0.25 * d, 1);
      const double           t1    = timer.wall_time();
      const auto             p     = RBSN::poisson_disk_points(region, spacing, fixed, 2, "RBSN", 0.25 * d);
      const double           t2    = timer.wall_time();
      const auto             t     = RBSN::voronoi(p, {&region}, 0.25 * d, "Body names");
      const double           t3    = timer.wall_time();
      std::cout << "d = " << d << ": " << fixed.size() << " boundary nuclei in " << t1 << " s, " << p.size()
                << " nuclei in " << t2 - t1 << " s, " << t.facets.size() << " facets in " << t3 - t2
                << " s; total " << t3 << " s" << std::endl;
    }
}


// The faces of a cube saturated as planar Poisson-disk sets: 0.68 points per d^2 (the
// 2D density) on the middle of a face.
TEST(Tessellation3D, FaceDensity)
{
  const double d      = 0.05;
  const auto   region = parse("box(0, 0, 0, 1, 1, 1)");
  const auto   p      = RBSN::boundary_points(region, RBSN::Spacing<3>(d), 0.25 * d, 3);
  for (unsigned int axis = 0; axis < 3; ++axis)
    for (const double value : {0.0, 1.0})
      {
        unsigned int inner = 0;
        for (const auto &q : p)
          inner += std::abs(q[axis] - value) < 1e-12 && q[(axis + 1) % 3] > 0.1 && q[(axis + 1) % 3] < 0.9 &&
                   q[(axis + 2) % 3] > 0.1 && q[(axis + 2) % 3] < 0.9;
        EXPECT_NEAR(inner * d * d / 0.64, RBSN::Spacing<2>::density, 0.05);
      }
}

// The measurement behind Spacing<3>::density (doc/rbsn/geometry_3d.md): n d^3 / V of the
// points of a unit cube farther than 0.1 from its faces, for 4 seeds; run with
//   hysteron_unit_tests --gtest_also_run_disabled_tests --gtest_filter='Tessellation3D.DISABLED_MeasureDensity'
TEST(Tessellation3D, DISABLED_MeasureDensity)
{
  const double d      = 0.02;
  const auto   region = parse("box(0, 0, 0, 1, 1, 1)");
  double       sum = 0, sum2 = 0;
  for (const std::uint64_t seed : {1, 2, 3, 4})
    {
      const auto   p     = RBSN::poisson_disk_points(region, RBSN::Spacing<3>(d), {}, seed, "RBSN", 0.25 * d);
      unsigned int inner = 0;
      for (const auto &q : p)
        inner += q[0] > 0.1 && q[0] < 0.9 && q[1] > 0.1 && q[1] < 0.9 && q[2] > 0.1 && q[2] < 0.9;
      const double density = inner * d * d * d / (0.8 * 0.8 * 0.8);
      sum += density;
      sum2 += density * density;
      std::cout << "seed " << seed << ": " << p.size() << " points, " << inner << " inner, n d^3 / V = " << density
                << std::endl;
    }
  const double mean = sum / 4;
  std::cout << "mean " << mean << ", standard deviation " << std::sqrt((sum2 / 4 - mean * mean) * 4 / 3) << std::endl;
}



// The same for curved bodies at the default resolution h = d / 4: a ball (a geodesic
// polyhedron of edges <= h) and a plate with 4 bores (prisms); run as above with
// --gtest_filter='Tessellation3D.DISABLED_TimingCurved'.
TEST(Tessellation3D, DISABLED_TimingCurved)
{
  for (const std::string expression :
       {"sphere(0, 0, 0, 1)",
        "box(0, 0, 0, 2, 2, 0.4) - cylinder(0.5, 0.5, -1, 0.5, 0.5, 1, 0.25) - cylinder(1.5, 0.5, -1, 1.5, 0.5, 1, "
        "0.25) - cylinder(0.5, 1.5, -1, 0.5, 1.5, 1, 0.25) - cylinder(1.5, 1.5, -1, 1.5, 1.5, 1, 0.25)"})
    {
      const double           d      = 0.06;
      const auto             region = parse(expression);
      const RBSN::Spacing<3> spacing(d);
      dealii::Timer          timer;
      const auto             fixed = RBSN::boundary_points(region, spacing, 0.25 * d, 1);
      const double           t1    = timer.wall_time();
      const auto             p     = RBSN::poisson_disk_points(region, spacing, fixed, 2, "RBSN", 0.25 * d);
      const double           t2    = timer.wall_time();
      const auto             t     = RBSN::voronoi(p, {&region}, 0.25 * d, "Body names");
      const double           t3    = timer.wall_time();
      double                 volume = 0;
      for (const auto &c : t.cells)
        volume += c.volume;
      std::cout << expression << ", d = " << d << ": " << fixed.size() << " boundary nuclei in " << t1 << " s, "
                << p.size() << " nuclei in " << t2 - t1 << " s, " << t.facets.size() << " facets in " << t3 - t2
                << " s; total " << t3 << " s; volume " << volume << std::endl;
    }
}
