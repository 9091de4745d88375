// Unit tests of the RBSN tessellation: points along boundaries (with holes and
// curved edges), Poisson-disk nuclei, and the clipped Voronoi cells (areas and
// first moments add up to the domain's, facets are the common edges).
#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/region.h>
#include "rbsn/tessellation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace
{
  using namespace hysteron;
  using dealii::Point;

  Geometry::Region<2>
  parse(const std::string &expression)
  {
    return Geometry::Region<2>::parse(expression, "Body/plate/Shape");
  }

  /// The area of the polygon with vertices @p v (shoelace).
  double
  polygon_area(const std::vector<Point<2>> &v)
  {
    double a = 0;
    for (unsigned int i = 0; i < v.size(); ++i)
      a += v[i][0] * v[(i + 1) % v.size()][1] - v[(i + 1) % v.size()][0] * v[i][1];
    return 0.5 * std::abs(a);
  }

  unsigned int
  count(const std::vector<Point<2>> &points, const std::function<bool(const Point<2> &)> &where)
  {
    return std::count_if(points.begin(), points.end(), where);
  }
} // namespace



// A rectangle: the corners and evenly spread points, spacing at most the given one.
TEST(Tessellation, BoundaryPointsOfARectangle)
{
  const auto region = parse("rectangle(0, 0, 1, 0.5)");
  const auto p      = RBSN::boundary_points(region, 0.1, 0.025);
  EXPECT_EQ(p.size(), 30u); // perimeter 3 m / 0.1 m
  for (const auto &c : {Point<2>(0, 0), Point<2>(1, 0), Point<2>(1, 0.5), Point<2>(0, 0.5)})
    EXPECT_EQ(count(p, [&](const Point<2> &q) { return q.distance(c) < 1e-12; }), 1u) << c;
  EXPECT_EQ(count(p, [](const Point<2> &q) { return std::abs(q[1] - 0.5) < 1e-12; }), 11u);
}



// A hole inside: its polygon gets points too (the chords of a circle lie inside the
// exact disk, so the boundary is that of the polygonized domain), on the polygon.
TEST(Tessellation, BoundaryPointsOnAHole)
{
  const double r      = 0.1, h = 0.01;
  const auto   region = parse("rectangle(0, 0, 1, 0.5) - disk(0.5, 0.25, 0.1)");
  const auto   p      = RBSN::boundary_points(region, 0.05, h);
  const auto   on_hole = [&](const Point<2> &q) { return std::abs(q.distance(Point<2>(0.5, 0.25)) - r) < 2e-3 * r; };
  // 2 pi r / 0.05 = 12.6: 13 points, on the 64-gon (sagitta r (1 - cos(pi / 64)) = 1.2e-3 r).
  EXPECT_EQ(count(p, on_hole), 13u);
  EXPECT_EQ(p.size(), 60u + 13u);
  const auto polygonized = region.polygonized(h);
  for (const auto &q : p)
    EXPECT_TRUE(polygonized.contains(q, 1e-12)) << q;
}



// The perforated plate's quarter (dissertation §3.7.4): a hole through the corner.
// The straight edges keep their end points where the hole cuts them, so the
// symmetry lines x = 0 and y = 0 carry nuclei for the rollers.
TEST(Tessellation, BoundaryPointsOfAHoleThroughACorner)
{
  const auto region = parse("rectangle(0, 0, 0.25, 0.45) - disk(0, 0, 0.125)");
  const auto p      = RBSN::boundary_points(region, 0.05, 0.0125);
  const auto on     = [&](const Point<2> &c) {
    return count(p, [&](const Point<2> &q) { return q.distance(c) < 1e-12; }) == 1;
  };
  EXPECT_TRUE(on(Point<2>(0, 0.125)));
  EXPECT_TRUE(on(Point<2>(0.125, 0)));
  EXPECT_TRUE(on(Point<2>(0, 0.45)));
  EXPECT_TRUE(on(Point<2>(0.25, 0)));
  // x = 0 from 0.125 to 0.45: 0.325 / 0.05 -> 7 pieces, 8 points; y = 0: 0.125 / 0.05 -> 3, 4.
  EXPECT_EQ(count(p, [](const Point<2> &q) { return std::abs(q[0]) < 1e-12; }), 8u);
  EXPECT_EQ(count(p, [](const Point<2> &q) { return std::abs(q[1]) < 1e-12; }), 4u);
}



