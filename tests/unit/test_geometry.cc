// Unit tests of the geometry module: the region expression language (parser,
// errors, contains, bounding boxes, volumes) and the lattice particle fill.
#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/region.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace
{
  using namespace hysteron;
  using namespace hysteron::Geometry;
  using dealii::Point;

  const std::string where = "Body/beam/Shape";

  Region<2>
  parse2(const std::string &expression)
  {
    return Region<2>::parse(expression, where);
  }

  Region<3>
  parse3(const std::string &expression)
  {
    return Region<3>::parse(expression, where);
  }

  /// Parse must fail with a problem containing every phrase, and name `where`.
  template <int dim>
  void
  expect_error(const std::string &expression, const std::vector<std::string> &phrases)
  {
    try
      {
        Region<dim>::parse(expression, where);
        ADD_FAILURE() << "no error for '" << expression << "'";
      }
    catch (const InputError &e)
      {
        EXPECT_EQ(e.where(), where);
        EXPECT_NE(std::string(e.what()).find(where), std::string::npos);
        for (const auto &phrase : phrases)
          EXPECT_NE(e.problem().find(phrase), std::string::npos)
            << "'" << expression << "': '" << e.problem() << "' lacks '" << phrase << "'";
      }
  }

  template <int dim>
  double
  filled_volume(const Region<dim> &region, const FillLattice<dim> &lattice, const unsigned int k)
  {
    return fill(region, lattice, k).size() * fill_particle_volume(lattice, k);
  }
} // namespace



TEST(GeometryRegion, Rectangle)
{
  const auto r = parse2("rectangle(2, 1, 0, 0)"); // corners in any order
  EXPECT_TRUE(r.contains(Point<2>(1, 0.5)));
  EXPECT_FALSE(r.contains(Point<2>(2.1, 0.5)));
  EXPECT_FALSE(r.contains(Point<2>(1, -0.01)));
  EXPECT_TRUE(r.contains(Point<2>(2, 0.5)));  // closed
  EXPECT_TRUE(r.contains(Point<2>(0, 0)));    // corner
  EXPECT_FALSE(r.contains(Point<2>(2 + 1e-10, 0.5)));
  EXPECT_TRUE(r.contains(Point<2>(2 + 1e-10, 0.5), 1e-9));
  EXPECT_DOUBLE_EQ(r.volume_estimate(), 2.0);
  const auto box = r.bounding_box().get_boundary_points();
  EXPECT_EQ(box.first, Point<2>(0, 0));
  EXPECT_EQ(box.second, Point<2>(2, 1));
  EXPECT_EQ(r.expression(), "rectangle(2, 1, 0, 0)");
  EXPECT_FALSE(r.is_empty());
}



TEST(GeometryRegion, Disk)
{
  const auto r = parse2("disk(1, 2, 0.5)");
  EXPECT_TRUE(r.contains(Point<2>(1, 2)));
  EXPECT_TRUE(r.contains(Point<2>(1.5, 2)));   // on the boundary
  EXPECT_TRUE(r.contains(Point<2>(1, 1.5)));   // on the boundary
  EXPECT_FALSE(r.contains(Point<2>(1.5 + 1e-9, 2)));
  EXPECT_TRUE(r.contains(Point<2>(1.5 + 1e-9, 2), 1e-8));
  EXPECT_FALSE(r.contains(Point<2>(1.36, 2.36))); // |d| = 0.509
  EXPECT_TRUE(r.contains(Point<2>(1.35, 2.35)));  // |d| = 0.495
  EXPECT_DOUBLE_EQ(r.volume_estimate(), M_PI * 0.25);
  const auto box = r.bounding_box().get_boundary_points();
  EXPECT_EQ(box.first, Point<2>(0.5, 1.5));
  EXPECT_EQ(box.second, Point<2>(1.5, 2.5));
}



