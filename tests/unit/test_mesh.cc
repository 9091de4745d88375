// Unit tests of the FEM mesh generators (structured_mesh, unstructured_mesh) and
// of the region helpers they use (polygonized, boundary_segments).
#include <deal.II/base/mpi.h>

#include <deal.II/distributed/tria.h>

#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/mesh.h>
#include <hysteron/geometry/region.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <map>
#include <memory>
#include <set>

namespace
{
  using namespace hysteron;
  using namespace hysteron::Geometry;
  using dealii::Point;

  const std::string where = "FEM/Mesh";

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

  template <int dim>
  std::vector<const Region<dim> *>
  pointers(const std::vector<Region<dim>> &regions)
  {
    std::vector<const Region<dim> *> p;
    for (const auto &r : regions)
      p.push_back(&r);
    return p;
  }

  template <int dim>
  bool
  in_union(const std::vector<Region<dim>> &bodies, const Point<dim> &p)
  {
    for (const auto &b : bodies)
      if (b.contains(p))
        return true;
    return false;
  }

  template <int dim>
  Point<dim>
  cell_centre(const CoarseMesh<dim> &mesh, const dealii::CellData<dim> &cell)
  {
    Point<dim> c;
    for (const unsigned int v : cell.vertices)
      c += mesh.vertices[v] / static_cast<double>(cell.vertices.size());
    return c;
  }

