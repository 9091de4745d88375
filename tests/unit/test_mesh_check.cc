// Unit tests of the cell checks of FEM meshes (cell_defect, check_cells) and of structured
// meshes built from a coarse mesh and global refinements (coarse_structured_mesh).
#include <deal.II/base/mpi.h>

#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/mesh.h>
#include <hysteron/geometry/region.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace
{
  using namespace hysteron;
  using namespace hysteron::Geometry;
  using dealii::Point;

  const std::string where = "FEM/Mesh/Cell size";

  /// A unit square's lexicographic vertices, optionally moved.
  std::vector<Point<2>>
  square(const std::map<unsigned int, Point<2>> &moved = {})
  {
    std::vector<Point<2>> x = {Point<2>(0, 0), Point<2>(1, 0), Point<2>(0, 1), Point<2>(1, 1)};
    for (const auto &[v, p] : moved)
      x[v] = p;
    return x;
  }

  std::string
  defect(const std::vector<Point<2>> &x, bool &inverted)
  {
    return cell_defect<2>(x, inverted);
  }

  std::vector<Point<3>>
  cube()
  {
    std::vector<Point<3>> x;
    for (unsigned int v = 0; v < 8; ++v)
      x.emplace_back(v & 1, (v >> 1) & 1, (v >> 2) & 1);
    return x;
  }
} // namespace



TEST(MeshCheck, GoodCellsOfAnyAspectRatio)
{
  bool inverted = true;
  EXPECT_EQ(defect(square(), inverted), "");
  EXPECT_FALSE(inverted);
  // 1 x 1e-6: thin, but 1e6 is not a sliver (the measure limit is 1e-8 diameter^2)
  EXPECT_EQ(defect(square({{2, Point<2>(0, 1e-6)}, {3, Point<2>(1, 1e-6)}}), inverted), "");
  // a convex quadrilateral with a 169-degree corner (the unstructured generator's go to 166)
  EXPECT_EQ(defect(square({{3, Point<2>(0.55, 0.55)}}), inverted), "");
  EXPECT_EQ(defect({Point<2>(0, 0), Point<2>(1, 0), Point<2>(0, 1)}, inverted), "");
  EXPECT_EQ(cell_defect<3>(cube(), inverted), "");
  EXPECT_EQ(cell_defect<3>({Point<3>(0, 0, 0), Point<3>(1, 0, 0), Point<3>(0, 1, 0), Point<3>(0, 0, 1)}, inverted), "");
  EXPECT_FALSE(inverted);
}



TEST(MeshCheck, InvertedCellsAreRepairable)
{
  bool inverted = false;
  // mirrored: x -> -x
  EXPECT_EQ(defect({Point<2>(0, 0), Point<2>(-1, 0), Point<2>(0, 1), Point<2>(-1, 1)}, inverted), "");
  EXPECT_TRUE(inverted);
  EXPECT_EQ(defect({Point<2>(0, 0), Point<2>(0, 1), Point<2>(1, 0)}, inverted), ""); // clockwise
  EXPECT_TRUE(inverted);
  auto x = cube();
  std::rotate(x.begin(), x.begin() + 4, x.end()); // top and bottom swapped
  EXPECT_EQ(cell_defect<3>(x, inverted), "");
  EXPECT_TRUE(inverted);
}



TEST(MeshCheck, DefectsNamed)
{
  bool inverted = false;
  // vertices 2 and 3 swapped: two edges cross (a bow-tie)
  EXPECT_NE(defect(square({{2, Point<2>(1, 1)}, {3, Point<2>(0, 1)}}), inverted).find("bow-tie"),
            std::string::npos);
  // a re-entrant corner: not convex
  EXPECT_NE(defect(square({{3, Point<2>(0.3, 0.3)}}), inverted).find("changes sign"), std::string::npos);
  EXPECT_NE(defect(square({{3, Point<2>(0, 1)}}), inverted).find("coincide (at (0, 1))"), std::string::npos);
  EXPECT_NE(defect(square({{2, Point<2>(0, 1e-10)}, {3, Point<2>(1, 1e-10)}}), inverted).find("sliver"),
            std::string::npos);
  EXPECT_NE(defect({Point<2>(0, 0), Point<2>(1, 0), Point<2>(0.5, 1e-12)}, inverted).find("sliver"),
            std::string::npos);
  // three vertices on a line: a flat 180-degree corner
  EXPECT_NE(defect(square({{3, Point<2>(2, 0)}}), inverted).find("degenerate"), std::string::npos);
  // a hexahedron with a corner pushed inside: det J < 0 there, > 0 at the opposite corner
  auto x = cube();
  x[7]   = Point<3>(0.2, 0.2, 0.2);
  EXPECT_NE(cell_defect<3>(x, inverted).find("changes sign"), std::string::npos);
}



TEST(MeshCheck, CheckCellsRepairsInvertedCells)
{
  // two unit squares side by side, the second listed mirrored
  std::vector<Point<2>> vertices = {Point<2>(0, 0), Point<2>(1, 0), Point<2>(2, 0),
                                    Point<2>(0, 1), Point<2>(1, 1), Point<2>(2, 1)};
  std::vector<dealii::CellData<2>> cells(2);
  cells[0].vertices = {0, 1, 3, 4};
  cells[1].vertices = {2, 1, 5, 4};
  const CellCheck check = check_cells(vertices, cells);
  EXPECT_TRUE(check.valid);
  EXPECT_EQ(check.inverted, 1u);
  for (const auto &cell : cells)
    EXPECT_GT(dealii::GridTools::cell_measure<2>(vertices, cell.vertices), 0);
  dealii::Triangulation<2> tria;
  tria.create_triangulation(vertices, cells, dealii::SubCellData());
  EXPECT_NEAR(dealii::GridTools::volume(tria), 2, 1e-14);

  cells[1].vertices = {1, 2, 5, 4}; // a bow-tie
  const CellCheck bad = check_cells(vertices, cells);
  EXPECT_FALSE(bad.valid);
  EXPECT_EQ(bad.cell, 1u);
  EXPECT_EQ(vertex_list(vertices, cells[1]), "(1, 0), (2, 0), (1, 1), (2, 1)");
}