TEST(GeometryRegion, PolygonOrientationIndependent)
{
  const auto ccw = parse2("polygon(0,0, 3,0, 0,2)");
  const auto cw  = parse2("polygon(0,0, 0,2, 3,0)");
  unsigned   n_inside = 0;
  for (int i = -5; i <= 35; ++i)
    for (int j = -5; j <= 25; ++j)
      {
        const Point<2> p(0.1 * i + 0.013, 0.1 * j + 0.007);
        const bool     expected = p[0] >= 0 && p[1] >= 0 && p[0] / 3 + p[1] / 2 <= 1;
        EXPECT_EQ(ccw.contains(p), expected) << p;
        EXPECT_EQ(cw.contains(p), expected) << p;
        n_inside += expected;
      }
  EXPECT_GT(n_inside, 200u);
  EXPECT_DOUBLE_EQ(ccw.volume_estimate(), 3.0);
  EXPECT_DOUBLE_EQ(cw.volume_estimate(), 3.0);
  // On the slanted edge, robustly inside with a tolerance.
  EXPECT_TRUE(ccw.contains(Point<2>(1.5, 1.0), 1e-12));
  EXPECT_TRUE(cw.contains(Point<2>(1.5, 1.0), 1e-12));
  EXPECT_FALSE(ccw.contains(Point<2>(1.5, 1.001), 1e-12));
}



TEST(GeometryRegion, ConcavePolygon)
{
  // L-shape: [0,2]x[0,2] without (1,2]x(1,2].
  const auto r = parse2("polygon(0,0, 2,0, 2,1, 1,1, 1,2, 0,2)");
  EXPECT_TRUE(r.contains(Point<2>(0.5, 0.5)));
  EXPECT_TRUE(r.contains(Point<2>(1.5, 0.5)));
  EXPECT_TRUE(r.contains(Point<2>(0.5, 1.5)));
  EXPECT_FALSE(r.contains(Point<2>(1.5, 1.5)));
  EXPECT_FALSE(r.contains(Point<2>(2.5, 0.5)));
  EXPECT_FALSE(r.contains(Point<2>(1.5, -0.1)));
  // Boundary points, also on the re-entrant edges, are in the closed set.
  EXPECT_TRUE(r.contains(Point<2>(1.5, 1.0)));
  EXPECT_TRUE(r.contains(Point<2>(1.0, 1.5)));
  EXPECT_TRUE(r.contains(Point<2>(2.0, 0.5)));
  EXPECT_TRUE(r.contains(Point<2>(1.0, 1.0)));
  EXPECT_FALSE(r.contains(Point<2>(1.5, 1.0 + 1e-10)));
  EXPECT_TRUE(r.contains(Point<2>(1.5, 1.0 + 1e-10), 1e-9));
  // An inflated polygon contains its interior, its boundary and its vertices.
  for (const double t : {1e-12, 1e-9, 1e-3})
    {
      EXPECT_TRUE(r.contains(Point<2>(0.5, 0.5), t));
      EXPECT_TRUE(r.contains(Point<2>(0.0, 1.0), t));
      EXPECT_TRUE(r.contains(Point<2>(0.0, 2.0), t));
      EXPECT_TRUE(r.contains(Point<2>(1.0, 1.0), t));
    }
  // A deflated one keeps only the points at least |t| inside.
  EXPECT_TRUE(r.contains(Point<2>(0.5, 0.5), -1e-3));
  EXPECT_FALSE(r.contains(Point<2>(0.0, 1.0), -1e-3));
  EXPECT_DOUBLE_EQ(r.volume_estimate(), 3.0);
  const auto box = r.bounding_box().get_boundary_points();
  EXPECT_EQ(box.first, Point<2>(0, 0));
  EXPECT_EQ(box.second, Point<2>(2, 2));
}