  /// The vertices of the faces of a cell in deal.II's numbering, as sorted keys.
  template <int dim>
  std::vector<std::vector<unsigned int>>
  face_keys(const dealii::CellData<dim> &cell)
  {
    std::vector<std::vector<unsigned int>> keys;
    for (unsigned int f = 0; f < dealii::GeometryInfo<dim>::faces_per_cell; ++f)
      {
        std::vector<unsigned int> key;
        for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_face; ++v)
          key.push_back(cell.vertices[dealii::GeometryInfo<dim>::face_to_cell_vertices(f, v)]);
        std::sort(key.begin(), key.end());
        keys.push_back(key);
      }
    return keys;
  }

  /**
   * deal.II's orientation requirement: every line (from its first to its second
   * vertex in the cell's local numbering) runs the same way in all cells that
   * share it.
   */
  template <int dim>
  void
  expect_consistent_lines(const CoarseMesh<dim> &mesh)
  {
    std::map<std::pair<unsigned int, unsigned int>, bool> forward; // key (min, max)
    std::size_t                                           n_bad = 0;
    for (const auto &cell : mesh.cells)
      for (unsigned int l = 0; l < dealii::GeometryInfo<dim>::lines_per_cell; ++l)
        {
          using Info             = dealii::GeometryInfo<dim>;
          const unsigned int a   = cell.vertices[Info::line_to_cell_vertices(l, 0)];
          const unsigned int b   = cell.vertices[Info::line_to_cell_vertices(l, 1)];
          const auto         key = std::make_pair(std::min(a, b), std::max(a, b));
          const auto [it, inserted] = forward.emplace(key, a < b);
          if (!inserted && it->second != (a < b))
            ++n_bad;
        }
    EXPECT_EQ(n_bad, 0u) << "lines oriented differently by neighbouring cells";
  }

  /**
   * The mesh is conforming: no face is shared by more than two cells, and every
   * face of only one cell lies on the boundary of the union of @p bodies (just
   * off its centre on the two sides of the face, one point is inside and one
   * outside; a hanging node would give an interior face of one cell).
   * Returns the number of boundary faces and checks the counts add up.
   */
  template <int dim>
  std::size_t
  expect_conforming(const CoarseMesh<dim> &mesh, const std::vector<Region<dim>> &bodies,
                    const double offset, const bool boundary_faces_on_the_boundary = true)
  {
    expect_consistent_lines(mesh);
    std::map<std::vector<unsigned int>, unsigned int> count;
    for (const auto &cell : mesh.cells)
      for (const auto &key : face_keys<dim>(cell))
        ++count[key];
    std::size_t n_boundary = 0, n_interior = 0, n_bad = 0;
    for (const auto &[key, n] : count)
      {
        EXPECT_LE(n, 2u);
        if (n == 2)
          {
            ++n_interior;
            continue;
          }
        ++n_boundary;
        if (!boundary_faces_on_the_boundary)
          continue;
        // The face centre and its unit normal (2D: perpendicular to the edge;
        // 3D: cross product of the diagonals of the planar face).
        Point<dim> centre;
        for (const unsigned int v : key)
          centre += mesh.vertices[v] / static_cast<double>(key.size());
        dealii::Tensor<1, dim> normal;
        if constexpr (dim == 2)
          {
            const auto e = mesh.vertices[key[1]] - mesh.vertices[key[0]];
            normal[0]    = -e[1];
            normal[1]    = e[0];
          }
        else
          {
            // key is sorted; find the face's cyclic order through the distances
            const auto &p0 = mesh.vertices[key[0]];
            unsigned int far = 1;
            for (unsigned int k = 2; k < 4; ++k)
              if (p0.distance(mesh.vertices[key[k]]) > p0.distance(mesh.vertices[key[far]]))
                far = k;
            std::vector<unsigned int> others;
            for (unsigned int k = 1; k < 4; ++k)
              if (k != far)
                others.push_back(k);
            normal = dealii::cross_product_3d(mesh.vertices[key[far]] - p0,
                                              mesh.vertices[key[others[1]]] -
                                                mesh.vertices[key[others[0]]]);
          }
        normal /= normal.norm();
        const bool a = in_union(bodies, Point<dim>(centre + offset * normal));
        const bool b = in_union(bodies, Point<dim>(centre - offset * normal));
        if (a == b)
          ++n_bad;
      }
    EXPECT_EQ(n_bad, 0u) << "faces of one cell that are not on the boundary";
    EXPECT_EQ(2 * n_interior + n_boundary,
              mesh.cells.size() * dealii::GeometryInfo<dim>::faces_per_cell);
    return n_boundary;
  }

  /// Every cell's material id is the first body containing its centre.
  template <int dim>
  void
  expect_material_ids(const CoarseMesh<dim> &mesh, const std::vector<Region<dim>> &bodies)
  {
    for (const auto &cell : mesh.cells)
      {
        const Point<dim> c = cell_centre(mesh, cell);
        ASSERT_LT(cell.material_id, bodies.size());
        EXPECT_TRUE(bodies[cell.material_id].contains(c));
        for (unsigned int i = 0; i < cell.material_id; ++i)
          EXPECT_FALSE(bodies[i].contains(c));
      }
  }

  /// Every vertex is used by a cell.
  template <int dim>
  void
  expect_all_vertices_used(const CoarseMesh<dim> &mesh)
  {
    std::vector<bool> used(mesh.vertices.size(), false);
    for (const auto &cell : mesh.cells)
      for (const unsigned int v : cell.vertices)
        {
          ASSERT_LT(v, mesh.vertices.size());
          used[v] = true;
        }
    EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
  }

  /// A quad's vertices counter-clockwise (deal.II numbers them 0, 1, 3, 2 around).
  std::array<Point<2>, 4>
  cycle(const CoarseMesh<2> &mesh, const dealii::CellData<2> &cell)
  {
    return {{mesh.vertices[cell.vertices[0]], mesh.vertices[cell.vertices[1]],
             mesh.vertices[cell.vertices[3]], mesh.vertices[cell.vertices[2]]}};
  }

  double
  cross(const dealii::Tensor<1, 2> &a, const dealii::Tensor<1, 2> &b)
  {
    return a[0] * b[1] - a[1] * b[0];
  }

  struct QuadStatistics
  {
    double min_jacobian_ratio = 1e300; ///< min det J at a vertex / cell area
    double min_angle          = 180;   ///< degrees
    double max_angle          = 0;
    double max_edge           = 0;
  };

  QuadStatistics
  quad_statistics(const CoarseMesh<2> &mesh)
  {
    QuadStatistics s;
    for (const auto &cell : mesh.cells)
      {
        const auto &v = cell.vertices;
        const auto &x = mesh.vertices;
        const double area =
          dealii::GridTools::cell_measure<2>(x, dealii::ArrayView<const unsigned int>(v));
        // det J of the bilinear map at the vertices (xi, eta) in {0, 1}^2.
        const double det[4] = {cross(x[v[1]] - x[v[0]], x[v[2]] - x[v[0]]),
                               cross(x[v[1]] - x[v[0]], x[v[3]] - x[v[1]]),
                               cross(x[v[3]] - x[v[2]], x[v[2]] - x[v[0]]),
                               cross(x[v[3]] - x[v[2]], x[v[3]] - x[v[1]])};
        for (const double d : det)
          s.min_jacobian_ratio = std::min(s.min_jacobian_ratio, d / area);
        const auto c = cycle(mesh, cell);
        for (unsigned int k = 0; k < 4; ++k)
          {
            const auto   e1 = c[(k + 1) % 4] - c[k], e0 = c[(k + 3) % 4] - c[k];
            const double angle =
              std::acos(std::max(-1.0, std::min(1.0, e0 * e1 / (e0.norm() * e1.norm()))));
            s.min_angle = std::min(s.min_angle, angle * 180 / M_PI);
            s.max_angle = std::max(s.max_angle, angle * 180 / M_PI);
            s.max_edge  = std::max(s.max_edge, e1.norm());
          }
      }
    return s;
  }

  double
  polygon_area(const std::vector<Point<2>> &v)
  {
    double twice = 0;
    for (unsigned int i = 0, j = v.size() - 1; i < v.size(); j = i++)
      twice += v[j][0] * v[i][1] - v[i][0] * v[j][1];
    return 0.5 * std::abs(twice);
  }

  double
  distance_to_segment(const Point<2> &p, const Point<2> &a, const Point<2> &b)
  {
    const auto   e = b - a;
    const double t = std::max(0.0, std::min(1.0, (p - a) * e / (e * e)));
    return p.distance(Point<2>(a + t * e));
  }

  /// Expect InputError naming `where` whose problem contains @p phrase.
  template <typename F>
  void
  expect_input_error(F &&f, const std::string &phrase)
  {
    try
      {
        f();
        ADD_FAILURE() << "no error (expected '" << phrase << "')";
      }
    catch (const InputError &e)
      {
        EXPECT_EQ(e.where(), where);
        EXPECT_NE(std::string(e.what()).find(where), std::string::npos);
        EXPECT_NE(e.problem().find(phrase), std::string::npos)
          << "'" << e.problem() << "' lacks '" << phrase << "'";
      }
  }

  const double min_angle_bound = std::asin(std::sqrt(0.125)) * 180 / M_PI; // 20.70 degrees

  /// A hash (FNV-1a) of the vertices' bits, the cells' vertices and material ids.
  std::uint64_t
  mesh_hash(const CoarseMesh<2> &mesh)
  {
    std::uint64_t hash = 14695981039346656037ull;
    const auto    add  = [&hash](const void *data, const std::size_t n) {
      const unsigned char *bytes = static_cast<const unsigned char *>(data);
      for (std::size_t i = 0; i < n; ++i)
        hash = (hash ^ bytes[i]) * 1099511628211ull;
    };
    for (const auto &p : mesh.vertices)
      for (unsigned int d = 0; d < 2; ++d)
        add(&p[d], sizeof(double));
    for (const auto &cell : mesh.cells)
      {
        add(cell.vertices.data(), cell.vertices.size() * sizeof(unsigned int));
        add(&cell.material_id, sizeof(cell.material_id));
      }
    return hash;
  }
} // namespace



