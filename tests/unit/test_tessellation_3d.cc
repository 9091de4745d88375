// Unit tests of the 3D RBSN geometry (doc/rbsn/geometry_3d.md).
#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/region.h>
#include <hysteron/rbsn/tessellation.h>

#include "rbsn/polyhedron.h"

#include <gtest/gtest.h>

namespace
{
  using namespace hysteron;
  using dealii::Point;
}

TEST(Tessellation3D, Smoke)
{
  const auto region = Geometry::Region<3>::parse("box(0, 0, 0, 1, 0.5, 0.4)", "Body/b/Shape");
  const RBSN::Spacing<3> d(0.1);
  const auto b = RBSN::boundary_points(region, d, 0.025, 1);
  const auto p = RBSN::poisson_disk_points(region, d, b, 2, "RBSN", 0.025);
  const auto t = RBSN::voronoi(p, {&region}, 0.025, "Body names");
  double v = 0;
  for (const auto &c : t.cells)
    v += c.volume;
  std::cout << b.size() << " " << p.size() << " " << t.facets.size() << " " << v << std::endl;
  EXPECT_NEAR(v, 0.2, 1e-12);
}