TEST(GeometryRegion, Primitives3D)
{
  const auto box = parse3("box(1,0,0, 0,2,3)");
  EXPECT_TRUE(box.contains(Point<3>(0.5, 1, 1.5)));
  EXPECT_TRUE(box.contains(Point<3>(1, 2, 3)));
  EXPECT_FALSE(box.contains(Point<3>(0.5, 1, 3.01)));
  EXPECT_DOUBLE_EQ(box.volume_estimate(), 6.0);

  const auto sphere = parse3("sphere(1, 1, 1, 2)");
  EXPECT_TRUE(sphere.contains(Point<3>(1, 1, 3)));
  EXPECT_TRUE(sphere.contains(Point<3>(2, 2, 2)));  // |d| = 1.73
  EXPECT_FALSE(sphere.contains(Point<3>(2.2, 2.2, 2.2))); // |d| = 2.08
  EXPECT_DOUBLE_EQ(sphere.volume_estimate(), 4. / 3. * M_PI * 8);

  const auto cylinder = parse3("cylinder(0,0,0, 0,0,2, 0.5)");
  EXPECT_TRUE(cylinder.contains(Point<3>(0.5, 0, 1)));  // mantle
  EXPECT_TRUE(cylinder.contains(Point<3>(0.4, 0, 2)));  // end face
  EXPECT_FALSE(cylinder.contains(Point<3>(0, 0, 2.1)));
  EXPECT_FALSE(cylinder.contains(Point<3>(0, 0, -0.1)));
  EXPECT_TRUE(cylinder.contains(Point<3>(0.3, 0.3, 1)));  // r = 0.424
  EXPECT_FALSE(cylinder.contains(Point<3>(0.4, 0.4, 1))); // r = 0.566
  EXPECT_TRUE(cylinder.contains(Point<3>(0, 0, 2 + 1e-10), 1e-9));
  EXPECT_DOUBLE_EQ(cylinder.volume_estimate(), M_PI * 0.25 * 2);

  // Inclined axis.
  const auto     inclined = parse3("cylinder(0,0,0, 1,1,1, 0.1)");
  const Point<3> mid(0.5, 0.5, 0.5);
  const Point<3> normal(1 / std::sqrt(2.), -1 / std::sqrt(2.), 0);
  EXPECT_TRUE(inclined.contains(mid + 0.09 * normal));
  EXPECT_FALSE(inclined.contains(mid + 0.11 * normal));
  EXPECT_FALSE(inclined.contains(Point<3>(1.05, 1.05, 1.05)));
  EXPECT_TRUE(inclined.contains(Point<3>(0.95, 0.95, 0.95)));
  EXPECT_FALSE(inclined.contains(Point<3>(-0.01, -0.01, -0.01)));
  EXPECT_NEAR(inclined.volume_estimate(), M_PI * 0.01 * std::sqrt(3.), 1e-14);
  // The exact bounding box of the inclined cylinder: r sqrt(1 - 1/3) beyond the ends.
  const auto bb = inclined.bounding_box().get_boundary_points();
  for (unsigned int d = 0; d < 3; ++d)
    {
      EXPECT_NEAR(bb.first[d], -0.1 * std::sqrt(2. / 3.), 1e-14);
      EXPECT_NEAR(bb.second[d], 1 + 0.1 * std::sqrt(2. / 3.), 1e-14);
    }
}



TEST(GeometryRegion, All)
{
  const auto all = parse2("all");
  EXPECT_TRUE(all.contains(Point<2>(1e10, -1e10)));
  EXPECT_TRUE(std::isinf(all.volume_estimate()));
  EXPECT_TRUE(std::isinf(all.bounding_box().get_boundary_points().second[0]));
  const auto holed = parse3("all() - sphere(0,0,0,1)");
  EXPECT_FALSE(holed.contains(Point<3>(0.5, 0, 0)));
  EXPECT_TRUE(holed.contains(Point<3>(5, 0, 0)));

  const Region<2> empty;
  EXPECT_TRUE(empty.is_empty());
  EXPECT_FALSE(empty.contains(Point<2>(0, 0)));
  EXPECT_EQ(empty.volume_estimate(), 0.0);
  EXPECT_EQ(empty.expression(), "");
}