// ------------------------------------------------------------------------------
// Region helpers
// ------------------------------------------------------------------------------

TEST(RegionPrimitives, ReadAccess)
{
  const auto r = parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25) + polygon(0,0, 1,0, 0,1)");
  const auto &q = r.get_primitives();
  ASSERT_EQ(q.size(), 3u);
  EXPECT_EQ(q[0].kind, Region<2>::Kind::rectangle);
  EXPECT_EQ(q[1].kind, Region<2>::Kind::disk);
  EXPECT_EQ(q[1].sign, -1.0);
  EXPECT_EQ(q[2].kind, Region<2>::Kind::polygon);
  EXPECT_EQ(r.get_program().size(), 5u); // push push subtract push unite
  const auto v = r.polygon_vertices(q[2]);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[1], Point<2>(1, 0));
  EXPECT_TRUE(is_rectilinear(parse2("rectangle(0,0,1,1) - rectangle(0.2,0.2,0.4,0.4) + all")));
  EXPECT_FALSE(is_rectilinear(r));
  EXPECT_TRUE(is_rectilinear(parse3("box(0,0,0,1,1,1) + box(1,0,0,2,1,1)")));
  EXPECT_FALSE(is_rectilinear(parse3("box(0,0,0,1,1,1) - sphere(0,0,0,0.5)")));
}



TEST(RegionPolygonized, DiskBecomesRegularPolygon)
{
  // n = max(16, ceil(2 pi r / h)) rounded up to a multiple of 4
  EXPECT_EQ(Region<2>::n_disk_sides(0.25, 0.01), 160u); // ceil(157.08) = 158 -> 160
  EXPECT_EQ(Region<2>::n_disk_sides(0.25, 1.0), 16u);
  EXPECT_EQ(Region<2>::n_disk_sides(1.0, 2 * M_PI / 17), 20u);

  const Point<2> c(1, 0.5);
  const double   r = 0.25, h = 0.01;
  const auto     v = Region<2>::disk_polygon(c, r, h);
  ASSERT_EQ(v.size(), 160u);
  // axis points exact, counter-clockwise from (cx + r, cy)
  EXPECT_EQ(v[0], Point<2>(1.25, 0.5));
  EXPECT_EQ(v[40], Point<2>(1, 0.75));
  EXPECT_EQ(v[80], Point<2>(0.75, 0.5));
  EXPECT_EQ(v[120], Point<2>(1, 0.25));
  double max_side = 0;
  for (unsigned int i = 0; i < v.size(); ++i)
    {
      EXPECT_NEAR(v[i].distance(c), r, 1e-15);
      EXPECT_GT(cross(v[i] - c, v[(i + 1) % v.size()] - c), 0);
      max_side = std::max(max_side, v[i].distance(v[(i + 1) % v.size()]));
    }
  EXPECT_LE(max_side, h);
  EXPECT_NEAR(polygon_area(v), 0.5 * 160 * r * r * std::sin(2 * M_PI / 160), 1e-15);

  const auto disk = parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)");
  const auto poly = disk.polygonized(h);
  EXPECT_EQ(poly.expression(), disk.expression());
  EXPECT_EQ(poly.bounding_box().get_boundary_points(), disk.bounding_box().get_boundary_points());
  ASSERT_EQ(poly.get_primitives().size(), 2u);
  EXPECT_EQ(poly.get_primitives()[1].kind, Region<2>::Kind::polygon);
  EXPECT_EQ(poly.get_primitives()[1].sign, -1.0);
  EXPECT_EQ(poly.polygon_vertices(poly.get_primitives()[1]), v); // bit for bit

  // Between the polygon and the circle the two regions differ.
  const Point<2> side_midpoint(0.5 * (v[3] + v[4]));
  const Point<2> between(c + (side_midpoint - c) * (1 + 0.5 * (r / side_midpoint.distance(c) - 1)));
  EXPECT_TRUE(poly.contains(between));
  EXPECT_FALSE(disk.contains(between));
  EXPECT_FALSE(poly.contains(Point<2>(1, 0.5)));
  EXPECT_TRUE(poly.contains(Point<2>(0.1, 0.1)));
  EXPECT_THROW(parse3("sphere(0, 0, 0, 1)").polygonized(h), dealii::ExceptionBase);
}



