// The structured (tensor-product) meshes of the FEM: the cells of a grid through every
// coordinate of the bodies' rectangles and boxes, directly or as a coarse mesh that global
// refinements turn into them.
#include <deal.II/base/geometry_info.h>

#include <deal.II/grid/grid_tools.h>

#include <hysteron/geometry/mesh.h>

#include "geometry/mesh_common.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace Geometry
  {
    using namespace internal;



    template <int dim>
    double
    CoarseMesh<dim>::volume() const
    {
      double sum = 0;
      for (const auto &cell : cells)
        sum += dealii::GridTools::cell_measure<dim>(
          vertices, dealii::ArrayView<const unsigned int>(cell.vertices));
      return sum;
    }



    template <int dim>
    bool
    is_rectilinear(const Region<dim> &region)
    {
      using Kind = typename Region<dim>::Kind;
      for (const auto &q : region.get_primitives())
        if (q.kind != Kind::rectangle && q.kind != Kind::box && q.kind != Kind::all)
          return false;
      return true;
    }



    namespace
    {
      /// The tensor grid of structured_mesh(): along each axis the merged breakpoints and
      /// the number of cells of every interval between them.
      template <int dim>
      struct TensorGrid
      {
        std::array<std::vector<double>, dim>      breaks;
        std::array<std::vector<std::size_t>, dim> counts;

        /// The cells of the grid with every count rounded up to a multiple of 2^level,
        /// divided by (2^level)^dim: the coarse cells of that level.
        double
        coarse_cells(const unsigned int level) const
        {
          double cells = 1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              double sum = 0;
              for (const std::size_t n : counts[d])
                sum += std::ceil(std::ldexp(static_cast<double>(n), -static_cast<int>(level)));
              cells *= sum;
            }
          return cells;
        }
      };

      template <int dim>
      TensorGrid<dim>
      tensor_grid(const std::vector<const Region<dim> *> &bodies,
                  const double                             h,
                  const std::string                       &where)
      {
        using Kind          = typename Region<dim>::Kind;
        const auto [lo, hi] = checked_bounding_box(bodies, h, where);
        double extent = 0;
        for (unsigned int d = 0; d < dim; ++d)
          extent = std::max(extent, hi[d] - lo[d]);
        const double merge_tolerance = 1e-12 * extent;

        TensorGrid<dim> grid;
        for (unsigned int d = 0; d < dim; ++d)
          {
            std::vector<double> breaks{lo[d], hi[d]};
            for (const auto *body : bodies)
              for (const auto &q : body->get_primitives())
                if (q.kind == Kind::rectangle || q.kind == Kind::box)
                  for (const double b : {q.p[d], q.p[dim + d]})
                    if (b > lo[d] && b < hi[d])
                      breaks.push_back(b);
            std::sort(breaks.begin(), breaks.end());
            auto &merged = grid.breaks[d];
            merged       = {breaks.front()};
            for (const double b : breaks)
              if (b - merged.back() > merge_tolerance)
                merged.push_back(b);
            merged.back() = hi[d]; // the last breakpoint is the box end, exactly
            for (unsigned int k = 0; k + 1 < merged.size(); ++k)
              {
                const double ratio = (merged[k + 1] - merged[k]) / h * (1 - 1e-9);
                require(ratio < max_cells, where,
                        "h = " + to_string(h) + " gives more than " + to_string(max_cells) +
                          " cells along axis " + std::to_string(d));
                grid.counts[d].push_back(std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(ratio))));
              }
          }
        return grid;
      }

      /**
       * The cells of @p grid whose centre lies in a body, with @p level: every count
       * rounded up to a multiple of 2^level and divided by 2^level. Vertices that no kept
       * cell uses are dropped; the others are numbered lexicographically (x fastest), the
       * cells likewise.
       */
      template <int dim>
      CoarseMesh<dim>
      grid_mesh(const std::vector<const Region<dim> *> &bodies,
                const TensorGrid<dim>                  &grid,
                const unsigned int                      level,
                const double                            h,
                const std::string                      &where)
      {
        std::array<std::vector<double>, dim> x;
        double                               n_grid_cells = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const auto &b = grid.breaks[d];
            for (unsigned int k = 0; k < grid.counts[d].size(); ++k)
              {
                const std::size_t n = (grid.counts[d][k] + (std::size_t(1) << level) - 1) >> level;
                for (std::size_t i = 0; i < n; ++i)
                  x[d].push_back(b[k] + (b[k + 1] - b[k]) * static_cast<double>(i) / static_cast<double>(n));
              }
            x[d].push_back(b.back());
            n_grid_cells *= x[d].size() - 1;
          }
        require(n_grid_cells <= max_cells, where,
                "the tensor-product grid at h = " + to_string(h) + " has " +
                  to_string(n_grid_cells) + " cells, more than the limit of " +
                  to_string(max_cells));

        // Grid vertex (i_0, ..., i_{dim-1}) has the index sum_d i_d stride_d (x fastest).
        std::array<std::size_t, dim> n_cells, stride;
        std::size_t                  n_grid_vertices = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            n_cells[d] = x[d].size() - 1;
            stride[d]  = n_grid_vertices;
            n_grid_vertices *= x[d].size();
          }

        CoarseMesh<dim>              mesh;
        constexpr unsigned int       invalid = std::numeric_limits<unsigned int>::max();
        std::vector<unsigned int>    new_index(n_grid_vertices, invalid);
        std::array<std::size_t, dim> i{};
        const std::size_t            n_total = static_cast<std::size_t>(n_grid_cells);
        for (std::size_t c = 0; c < n_total; ++c)
          {
            std::size_t        r = c;
            dealii::Point<dim> centre;
            std::size_t        first_vertex = 0;
            for (unsigned int d = 0; d < dim; ++d)
              {
                i[d] = r % n_cells[d];
                r /= n_cells[d];
                centre[d] = 0.5 * (x[d][i[d]] + x[d][i[d] + 1]);
                first_vertex += i[d] * stride[d];
              }
            const int body = first_body<dim>(bodies, centre);
            if (body < 0)
              continue;
            dealii::CellData<dim> cell;
            for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_cell; ++v)
              {
                std::size_t g = first_vertex;
                for (unsigned int d = 0; d < dim; ++d)
                  if (v & (1u << d))
                    g += stride[d];
                cell.vertices[v] = static_cast<unsigned int>(g); // renumbered below
                new_index[g]     = 0;
              }
            cell.material_id = static_cast<dealii::types::material_id>(body);
            mesh.cells.push_back(cell);
          }

        // Keep the used vertices, numbered in grid (lexicographic) order.
        for (std::size_t g = 0; g < n_grid_vertices; ++g)
          if (new_index[g] != invalid)
            {
              new_index[g] = mesh.vertices.size();
              dealii::Point<dim> p;
              std::size_t        r = g;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  p[d] = x[d][r % x[d].size()];
                  r /= x[d].size();
                }
              mesh.vertices.push_back(p);
            }
        for (auto &cell : mesh.cells)
          for (auto &v : cell.vertices)
            v = new_index[v];

        check_cell_counts(bodies, mesh, h, where);
        return mesh;
      }
    } // namespace



    template <int dim>
    CoarseMesh<dim>
    structured_mesh(const std::vector<const Region<dim> *> &bodies,
                    const double                             h,
                    const std::string                       &where)
    {
      return grid_mesh(bodies, tensor_grid(bodies, h, where), 0, h, where);
    }



    template <int dim>
    StructuredMesh<dim>
    coarse_structured_mesh(const std::vector<const Region<dim> *> &bodies,
                           const double                             h,
                           const std::string                       &where,
                           const double                             max_coarse_cells,
                           const double                             max_growth)
    {
      const TensorGrid<dim> grid    = tensor_grid(bodies, h, where);
      const double          n_cells = grid.coarse_cells(0);
      require(n_cells <= 1e12, where,
              "the tensor-product grid at h = " + to_string(h) + " has " + to_string(n_cells) +
                " cells");
      // The exact level: every count a multiple of 2^exact.
      unsigned int exact = 0;
      while (exact < 30)
        {
          bool divisible = true;
          for (unsigned int d = 0; d < dim; ++d)
            for (const std::size_t n : grid.counts[d])
              divisible = divisible && n % (std::size_t(2) << exact) == 0;
          if (!divisible)
            break;
          ++exact;
        }
      bool rectilinear = true;
      for (const auto *body : bodies)
        rectilinear = rectilinear && is_rectilinear(*body);

      // The smallest exact level that makes the coarse mesh small enough: a small mesh stays
      // its own coarse mesh (L = 0), with the cells in the same order as structured_mesh().
      StructuredMesh<dim> result;
      unsigned int        level = 0;
      while (rectilinear && level < exact && grid.coarse_cells(level) > max_coarse_cells)
        ++level;
      if (grid.coarse_cells(level) > max_coarse_cells)
        {
          if (!rectilinear)
            return result;
          // The smallest level whose rounded-up counts give a small coarse mesh.
          while (level < 30 && grid.coarse_cells(level) > max_coarse_cells)
            ++level;
          const double rounded = grid.coarse_cells(level) * std::pow(2.0, dim * level);
          if (grid.coarse_cells(level) > max_coarse_cells || rounded > max_growth * n_cells)
            return result;
          std::ostringstream note;
          note << "the structured mesh of " << n_cells << " cells would need a coarse mesh of "
               << grid.coarse_cells(exact) << " cells on every rank; its cell counts per interval "
               << "are rounded up to multiples of 2^" << level << ": " << rounded << " cells ("
               << to_string(100 * (rounded / n_cells - 1)) << " % more, each at most h)";
          result.note = note.str();
        }
      result.coarse  = grid_mesh(bodies, grid, level, h, where);
      result.levels  = level;
      result.n_cells = result.coarse.cells.size() * std::pow(2.0, dim * level);
      return result;
    }



    template struct CoarseMesh<2>;
    template struct CoarseMesh<3>;
    template bool
    is_rectilinear(const Region<2> &);
    template bool
    is_rectilinear(const Region<3> &);
    template CoarseMesh<2>
    structured_mesh(const std::vector<const Region<2> *> &, double, const std::string &);
    template CoarseMesh<3>
    structured_mesh(const std::vector<const Region<3> *> &, double, const std::string &);
    template StructuredMesh<2>
    coarse_structured_mesh(const std::vector<const Region<2> *> &, double, const std::string &, double, double);
    template StructuredMesh<3>
    coarse_structured_mesh(const std::vector<const Region<3> *> &, double, const std::string &, double, double);
  } // namespace Geometry
} // namespace hysteron