TEST(GeometryRegion, UnionDifferencePrecedence)
{
  // a = [0,4], b = [1,3], c = [2,5] (in x, all of height 1).
  const auto left   = parse2("rectangle(0,0,4,1) - rectangle(1,0,3,1) + rectangle(2,0,5,1)");
  const auto nested = parse2("rectangle(0,0,4,1) - (rectangle(1,0,3,1) + rectangle(2,0,5,1))");
  const double expected_left[]   = {1, 0, 1, 1, 1, 0};
  const double expected_nested[] = {1, 0, 0, 0, 0, 0};
  const double xs[]              = {0.5, 1.5, 2.5, 3.5, 4.5, 5.5};
  for (unsigned int i = 0; i < 6; ++i)
    {
      EXPECT_EQ(left.contains(Point<2>(xs[i], 0.5)), expected_left[i] == 1) << xs[i];
      EXPECT_EQ(nested.contains(Point<2>(xs[i], 0.5)), expected_nested[i] == 1) << xs[i];
    }
  EXPECT_EQ(left.bounding_box().get_boundary_points().second[0], 5.0);
  EXPECT_EQ(nested.bounding_box().get_boundary_points().second[0], 4.0);
  EXPECT_NEAR(left.volume_estimate(), 4.0, 4.0 * 2e-3);
  EXPECT_NEAR(nested.volume_estimate(), 1.0, 1.0 * 5e-3);

  // Union is left-associative too: a - b - c == (a - b) - c.
  const auto chain = parse2("rectangle(0,0,4,1) - rectangle(1,0,2,1) - rectangle(3,0,5,1)");
  EXPECT_TRUE(chain.contains(Point<2>(2.5, 0.5)));
  EXPECT_FALSE(chain.contains(Point<2>(1.5, 0.5)));
  EXPECT_FALSE(chain.contains(Point<2>(3.5, 0.5)));
}



TEST(GeometryRegion, ToleranceSignFollowsDifferences)
{
  const auto r = parse2("rectangle(0,0,2,2) - disk(1,1,0.5)");
  const Point<2> on_hole(1.5, 1);
  EXPECT_FALSE(r.contains(on_hole));        // closed hole removes its boundary
  EXPECT_TRUE(r.contains(on_hole, 1e-9));   // the hole is deflated
  EXPECT_TRUE(r.contains(Point<2>(2 + 1e-10, 1), 1e-9)); // the rectangle is inflated
  EXPECT_FALSE(r.contains(Point<2>(1.4, 1), 1e-9));

  // a - (b - c): c is added back and therefore inflated.
  const auto n = parse2("rectangle(0,0,4,1) - (rectangle(1,0,3,1) - rectangle(2,0,3,1))");
  EXPECT_TRUE(n.contains(Point<2>(2.5, 0.5)));
  EXPECT_FALSE(n.contains(Point<2>(1.5, 0.5)));
  EXPECT_TRUE(n.contains(Point<2>(2 - 1e-10, 0.5), 1e-9));
  EXPECT_TRUE(n.contains(Point<2>(1 - 1e-10, 0.5), 1e-9));
}



TEST(GeometryRegion, WhitespaceNumbersAndCase)
{
  const auto r = parse2(" \t RECTANGLE ( -2.5e0 ,0,\n2.5E+0, 1e-3 )+disk(+10,-.5,0x1p-1) ");
  EXPECT_TRUE(r.contains(Point<2>(0, 5e-4)));
  EXPECT_FALSE(r.contains(Point<2>(0, 2e-3)));
  EXPECT_TRUE(r.contains(Point<2>(10, -0.9))); // disk radius 0x1p-1 = 0.5
  EXPECT_FALSE(r.contains(Point<2>(10, -1.1)));
  const auto p = parse2("((disk(0,0,1)))");
  EXPECT_TRUE(p.contains(Point<2>(0.9, 0)));
  EXPECT_DOUBLE_EQ(p.volume_estimate(), M_PI);
}