TEST(RegionPolygonized, BoundarySegments)
{
  const double h    = 0.05;
  const auto   r =
    parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25) + polygon(3,0, 4,0, 3,1) + all");
  const auto   segs = r.boundary_segments(h);
  const unsigned int n = Region<2>::n_disk_sides(0.25, h);
  ASSERT_EQ(segs.size(), 4 + n + 3);
  EXPECT_EQ(segs[0][0], Point<2>(0, 0));
  EXPECT_EQ(segs[0][1], Point<2>(2, 0));
  EXPECT_EQ(segs[3][1], Point<2>(0, 0));
  const auto v = Region<2>::disk_polygon(Point<2>(1, 0.5), 0.25, h);
  for (unsigned int i = 0; i < n; ++i)
    {
      EXPECT_EQ(segs[4 + i][0], v[i]);
      EXPECT_EQ(segs[4 + i][1], v[(i + 1) % n]);
    }
  EXPECT_EQ(segs[4 + n + 2][0], Point<2>(3, 1));
  EXPECT_EQ(segs[4 + n + 2][1], Point<2>(3, 0));
  EXPECT_THROW(parse3("box(0,0,0,1,1,1)").boundary_segments(h), dealii::ExceptionBase);
}



// ------------------------------------------------------------------------------
// structured_mesh
// ------------------------------------------------------------------------------

TEST(MeshStructured, Rectangle)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 1, 0.1)")};
  const auto                   mesh   = structured_mesh<2>(pointers(bodies), 0.025, where);
  EXPECT_EQ(mesh.cells.size(), 40u * 4u);
  EXPECT_EQ(mesh.vertices.size(), 41u * 5u);
  EXPECT_NEAR(mesh.volume(), 0.1, 1e-14);
  for (const auto &cell : mesh.cells)
    {
      EXPECT_EQ(cell.material_id, 0u);
      const auto &x = mesh.vertices;
      EXPECT_NEAR(x[cell.vertices[1]][0] - x[cell.vertices[0]][0], 0.025, 1e-15);
      EXPECT_NEAR(x[cell.vertices[2]][1] - x[cell.vertices[0]][1], 0.025, 1e-15);
      EXPECT_EQ(x[cell.vertices[3]][0], x[cell.vertices[1]][0]);
      EXPECT_EQ(x[cell.vertices[3]][1], x[cell.vertices[2]][1]);
    }
  EXPECT_EQ(mesh.vertices.front(), Point<2>(0, 0));
  EXPECT_EQ(mesh.vertices.back(), Point<2>(1, 0.1)); // box ends exact
  EXPECT_EQ(expect_conforming(mesh, bodies, 1e-9), 2u * (40 + 4));
}



TEST(MeshStructured, LShapeTwoBodies)
{
  // a column on a slab: the column's sides are breakpoints of the slab's grid
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 1, 0.2)"),
                                         parse2("rectangle(0.35, 0.2, 0.5, 1.3)")};
  const double                 h      = 0.1;
  const auto                   mesh   = structured_mesh<2>(pointers(bodies), h, where);
  EXPECT_NEAR(mesh.volume(), 0.2 + 0.15 * 1.1, 1e-14);
  expect_material_ids(mesh, bodies);
  expect_all_vertices_used(mesh);
  expect_conforming(mesh, bodies, 1e-9);
  std::size_t n[2] = {0, 0};
  for (const auto &cell : mesh.cells)
    ++n[cell.material_id];
  // x breakpoints 0 | 0.35 | 0.5 | 1 -> 4 + 2 + 5 = 11 columns; y: 0 | 0.2 | 1.3 -> 2 + 11 rows
  EXPECT_EQ(n[0], 11u * 2u);
  EXPECT_EQ(n[1], 2u * 11u);
}



TEST(MeshStructured, ISectionThreeBodies)
{
  // flanges of different thickness and a web: bottom 0.03, top 0.02, web 0.012 wide
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 0.3, 0.03)"),
                                         parse2("rectangle(0.144, 0.03, 0.156, 0.38)"),
                                         parse2("rectangle(0, 0.38, 0.3, 0.4)")};
  const double                 exact  = 0.3 * 0.03 + 0.012 * 0.35 + 0.3 * 0.02;
  for (const double h : {0.05, 0.01})
    {
      const auto mesh = structured_mesh<2>(pointers(bodies), h, where);
      EXPECT_NEAR(mesh.volume(), exact, 1e-14 * exact);
      expect_material_ids(mesh, bodies);
      expect_all_vertices_used(mesh);
      expect_conforming(mesh, bodies, 1e-9);
      double size[3] = {0, 0, 0};
      for (const auto &cell : mesh.cells)
        size[cell.material_id] += dealii::GridTools::cell_measure<2>(
          mesh.vertices, dealii::ArrayView<const unsigned int>(cell.vertices));
      EXPECT_NEAR(size[0], 0.009, 1e-15);
      EXPECT_NEAR(size[1], 0.0042, 1e-15);
      EXPECT_NEAR(size[2], 0.006, 1e-15);
      // the web is 0.012 wide: ceil(0.012 / h) columns of cells (1 for h = 0.05)
      const double width = 0.012 / std::ceil(0.012 / h);
      for (const auto &cell : mesh.cells)
        if (cell.material_id == 1)
          {
            EXPECT_NEAR(mesh.vertices[cell.vertices[1]][0] - mesh.vertices[cell.vertices[0]][0],
                        width, 1e-15);
          }
    }
}