TEST(MeshStructuredCoarse, ExactLevels)
{
  // 1 x 0.1 at h = 0.0125: 80 x 8 cells, below 4096: its own coarse mesh
  const Region<2> bar = Region<2>::parse("rectangle(0, 0, 1, 0.1)", where);
  const auto      fine = structured_mesh<2>({&bar}, 0.0125, where);
  EXPECT_EQ(coarse_structured_mesh<2>({&bar}, 0.0125, where, 4096, 1.2).levels, 0u);
  // at most 10 coarse cells: a coarse 10 x 1 mesh refined 3 times
  const auto s = coarse_structured_mesh<2>({&bar}, 0.0125, where, 10, 1.2);
  EXPECT_EQ(s.levels, 3u);
  EXPECT_EQ(s.coarse.cells.size(), 10u);
  EXPECT_EQ(s.n_cells, 640);
  EXPECT_TRUE(s.note.empty());
  // the refined coarse mesh has the fine mesh's cells (vertices to round-off)
  dealii::Triangulation<2> tria;
  tria.create_triangulation(s.coarse.vertices, s.coarse.cells, dealii::SubCellData());
  tria.refine_global(s.levels);
  std::vector<Point<2>> centres;
  for (const auto &cell : tria.active_cell_iterators())
    centres.push_back(cell->center());
  ASSERT_EQ(centres.size(), fine.cells.size());
  const auto less = [](const Point<2> &a, const Point<2> &b) {
    return std::make_pair(std::round(a[1] * 1e9), a[0]) < std::make_pair(std::round(b[1] * 1e9), b[0]);
  };
  std::sort(centres.begin(), centres.end(), less);
  std::vector<Point<2>> expected;
  for (const auto &cell : fine.cells)
    {
      Point<2> c;
      for (const unsigned int v : cell.vertices)
        c += fine.vertices[v] / 4.0;
      expected.push_back(c);
    }
  std::sort(expected.begin(), expected.end(), less);
  for (unsigned int i = 0; i < centres.size(); ++i)
    EXPECT_LT(centres[i].distance(expected[i]), 1e-14);
}



TEST(MeshStructuredCoarse, TwoBodiesKeepTheirCells)
{
  // a column on a slab (the intervals 0.35, 0.15, 0.5 x 0.2, 1.1 at h = 0.05: 7, 3, 10 x 4, 22
  // cells): 3 and 7 are odd, so the exact level is 0 and the 20 x 26 grid is the coarse mesh
  const Region<2> slab   = Region<2>::parse("rectangle(0, 0, 1, 0.2)", where);
  const Region<2> column = Region<2>::parse("rectangle(0.35, 0.2, 0.5, 1.3)", where);
  const auto      s      = coarse_structured_mesh<2>({&slab, &column}, 0.05, where, 4096, 1.2);
  EXPECT_EQ(s.levels, 0u);
  EXPECT_EQ(s.coarse.cells.size(), structured_mesh<2>({&slab, &column}, 0.05, where).cells.size());
  // h = 0.025: 14, 6, 20 x 8, 44 cells (a 40 x 52 grid), at most 1000 coarse cells: one level
  const auto t = coarse_structured_mesh<2>({&slab, &column}, 0.025, where, 1000, 1.2);
  EXPECT_EQ(t.levels, 1u);
  std::size_t n[2] = {0, 0};
  for (const auto &cell : t.coarse.cells)
    ++n[cell.material_id];
  EXPECT_EQ(n[0] * 4, 40u * 8u);
  EXPECT_EQ(n[1] * 4, 6u * 44u);
}



TEST(MeshStructuredCoarse, RoundedOrWhole)
{
  // 1001 x 3 cells: odd, 3003 cells > 1000 allowed coarse cells; counts rounded up to
  // multiples of 2 leave 501 x 2 coarse cells, to multiples of 4 (1004 x 4: 33.7 % more cells)
  // exceed a 20 % growth: the mesh is not coarsened
  const Region<2> bar = Region<2>::parse("rectangle(0, 0, 1.001, 0.003)", where);
  EXPECT_TRUE(coarse_structured_mesh<2>({&bar}, 0.001, where, 1000, 1.2).coarse.cells.empty());
  // 1001 x 64 cells: rounded to multiples of 8 (1008 x 64 = 0.7 % more), 126 x 8 coarse cells
  const Region<2> wide = Region<2>::parse("rectangle(0, 0, 1.001, 0.064)", where);
  const auto      s    = coarse_structured_mesh<2>({&wide}, 0.001, where, 1008, 1.2);
  EXPECT_EQ(s.levels, 3u);
  EXPECT_EQ(s.coarse.cells.size(), 126u * 8u);
  EXPECT_EQ(s.n_cells, 1008 * 64);
  EXPECT_NE(s.note.find("rounded up to multiples of 2^3"), std::string::npos);
  // a disk is not rectilinear: never coarsened, whole if large
  const Region<2> disk = Region<2>::parse("disk(0, 0, 1)", where);
  EXPECT_TRUE(coarse_structured_mesh<2>({&disk}, 0.01, where, 4096, 1.2).coarse.cells.empty());
  EXPECT_EQ(coarse_structured_mesh<2>({&disk}, 0.5, where, 4096, 1.2).levels, 0u);
}