TEST(GeometryRegion, Errors)
{
  expect_error<2>("rectangle(0, 0, 2, 0.1) - circle(1, 0.05, 0.02)",
                  {"unknown shape 'circle' at position 27",
                   "(known in 2D: rectangle, disk, polygon, all)"});
  expect_error<3>("ball(0,0,0,1)", {"unknown shape 'ball'", "known in 3D: box, sphere, cylinder"});
  expect_error<2>("disk(0, 1)", {"disk needs 3 numbers (cx, cy, r), got 2"});
  expect_error<3>("cylinder(0,0,0, 0,0,1)", {"cylinder needs 7 numbers", "got 6"});
  expect_error<2>("rectangle(0,0,1,1,2)", {"rectangle needs 4 numbers", "got 5"});
  expect_error<2>("disk()", {"disk needs 3 numbers", "got 0"});
  expect_error<2>("disk(0, 0, -1)", {"radius must be > 0", "got -1"});
  expect_error<2>("disk(0, 0, 0)", {"radius must be > 0"});
  expect_error<3>("sphere(0, 0, 0, -2)", {"radius must be > 0"});
  expect_error<3>("cylinder(0,0,0, 0,0,1, 0)", {"radius must be > 0"});
  expect_error<2>("box(0,0,0, 1,1,1)", {"3D shape 'box' in a 2D scene", "position 1"});
  expect_error<3>("box(0,0,0, 1,1,1) + disk(0,0,1)", {"2D shape 'disk' in a 3D scene"});
  expect_error<2>("", {"empty"});
  expect_error<2>("  \t ", {"empty"});
  expect_error<2>("disk(0,0,1) x", {"unexpected 'x' at position 13"});
  expect_error<2>("disk(0,0,1) disk(0,0,2)", {"unexpected 'disk' at position 13"});
  expect_error<2>("(disk(0,0,1)", {"unbalanced parentheses", "'(' at position 1"});
  expect_error<2>("disk(0,0,1))", {"unbalanced parentheses", "')' at position 12"});
  expect_error<2>("disk(0,0,1", {"unbalanced parentheses", "'(' at position 5"});
  expect_error<2>("()", {"expected a shape or '(' at position 2, found ')'"});
  expect_error<2>("disk(0,0,inf)", {"non-finite number 'inf' at position 10"});
  expect_error<2>("disk(nan,0,1)", {"non-finite number 'nan'"});
  expect_error<2>("disk(1e999,0,1)", {"non-finite number '1e999'"});
  expect_error<2>("disk(0,0,1) +", {"expected a shape or '(' at position 14",
                                    "found the end of the expression"});
  expect_error<2>("- disk(0,0,1)", {"expected a shape or '(' at position 1, found '-'"});
  expect_error<2>("disk 0,0,1", {"expected '(' after 'disk'"});
  expect_error<2>("disk(0,0;1)", {"expected ',' or ')' at position 9"});
  expect_error<2>("disk(0,,1)", {"expected a number at position 8"});
  expect_error<2>("rectangle(0,0,0,1)", {"corners must differ"});
  expect_error<3>("cylinder(1,1,1, 1,1,1, 0.5)", {"axis end points must differ"});
  expect_error<2>("polygon(0,0, 1,0)", {"polygon needs an even number of at least 6 numbers"});
  expect_error<2>("polygon(0,0, 1,0, 1)", {"polygon needs an even number", "got 5"});
  expect_error<2>("polygon(0,0, 1,1, 1,0, 0,1)", {"not a simple polygon"}); // bow tie
  expect_error<2>("polygon(0,0, 1,0, 1,0, 0,1)", {"vertices 2 and 3 coincide"});
  expect_error<2>("polygon(0,0, 1,0, 2,0)", {"polygon"});
  std::string deep;
  for (unsigned int i = 0; i < 100; ++i)
    deep += "(";
  expect_error<2>(deep + "disk(0,0,1)", {"nested deeper"});
}