TEST(MeshStructured, Boxes3D)
{
  {
    const std::vector<Region<3>> bodies = {parse3("box(0, 0, 0, 1, 0.2, 0.3)")};
    const auto                   mesh   = structured_mesh<3>(pointers(bodies), 0.1, where);
    EXPECT_EQ(mesh.cells.size(), 10u * 2u * 3u);
    EXPECT_EQ(mesh.vertices.size(), 11u * 3u * 4u);
    EXPECT_NEAR(mesh.volume(), 0.06, 1e-15);
    EXPECT_EQ(expect_conforming(mesh, bodies, 1e-9), 2u * (10 * 2 + 10 * 3 + 2 * 3));
  }
  {
    // a T of two boxes plus a box with a box-shaped hole
    const std::vector<Region<3>> bodies = {parse3("box(0, 0, 0, 1, 1, 0.2)"),
                                           parse3("box(0.4, 0.4, 0.2, 0.6, 0.6, 1)"),
                                           parse3("box(1, 0, 0, 1.5, 1, 0.2) - "
                                                  "box(1.1, 0.1, -1, 1.2, 0.2, 1)")};
    const auto mesh = structured_mesh<3>(pointers(bodies), 0.1, where);
    EXPECT_NEAR(mesh.volume(), 0.2 + 0.04 * 0.8 + 0.1 - 0.01 * 0.2, 1e-14);
    expect_material_ids(mesh, bodies);
    expect_all_vertices_used(mesh);
    expect_conforming(mesh, bodies, 1e-9);
    EXPECT_TRUE(is_rectilinear(bodies[2]));
  }
}



TEST(MeshStructured, StaircaseForCurvedBodies)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)")};
  EXPECT_FALSE(is_rectilinear(bodies[0]));
  const double h     = 0.05;
  const auto   mesh  = structured_mesh<2>(pointers(bodies), h, where);
  const double exact = 2 - M_PI * 0.25 * 0.25;
  EXPECT_GT(std::abs(mesh.volume() - exact), 1e-4); // not exact ...
  EXPECT_LT(std::abs(mesh.volume() - exact), 2 * M_PI * 0.25 * h); // ... within perimeter * h
  EXPECT_EQ(mesh.cells.size(), 40u * 20u - 80u);   // the 80 cells with centre in the disk
  // the staircase boundary is not the region's boundary: check the face counts only
  const std::size_t n_boundary = expect_conforming(mesh, bodies, 1e-9, false);
  // the outer rectangle plus the hole's staircase, which spans 10 x 10 cells
  EXPECT_EQ(n_boundary, 2u * (40 + 20) + 2u * (10 + 10));
}



// ------------------------------------------------------------------------------
// unstructured_mesh
// ------------------------------------------------------------------------------

TEST(MeshUnstructured, PlateWithHole)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)")};
  const double                 h      = 0.05;
  const auto                   mesh   = unstructured_mesh(pointers(bodies), h, where);
  const auto                   hole   = Region<2>::disk_polygon(Point<2>(1, 0.5), 0.25, h);
  const double                 area   = 2 - polygon_area(hole);

  EXPECT_NEAR(mesh.volume(), area, 1e-12 * area);
  expect_all_vertices_used(mesh);
  expect_material_ids(mesh, std::vector<Region<2>>{bodies[0].polygonized(h)});

  const auto s = quad_statistics(mesh);
  EXPECT_GT(s.min_jacobian_ratio, 0); // det J > 0 at every vertex of every cell
  EXPECT_LE(s.max_edge, 0.5 * h * (1 + 1e-12));
  EXPECT_GE(s.min_angle, min_angle_bound - 1e-9);
  EXPECT_LE(s.max_angle, 166.0);
  std::cout << "plate with hole, h = " << h << ": " << mesh.cells.size()
            << " quads, min det J / area " << s.min_jacobian_ratio << ", angles "
            << s.min_angle << " .. " << s.max_angle << " degrees, max edge "
            << s.max_edge / h << " h" << std::endl;

  // conforming, with every edge of one cell on the (polygonized) boundary
  const std::vector<Region<2>> polygonized = {bodies[0].polygonized(h)};
  const std::size_t n_boundary = expect_conforming(mesh, polygonized, 1e-6 * h);
  std::map<std::pair<unsigned int, unsigned int>, unsigned int> edges;
  for (const auto &cell : mesh.cells)
    for (const auto &key : face_keys<2>(cell))
      ++edges[{key[0], key[1]}];
  std::set<unsigned int> boundary_vertices;
  double                 perimeter = 0;
  for (const auto &[edge, n] : edges)
    if (n == 1)
      {
        boundary_vertices.insert(edge.first);
        boundary_vertices.insert(edge.second);
        perimeter += mesh.vertices[edge.first].distance(mesh.vertices[edge.second]);
      }
  EXPECT_EQ(boundary_vertices.size(), n_boundary); // closed loops
  double polygon_perimeter = 0;
  for (unsigned int i = 0; i < hole.size(); ++i)
    polygon_perimeter += hole[i].distance(hole[(i + 1) % hole.size()]);
  EXPECT_NEAR(perimeter, 6 + polygon_perimeter, 1e-12);
  // every boundary vertex lies on a rectangle side or on the polygon
  for (const unsigned int v : boundary_vertices)
    {
      const auto  &p  = mesh.vertices[v];
      const double dr = std::min({std::abs(p[0]), std::abs(p[0] - 2), std::abs(p[1]),
                                  std::abs(p[1] - 1)});
      double       dp = 1e300;
      for (unsigned int i = 0; i < hole.size(); ++i)
        dp = std::min(dp, distance_to_segment(p, hole[i], hole[(i + 1) % hole.size()]));
      EXPECT_LT(std::min(dr, dp), 1e-14) << p;
    }
  // each polygon vertex is a mesh vertex
  for (const auto &p : hole)
    EXPECT_TRUE(std::find(mesh.vertices.begin(), mesh.vertices.end(), p) != mesh.vertices.end());
}