// The clipped cells tile the (polygonized) domain: their areas and first moments
// add up to the domain's exactly; every nucleus lies in its cell's body; random
// nuclei keep the minimum distance and approach the saturated density.
TEST(Tessellation, CellsTileThePerforatedDomain)
{
  const double d_m = 0.02, h = 0.005;
  const auto   region  = parse("rectangle(0, 0, 1, 0.5) - disk(0.5, 0.25, 0.1)");
  const auto   fixed   = RBSN::boundary_points(region, d_m, h);
  const auto   nuclei  = RBSN::poisson_disk_points(region, d_m, fixed, 42, "RBSN/Minimum distance");
  const auto   network = RBSN::voronoi(nuclei, {&region}, h, "Body names");
  ASSERT_EQ(network.cells.size(), nuclei.size());

  const auto   hole      = Geometry::Region<2>::disk_polygon(Point<2>(0.5, 0.25), 0.1, h);
  const double area      = 0.5 - polygon_area(hole);
  double       sum       = 0;
  Point<2>     moment;
  for (const auto &c : network.cells)
    {
      EXPECT_GT(c.area, 0);
      sum += c.area;
      moment += c.area * c.centroid;
    }
  EXPECT_NEAR(sum / area, 1, 1e-12);
  // The domain's centroid is the rectangle's (the hole is centred in it).
  EXPECT_NEAR(moment[0] / sum, 0.5, 1e-12);
  EXPECT_NEAR(moment[1] / sum, 0.25, 1e-12);

  // Minimum distance between random nuclei (the fixed ones are at spacing <= d_m).
  double closest = 1e300;
  for (unsigned int i = fixed.size(); i < nuclei.size(); ++i)
    for (unsigned int j = 0; j < i; ++j)
      closest = std::min(closest, nuclei[i].distance(nuclei[j]));
  EXPECT_GE(closest, d_m);
  // Saturation: 0.68 A / d_m^2 points, here within 15 % (the boundary rows are denser).
  EXPECT_NEAR(nuclei.size() / (0.68 * area / (d_m * d_m)), 1.0, 0.15);

  // Facets: between distinct cells, inside the domain, of positive length, normal
  // from a to b; a cell's facets and boundary pieces close its outline.
  for (const auto &f : network.facets)
    {
      EXPECT_LT(f.a, f.b);
      EXPECT_GT(f.length, 0);
      EXPECT_TRUE(region.polygonized(h).contains(f.midpoint, 1e-9));
      EXPECT_GT(f.normal * (network.cells[f.b].nucleus - network.cells[f.a].nucleus), 0);
      EXPECT_NEAR(f.distance, network.cells[f.a].nucleus.distance(network.cells[f.b].nucleus), 1e-14);
    }
  double boundary = 0;
  for (const auto &c : network.cells)
    for (const auto &piece : c.boundary)
      boundary += piece[0].distance(piece[1]);
  double hole_perimeter = 0;
  for (unsigned int i = 0; i < hole.size(); ++i)
    hole_perimeter += hole[i].distance(hole[(i + 1) % hole.size()]);
  EXPECT_NEAR(boundary, 3 + hole_perimeter, 1e-12);
}



// A square grid of nuclei: square cells of the grid spacing, facets of that
// length between neighbours only (4 per interior cell, no diagonal ones).
TEST(Tessellation, RegularGridGivesSquareCells)
{
  const auto            region = parse("rectangle(0, 0, 1, 0.5)");
  std::vector<Point<2>> nuclei;
  for (unsigned int j = 0; j < 5; ++j)
    for (unsigned int i = 0; i < 10; ++i)
      nuclei.emplace_back(0.05 + 0.1 * i, 0.05 + 0.1 * j);
  const auto network = RBSN::voronoi(nuclei, {&region}, 0.1, "Body names");
  ASSERT_EQ(network.cells.size(), 50u);
  for (const auto &c : network.cells)
    EXPECT_NEAR(c.area, 0.01, 1e-15);
  unsigned int n = 0;
  for (const auto &f : network.facets)
    if (f.length > 1e-9)
      {
        ++n;
        EXPECT_NEAR(f.length, 0.1, 1e-12);
        EXPECT_NEAR(f.distance, 0.1, 1e-12);
      }
  EXPECT_EQ(n, 9u * 5u + 10u * 4u);
}



// A nucleus outside the domain is an input error naming the parameter.
TEST(Tessellation, NucleusOutsideTheDomain)
{
  const auto region = parse("rectangle(0, 0, 1, 0.5)");
  EXPECT_THROW(RBSN::voronoi({Point<2>(0.5, 0.25), Point<2>(2, 0.25)}, {&region}, 0.1, "Body names"),
               InputError);
}