TEST(GeometryFill, AlignedRectangleExactCount)
{
  const auto     r = parse2("rectangle(0, 0, 2, 1)");
  FillLattice<2> lattice{Point<2>(-1, -1), 0.25, {{16, 12}}};
  for (const unsigned int k : {1u, 2u, 3u})
    {
      const auto points = fill(r, lattice, k);
      EXPECT_EQ(points.size(), 8u * 4u * k * k);
      EXPECT_NEAR(points.size() * fill_particle_volume(lattice, k), 2.0, 1e-12);
      for (const auto &p : points)
        EXPECT_TRUE(p[0] > 0 && p[0] < 2 && p[1] > 0 && p[1] < 1) << p;
    }
  // A region reaching beyond the lattice is clipped to it.
  const auto big = parse2("rectangle(-5, -5, 5, 5)");
  EXPECT_EQ(fill(big, lattice, 2).size(), 16u * 12u * 4u);
  // A region outside the lattice gives nothing.
  EXPECT_TRUE(fill(parse2("disk(10, 10, 1)"), lattice, 2).empty());
  EXPECT_TRUE(fill(Region<2>(), lattice, 2).empty());
}



TEST(GeometryFill, SubCellCentresOnTheBoundaryAreKept)
{
  // The boundary x = 0.25 passes through sub-cell centres (h = 1, k = 2): kept.
  const auto     r = parse2("rectangle(0.25, 0.25, 0.75, 0.75)");
  FillLattice<2> lattice{Point<2>(0, 0), 1.0, {{1, 1}}};
  EXPECT_EQ(fill(r, lattice, 2).size(), 4u);
}



TEST(GeometryFill, DiskArea)
{
  const double   R = 0.5;
  const auto     r = parse2("disk(0.3, 0.2, 0.5)");
  FillLattice<2> lattice{Point<2>(-1, -1), 0.02, {{100, 100}}};
  for (const unsigned int k : {1u, 2u})
    {
      const double area = filled_volume(r, lattice, k);
      EXPECT_LT(std::abs(area - M_PI * R * R), 2 * M_PI * R * lattice.h / k) << k;
    }
}



TEST(GeometryFill, RectangleMinusCentredDisk)
{
  const auto     r = parse2("rectangle(0, 0, 2, 2) - disk(1, 1, 0.5)");
  FillLattice<2> lattice{Point<2>(0, 0), 0.05, {{40, 40}}};
  const unsigned k      = 2;
  const auto     points = fill(r, lattice, k);
  const double   exact  = 4 - M_PI * 0.25;
  EXPECT_LT(std::abs(points.size() * fill_particle_volume(lattice, k) - exact),
            2 * M_PI * 0.5 * lattice.h / k);
  for (const auto &p : points)
    EXPECT_GT(p.distance(Point<2>(1, 1)), 0.5);
  EXPECT_NEAR(r.volume_estimate(), exact, 1e-3 * exact);
}



TEST(GeometryFill, Volumes3D)
{
  // A box aligned with the lattice: exact count.
  const auto     box = parse3("box(0,0,0, 1,0.5,0.25)");
  FillLattice<3> lattice{Point<3>(0, 0, 0), 0.125, {{10, 6, 4}}};
  const auto     points = fill(box, lattice, 2);
  EXPECT_EQ(points.size(), 8u * 4u * 2u * 8u);
  EXPECT_NEAR(points.size() * fill_particle_volume(lattice, 2), 0.125, 1e-12);

  // Cylinder along z: error bounded by the mantle area times h/k.
  const double   r = 0.3, L = 1, h = 0.05;
  const unsigned k = 2;
  FillLattice<3> fine{Point<3>(-0.5, -0.5, -0.25), h, {{20, 20, 30}}};
  const double   v = filled_volume(parse3("cylinder(0,0,0, 0,0,1, 0.3)"), fine, k);
  EXPECT_LT(std::abs(v - M_PI * r * r * L), 2 * M_PI * r * L * h / k);

  // Inclined cylinder: mantle and end faces.
  const double   li = std::sqrt(0.5 * 0.5 * 3);
  FillLattice<3> cube{Point<3>(-0.5, -0.5, -0.5), h, {{30, 30, 30}}};
  const double vi = filled_volume(parse3("cylinder(0,0,0, 0.5,0.5,0.5, 0.3)"), cube, k);
  EXPECT_LT(std::abs(vi - M_PI * r * r * li), (2 * M_PI * r * li + 2 * M_PI * r * r) * h / k);

  // Sphere.
  const double vs = filled_volume(parse3("sphere(0.1, 0, 0, 0.4)"), cube, k);
  EXPECT_LT(std::abs(vs - 4. / 3. * M_PI * 0.064), 4 * M_PI * 0.16 * h / k);
}