TEST(MeshUnstructured, TouchingBodiesShareTheInterface)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 1, 1)"),
                                         parse2("rectangle(1, 0, 2, 1)")};
  const double                 h      = 0.1;
  const auto                   mesh   = unstructured_mesh(pointers(bodies), h, where);
  EXPECT_NEAR(mesh.volume(), 2, 1e-13);
  expect_material_ids(mesh, bodies);
  expect_all_vertices_used(mesh);
  expect_conforming(mesh, bodies, 1e-6 * h);
  double area[2] = {0, 0};
  for (const auto &cell : mesh.cells)
    area[cell.material_id] += dealii::GridTools::cell_measure<2>(
      mesh.vertices, dealii::ArrayView<const unsigned int>(cell.vertices));
  EXPECT_NEAR(area[0], 1, 1e-13);
  EXPECT_NEAR(area[1], 1, 1e-13);

  // The interface x = 1: edges shared by a cell of each body, total length 1.
  std::map<std::pair<unsigned int, unsigned int>, std::vector<unsigned int>> edges;
  for (const auto &cell : mesh.cells)
    for (const auto &key : face_keys<2>(cell))
      edges[{key[0], key[1]}].push_back(cell.material_id);
  double interface = 0;
  for (const auto &[edge, materials] : edges)
    if (mesh.vertices[edge.first][0] == 1 && mesh.vertices[edge.second][0] == 1)
      {
        ASSERT_EQ(materials.size(), 2u);
        EXPECT_NE(materials[0], materials[1]);
        interface += mesh.vertices[edge.first].distance(mesh.vertices[edge.second]);
      }
  EXPECT_NEAR(interface, 1, 1e-14);
  const auto s = quad_statistics(mesh);
  EXPECT_GE(s.min_angle, min_angle_bound - 1e-9);
  EXPECT_LE(s.max_edge, 0.5 * h * (1 + 1e-12));
}



TEST(MeshUnstructured, Deterministic)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)"),
                                         parse2("disk(1, 0.5, 0.25)")};
  const auto                   first  = unstructured_mesh(pointers(bodies), 0.04, where);
  // a different heap layout for the second run
  std::vector<std::unique_ptr<double[]>> garbage;
  for (unsigned int i = 0; i < 1000; ++i)
    garbage.emplace_back(new double[1 + (i * 7919) % 613]);
  const auto second = unstructured_mesh(pointers(bodies), 0.04, where);
  EXPECT_EQ(mesh_hash(first), mesh_hash(second));
  ASSERT_EQ(first.vertices.size(), second.vertices.size());
  ASSERT_EQ(first.cells.size(), second.cells.size());
  for (unsigned int i = 0; i < first.vertices.size(); ++i)
    ASSERT_EQ(first.vertices[i], second.vertices[i]);
  for (unsigned int i = 0; i < first.cells.size(); ++i)
    {
      ASSERT_EQ(first.cells[i].vertices, second.cells[i].vertices);
      ASSERT_EQ(first.cells[i].material_id, second.cells[i].material_id);
    }
  // the inclusion (body 1) fills the hole of body 0 conformingly
  EXPECT_NEAR(first.volume(), 2, 1e-13);
  expect_conforming(first, bodies, 1e-6 * 0.04);
}



TEST(MeshUnstructured, PolygonBodies)
{
  {
    const std::vector<Region<2>> bodies = {parse2("polygon(0,0, 2,0, 2,1, 1,1, 1,2, 0,2)")};
    const auto                   mesh   = unstructured_mesh(pointers(bodies), 0.1, where);
    EXPECT_NEAR(mesh.volume(), 3, 3e-12);
    expect_conforming(mesh, bodies, 1e-7);
    const auto s = quad_statistics(mesh);
    EXPECT_GE(s.min_angle, min_angle_bound - 1e-9);
    EXPECT_LE(s.max_edge, 0.05 * (1 + 1e-12));
  }
  {
    // a sharp triangle (input angles 14.0 and 45 degrees) crossed by a rectangle:
    // the angle bound does not hold near the sharp corners, positivity does
    const std::vector<Region<2>> bodies = {parse2("polygon(0,0, 1,0, 0.8,0.2)"),
                                           parse2("rectangle(0.5, -0.1, 0.6, 0.3)")};
    const auto                   mesh   = unstructured_mesh(pointers(bodies), 0.02, where);
    // union area: triangle 0.1 plus the rectangle 0.04 minus their overlap (a
    // trapezoid between x = 0.5 and 0.6 under y = x / 4: (0.125 + 0.15) / 2 * 0.1)
    const double area = 0.1 + 0.04 - 0.5 * (0.125 + 0.15) * 0.1;
    EXPECT_NEAR(mesh.volume(), area, 1e-12 * area);
    expect_material_ids(mesh, bodies);
    expect_conforming(mesh, bodies, 1e-8);
    const auto s = quad_statistics(mesh);
    EXPECT_GT(s.min_jacobian_ratio, 0);
    EXPECT_LE(s.max_edge, 0.01 * (1 + 1e-12));
    std::cout << "sharp triangle + rectangle: angles " << s.min_angle << " .. " << s.max_angle
              << " degrees" << std::endl;
  }
}



