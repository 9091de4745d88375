// The validity of a mesh's cells: the Jacobian of every cell's map from its reference cell,
// inverted cells repaired, the others that cannot carry finite elements named.
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>

#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/reference_cell.h>

#include <hysteron/geometry/mesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace Geometry
  {
    namespace
    {
      /// Below this scaled Jacobian a corner counts as flat (an angle within 6e-5 degrees
      /// of 0 or 180) or, with the opposite sign elsewhere, as folded over.
      constexpr double flat_jacobian = 1e-6;

      /// A cell whose measure is below this fraction of diameter^dim is a sliver (an
      /// aspect ratio of about 1e8).
      constexpr double sliver_measure = 1e-8;

      /// Two vertices closer than this fraction of the cell's diameter coincide.
      constexpr double coincident_distance = 1e-12;

      /**
       * The Jacobian of the multilinear map of a hypercube at the reference point @p xi:
       * vertex v (lexicographic: bit d of v is its coordinate d) has the shape function
       * prod_d (bit_d ? xi_d : 1 - xi_d).
       */
      template <int dim>
      dealii::Tensor<2, dim>
      hypercube_jacobian(const std::vector<dealii::Point<dim>> &x, const dealii::Point<dim> &xi)
      {
        dealii::Tensor<2, dim> J;
        for (unsigned int v = 0; v < x.size(); ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              double g = 1;
              for (unsigned int e = 0; e < dim; ++e)
                {
                  const bool bit = (v >> e) & 1u;
                  g *= e == d ? (bit ? 1.0 : -1.0) : (bit ? xi[e] : 1.0 - xi[e]);
                }
              for (unsigned int c = 0; c < dim; ++c)
                J[c][d] += x[v][c] * g;
            }
        return J;
      }

      /// det J divided by the lengths of its columns: the sine of a corner's angle in 2D,
      /// in [-1, 1] whatever the cell's size and aspect ratio (0 if a column vanishes).
      template <int dim>
      double
      scaled_determinant(const dealii::Tensor<2, dim> &J)
      {
        double lengths = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            double column = 0;
            for (unsigned int c = 0; c < dim; ++c)
              column += J[c][d] * J[c][d];
            lengths *= std::sqrt(column);
          }
        return lengths > 0 ? dealii::determinant(J) / lengths : 0.0;
      }

      /// The signed measure and the extreme scaled Jacobians of one cell.
      struct Shape
      {
        double measure = 0, s_min = std::numeric_limits<double>::max(),
               s_max = -std::numeric_limits<double>::max();
        void
        add(const double s)
        {
          s_min = std::min(s_min, s);
          s_max = std::max(s_max, s);
        }
      };

      /**
       * Simplices are affine: one Jacobian, whose determinant scaled by the edges at each
       * vertex is the sine of that vertex's angle (2D) or solid-angle analogue (3D).
       * Hypercubes: the Jacobian at the vertices and at the Gauss points of 2 and 3 points
       * per direction (those of Q1 and Q2); the measure is the Gauss integral of det J.
       */
      template <int dim>
      Shape
      shape_of(const std::vector<dealii::Point<dim>> &x)
      {
        Shape shape;
        if (x.size() == dim + 1)
          {
            dealii::Tensor<2, dim> J;
            for (unsigned int d = 0; d < dim; ++d)
              for (unsigned int c = 0; c < dim; ++c)
                J[c][d] = x[d + 1][c] - x[0][c];
            const double det = dealii::determinant(J);
            shape.measure    = det / (dim == 2 ? 2.0 : 6.0);
            for (unsigned int v = 0; v <= dim; ++v)
              {
                double lengths = 1;
                for (unsigned int w = 0; w <= dim; ++w)
                  if (w != v)
                    lengths *= x[w].distance(x[v]);
                shape.add(lengths > 0 ? det / lengths : 0.0);
              }
            return shape;
          }
        for (unsigned int v = 0; v < x.size(); ++v)
          {
            dealii::Point<dim> corner;
            for (unsigned int d = 0; d < dim; ++d)
              corner[d] = (v >> d) & 1u;
            shape.add(scaled_determinant(hypercube_jacobian(x, corner)));
          }
        for (const unsigned int n : {2u, 3u})
          {
            const dealii::QGauss<dim> gauss(n);
            for (unsigned int q = 0; q < gauss.size(); ++q)
              {
                const auto J = hypercube_jacobian(x, gauss.point(q));
                shape.add(scaled_determinant(J));
                if (n == 3)
                  shape.measure += gauss.weight(q) * dealii::determinant(J);
              }
          }
        return shape;
      }

      std::string
      number(const double x)
      {
        std::ostringstream s;
        s.precision(3);
        s << x;
        return s.str();
      }

      /// "(x, y)" to 12 digits.
      template <int dim>
      std::string
      point_string(const dealii::Point<dim> &p)
      {
        std::ostringstream s;
        s.precision(12);
        for (unsigned int d = 0; d < dim; ++d)
          s << (d == 0 ? "(" : ", ") << p[d];
        return s.str() + ")";
      }
    } // namespace



    template <int dim>
    std::string
    cell_defect(const std::vector<dealii::Point<dim>> &x, bool &inverted)
    {
      inverted = false;
      double diameter = 0, closest = std::numeric_limits<double>::max();
      unsigned int a = 0;
      for (unsigned int v = 0; v < x.size(); ++v)
        for (unsigned int w = v + 1; w < x.size(); ++w)
          {
            const double r = x[v].distance(x[w]);
            diameter       = std::max(diameter, r);
            if (r < closest)
              {
                closest = r;
                a       = v;
              }
          }
      if (!(closest > coincident_distance * diameter))
        return "two of its vertices coincide (at " + point_string(x[a]) + ")";

      const Shape  shape    = shape_of(x);
      const double relative = std::abs(shape.measure) / std::pow(diameter, dim);
      if (shape.s_min < -flat_jacobian && shape.s_max > flat_jacobian)
        return "its Jacobian changes sign inside the cell (scaled determinant from " +
               number(shape.s_min) + " to " + number(shape.s_max) +
               "): it is self-intersecting (a bow-tie) or not convex";
      if (relative < sliver_measure)
        return "it is degenerate: its " + std::string(dim == 2 ? "area" : "volume") + " is " +
               number(relative) + " times its diameter^" + std::to_string(dim) + " (a sliver)";
      if (shape.s_max < -flat_jacobian)
        {
          inverted = true; // negative everywhere: the vertices are in the mirrored order
          return "";
        }
      if (shape.s_min <= flat_jacobian)
        return "it is degenerate: its scaled Jacobian falls to " + number(shape.s_min) +
               " (an angle of nearly 0 or 180 degrees)";
      return "";
    }



    template <int dim>
    CellCheck
    check_cells(const std::vector<dealii::Point<dim>> &vertices, std::vector<dealii::CellData<dim>> &cells)
    {
      CellCheck                       result;
      std::vector<dealii::Point<dim>> x;
      const auto examine = [&](const bool repairs_allowed) {
        for (unsigned int c = 0; c < cells.size(); ++c)
          {
            x.clear();
            for (const unsigned int v : cells[c].vertices)
              x.push_back(vertices[v]);
            bool              inverted = false;
            const std::string defect   = cell_defect(x, inverted);
            if (!defect.empty() || (inverted && !repairs_allowed))
              {
                result.cell    = c;
                result.problem = defect.empty() ? "it stays inverted after its repair" : defect;
                return false;
              }
            result.inverted += inverted;
          }
        return true;
      };
      if (!examine(true))
        return result;
      if (result.inverted > 0)
        {
          // Mirror the inverted cells (their measure is negative, the others' positive) and
          // orient the lines of quadrilaterals and hexahedra consistently again.
          dealii::GridTools::invert_cells_with_negative_measure(vertices, cells);
          if (cells.front().vertices.size() == dealii::GeometryInfo<dim>::vertices_per_cell)
            dealii::GridTools::consistently_order_cells(cells);
          const std::size_t inverted = result.inverted;
          result.inverted            = 0;
          if (!examine(false))
            return result;
          result.inverted = inverted;
        }
      result.valid = true;
      return result;
    }



    template <int dim>
    std::string
    vertex_list(const std::vector<dealii::Point<dim>> &vertices, const dealii::CellData<dim> &cell)
    {
      // Around the cell as Gmsh lists them: deal.II numbers a quadrilateral's vertices
      // lexicographically (0, 1, 3, 2 is the way round), and a hexahedron's per z-layer.
      static constexpr unsigned int around[8] = {0, 1, 3, 2, 4, 5, 7, 6};
      const bool  hypercube = cell.vertices.size() == dealii::GeometryInfo<dim>::vertices_per_cell;
      std::string list;
      for (unsigned int v = 0; v < cell.vertices.size(); ++v)
        list += (v == 0 ? "" : ", ") + point_string(vertices[cell.vertices[hypercube ? around[v] : v]]);
      return list;
    }



    template std::string
    cell_defect(const std::vector<dealii::Point<2>> &, bool &);
    template std::string
    cell_defect(const std::vector<dealii::Point<3>> &, bool &);
    template CellCheck
    check_cells(const std::vector<dealii::Point<2>> &, std::vector<dealii::CellData<2>> &);
    template CellCheck
    check_cells(const std::vector<dealii::Point<3>> &, std::vector<dealii::CellData<3>> &);
    template std::string
    vertex_list(const std::vector<dealii::Point<2>> &, const dealii::CellData<2> &);
    template std::string
    vertex_list(const std::vector<dealii::Point<3>> &, const dealii::CellData<3> &);
  } // namespace Geometry
} // namespace hysteron