TEST(GeometryFill, DeterministicOrder)
{
  const auto     r = parse2("rectangle(0, 0, 2, 1)");
  FillLattice<2> lattice{Point<2>(0, 0), 1.0, {{2, 1}}};
  const std::vector<Point<2>> expected = {{0.25, 0.25},
                                          {0.75, 0.25},
                                          {0.25, 0.75},
                                          {0.75, 0.75},
                                          {1.25, 0.25},
                                          {1.75, 0.25},
                                          {1.25, 0.75},
                                          {1.75, 0.75}};
  const auto                  points   = fill(r, lattice, 2);
  ASSERT_EQ(points.size(), expected.size());
  for (unsigned int i = 0; i < points.size(); ++i)
    EXPECT_LT(points[i].distance(expected[i]), 1e-15) << i;

  // Repeated fills of a composite give identical results.
  const auto     c = parse2("disk(0,0,1) - polygon(0,0, 1,0, 0,1) + rectangle(0.5,0.5,1.5,0.7)");
  FillLattice<2> l2{Point<2>(-1.3, -1.2), 0.07, {{40, 40}}};
  const auto     first  = fill(c, l2, 3);
  const auto     second = fill(c, l2, 3);
  EXPECT_EQ(first, second);
  EXPECT_GT(first.size(), 1000u);
}



TEST(GeometryFill, KeepCellRangeAndVisitedCells)
{
  const auto                    c = parse2("disk(0,0,1)");
  FillLattice<2>                lattice{Point<2>(-2, -2), 0.1, {{40, 40}}};
  const std::array<unsigned int, 2> first{{0, 0}}, last{{39, 39}};
  const auto                    all  = fill(c, lattice, 2);
  const auto                    even = fill<2>(c, lattice, 2, first, last, [](const std::array<unsigned int, 2> &cell) {
    return cell[0] % 2 == 0;
  });
  std::vector<Point<2>> expected;
  for (const auto &p : all)
    if (static_cast<unsigned int>(std::floor((p[0] + 2) / 0.1)) % 2 == 0)
      expected.push_back(p);
  EXPECT_EQ(even, expected);
  EXPECT_LT(even.size(), all.size());

  // A box of cells (one MPI rank's part) gives bit for bit the full fill's points there,
  // in the same order: the positions come from the whole lattice.
  const std::array<unsigned int, 2> lo{{13, 21}}, hi{{27, 35}};
  const auto                        part = fill<2>(c, lattice, 2, lo, hi);
  expected.clear();
  for (const auto &p : all)
    {
      const auto i = static_cast<unsigned int>(std::floor((p[0] + 2) / 0.1));
      const auto j = static_cast<unsigned int>(std::floor((p[1] + 2) / 0.1));
      if (i >= lo[0] && i <= hi[0] && j >= lo[1] && j <= hi[1])
        expected.push_back(p);
    }
  EXPECT_EQ(part, expected);
  EXPECT_GT(part.size(), 100u);

  // Only cells meeting the bounding box [0,1]^2 are visited: 3 x 3 cells of [-10, 20]^2.
  const auto     square = parse2("rectangle(0,0,1,1)");
  FillLattice<2> coarse{Point<2>(-10, -10), 1.0, {{30, 30}}};
  unsigned int   n_visited = 0;
  const auto     points    = fill<2>(square, coarse, 1, {{0, 0}}, {{29, 29}}, [&](const std::array<unsigned int, 2> &) {
    ++n_visited;
    return true;
  });
  EXPECT_EQ(n_visited, 9u);
  EXPECT_EQ(points.size(), 1u);
}