TEST(MeshUnstructured, CrossingTangentAndClippedPrimitives)
{
  const double h = 0.05;
  const auto   p  = [h](const double r) {
    return polygon_area(Region<2>::disk_polygon(Point<2>(0, 0), r, h));
  };
  struct Case
  {
    std::vector<std::string> bodies;
    double                   area;
  };
  const std::vector<Case> cases = {
    // a notch: the disk's polygon crosses the top side (rounded exact intersections)
    {{"rectangle(0, 0, 2, 1) - disk(1, 1, 0.25)"}, 2 - 0.5 * p(0.25)},
    // a tangent hole: the polygon's top axis point lies on the top side
    {{"rectangle(0, 0, 2, 1) - disk(1, 0.75, 0.25)"}, 2 - p(0.25)},
    // a subtracted rectangle far beyond the body: its sides are clipped to the box
    {{"rectangle(0, 0, 1, 1) - rectangle(0.5, 0.5, 10, 10)"}, 0.75},
    // overlapping bodies: the first wins, the disk keeps its outer half
    {{"rectangle(0, 0, 1, 1)", "disk(1, 0.5, 0.3)"}, 1 + 0.5 * p(0.3)},
    // an intersection written with `all`
    {{"rectangle(0, 0, 1, 1) - (all - disk(0.5, 0.5, 0.4))"}, p(0.4)}};
  for (const auto &c : cases)
    {
      std::vector<Region<2>> bodies, polygonized;
      for (const auto &b : c.bodies)
        {
          bodies.push_back(parse2(b));
          polygonized.push_back(bodies.back().polygonized(h));
        }
      const auto mesh = unstructured_mesh(pointers(bodies), h, where);
      EXPECT_NEAR(mesh.volume(), c.area, 1e-12 * c.area) << c.bodies[0];
      expect_material_ids(mesh, polygonized);
      expect_all_vertices_used(mesh);
      expect_conforming(mesh, polygonized, 1e-6 * h);
      const auto s = quad_statistics(mesh);
      EXPECT_GT(s.min_jacobian_ratio, 0) << c.bodies[0];
      EXPECT_LE(s.max_edge, 0.5 * h * (1 + 1e-12)) << c.bodies[0];
      std::cout << c.bodies[0] << (c.bodies.size() > 1 ? " + ..." : "") << ": "
                << mesh.cells.size() << " quads, angles " << s.min_angle << " .. "
                << s.max_angle << " degrees" << std::endl;
    }
}



TEST(MeshUnstructured, CellsScaleLikeAreaOverHSquared)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)")};
  for (const double h : {0.04, 0.02, 0.01})
    {
      const auto   start  = std::chrono::steady_clock::now();
      const auto   mesh   = unstructured_mesh(pointers(bodies), h, where);
      const double time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double factor = mesh.cells.size() * h * h / mesh.volume();
      std::cout << "plate with hole, h = " << h << ": " << mesh.cells.size() << " quads, "
                << factor << " area / h^2, " << time << " s" << std::endl;
      EXPECT_GT(factor, 13.5);
      EXPECT_LT(factor, 16.5);
    }
}



TEST(MeshUnstructured, LoadIntoDistributedTriangulation)
{
  const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 2, 1) - disk(1, 0.5, 0.25)"),
                                         parse2("rectangle(2, 0, 2.5, 1)")};
  const auto mesh = unstructured_mesh(pointers(bodies), 0.1, where);
  // every rank built the same mesh
  const std::uint64_t hash   = mesh_hash(mesh);
  const unsigned int  low    = static_cast<unsigned int>(hash & 0xffffffffu);
  const unsigned int  high   = static_cast<unsigned int>(hash >> 32);
  EXPECT_EQ(dealii::Utilities::MPI::min(low, MPI_COMM_WORLD),
            dealii::Utilities::MPI::max(low, MPI_COMM_WORLD));
  EXPECT_EQ(dealii::Utilities::MPI::min(high, MPI_COMM_WORLD),
            dealii::Utilities::MPI::max(high, MPI_COMM_WORLD));
  dealii::parallel::distributed::Triangulation<2> tria(MPI_COMM_WORLD);
  tria.create_triangulation(mesh.vertices, mesh.cells, dealii::SubCellData());
  EXPECT_EQ(tria.n_global_active_cells(), mesh.cells.size());
  EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-12);
  std::size_t n_second = 0;
  for (const auto &cell : tria.active_cell_iterators())
    if (cell->is_locally_owned() && cell->material_id() == 1)
      ++n_second;
  EXPECT_EQ(dealii::Utilities::MPI::sum(n_second, MPI_COMM_WORLD),
            std::count_if(mesh.cells.begin(), mesh.cells.end(),
                          [](const auto &c) { return c.material_id == 1; }));
  tria.refine_global(1);
  EXPECT_EQ(tria.n_global_active_cells(), 4 * mesh.cells.size());
  EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-12);
}



TEST(MeshStructured, LoadIntoDistributedTriangulation)
{
  {
    const std::vector<Region<2>> bodies = {parse2("rectangle(0, 0, 1, 0.2)"),
                                           parse2("rectangle(0.35, 0.2, 0.5, 1.3)")};
    const auto mesh = structured_mesh<2>(pointers(bodies), 0.1, where);
    dealii::parallel::distributed::Triangulation<2> tria(MPI_COMM_WORLD);
    tria.create_triangulation(mesh.vertices, mesh.cells, dealii::SubCellData());
    EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-14);
    tria.refine_global(1);
    EXPECT_EQ(tria.n_global_active_cells(), 4 * mesh.cells.size());
    EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-14);
  }
  {
    const std::vector<Region<3>> bodies = {parse3("box(0, 0, 0, 1, 1, 0.2)"),
                                           parse3("box(0.4, 0.4, 0.2, 0.6, 0.6, 1)")};
    const auto mesh = structured_mesh<3>(pointers(bodies), 0.2, where);
    dealii::parallel::distributed::Triangulation<3> tria(MPI_COMM_WORLD);
    tria.create_triangulation(mesh.vertices, mesh.cells, dealii::SubCellData());
    EXPECT_NEAR(mesh.volume(), 0.2 + 0.04 * 0.8, 1e-15);
    EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-13);
    tria.refine_global(1);
    EXPECT_EQ(tria.n_global_active_cells(), 8 * mesh.cells.size());
    EXPECT_NEAR(dealii::GridTools::volume(tria), mesh.volume(), 1e-13);
  }
}



TEST(MeshErrors, BadInput)
{
  const auto                     plate = parse2("rectangle(0, 0, 2, 1)");
  const auto                     box   = parse3("box(0, 0, 0, 1, 1, 1)");
  const std::vector<const Region<2> *> one = {&plate};
  for (const double h : {0.0, -0.1, std::nan("")})
    {
      expect_input_error([&] { structured_mesh<2>(one, h, where); }, "h must be a positive");
      expect_input_error([&] { unstructured_mesh(one, h, where); }, "h must be a positive");
    }
  expect_input_error([&] { structured_mesh<3>({}, 0.1, where); }, "no body");
  expect_input_error([&] { unstructured_mesh({}, 0.1, where); }, "no body");
  expect_input_error([&] { unstructured_mesh({&plate, nullptr}, 0.1, where); },
                     "body 1 is a null pointer");
  const Region<2> empty;
  expect_input_error([&] { unstructured_mesh({&plate, &empty}, 0.1, where); }, "body 1 is empty");
  const auto unbounded = parse2("all - disk(0, 0, 1)");
  expect_input_error([&] { structured_mesh<2>({&unbounded}, 0.1, where); },
                     "body 0 ('all - disk(0, 0, 1)') is unbounded");
  expect_input_error([&] { unstructured_mesh({&unbounded}, 0.1, where); }, "is unbounded");
  // a body covered by an earlier one, or too thin for the grid, gets no cell
  const auto inner = parse2("rectangle(0.2, 0.2, 0.4, 0.4)");
  expect_input_error([&] { structured_mesh<2>({&plate, &inner}, 0.1, where); },
                     "body 1 ('rectangle(0.2, 0.2, 0.4, 0.4)') gets no cell");
  expect_input_error([&] { unstructured_mesh({&plate, &inner}, 0.1, where); },
                     "body 1 ('rectangle(0.2, 0.2, 0.4, 0.4)') gets no cell");
  const auto nothing = parse2("rectangle(0, 0, 1, 1) - rectangle(-1, -1, 2, 2)");
  expect_input_error([&] { structured_mesh<2>({&nothing}, 0.1, where); }, "has no cell");
  expect_input_error([&] { unstructured_mesh({&nothing}, 0.1, where); }, "has no cell");
  // too many cells
  expect_input_error([&] { structured_mesh<3>({&box}, 0.005, where); }, "more than the limit");
  expect_input_error([&] { unstructured_mesh(one, 5e-4, where); }, "more than the limit");
  // a sliver of width 1e-9 along a whole side would need triangles of its width
  const auto left  = parse2("rectangle(0, 0, 1, 1)");
  const auto right = parse2("polygon(0.999999999, 0, 2, 0, 2, 1, 0.999999998, 1)");
  expect_input_error([&] { unstructured_mesh({&right, &left}, 0.1, where); },
                     "features much smaller than h");
  const auto huge_disk = parse2("rectangle(0, 0, 1, 1) - disk(0, 0, 1e4)");
  expect_input_error([&] { unstructured_mesh({&huge_disk}, 1e-3, where); }, "sides");
}
