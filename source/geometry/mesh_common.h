// Helpers shared by the FEM mesh generators (structured_mesh.cc, mesh.cc): argument checks
// and messages.
#ifndef hysteron_geometry_mesh_common_h
#define hysteron_geometry_mesh_common_h

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/mesh.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace Geometry
  {
    namespace internal
    {
      /// The largest mesh we build (cells of the tensor grid, or estimated cells).
      inline constexpr double max_cells = 5e6;

      inline std::string
      to_string(const double x)
      {
        std::ostringstream s;
        s.precision(6);
        s << x;
        return s.str();
      }

      template <int dim>
      std::string
      body_name(const std::vector<const Region<dim> *> &bodies, const unsigned int i)
      {
        return "body " + std::to_string(i) +
               (bodies[i] != nullptr && !bodies[i]->expression().empty() ?
                  " ('" + bodies[i]->expression() + "')" :
                  std::string());
      }

      /**
       * Check the common arguments and return the bounding box of all bodies.
       */
      template <int dim>
      std::pair<dealii::Point<dim>, dealii::Point<dim>>
      checked_bounding_box(const std::vector<const Region<dim> *> &bodies,
                           const double                             h,
                           const std::string                       &where)
      {
        require(h > 0 && std::isfinite(h), where,
                "the mesh size h must be a positive number, got " + to_string(h));
        require(!bodies.empty(), where, "there is no body to mesh");
        dealii::Point<dim> lo, hi;
        for (unsigned int d = 0; d < dim; ++d)
          {
            lo[d] = std::numeric_limits<double>::infinity();
            hi[d] = -std::numeric_limits<double>::infinity();
          }
        for (unsigned int i = 0; i < bodies.size(); ++i)
          {
            require(bodies[i] != nullptr, where, body_name(bodies, i) + " is a null pointer");
            require(!bodies[i]->is_empty(), where, body_name(bodies, i) + " is empty");
            const auto box = bodies[i]->bounding_box().get_boundary_points();
            for (unsigned int d = 0; d < dim; ++d)
              {
                require(std::isfinite(box.first[d]) && std::isfinite(box.second[d]), where,
                        body_name(bodies, i) +
                          " is unbounded (it adds 'all'); a mesh needs a bounded body");
                lo[d] = std::min(lo[d], box.first[d]);
                hi[d] = std::max(hi[d], box.second[d]);
              }
          }
        return {lo, hi};
      }

      /// The index of the first body that contains @p p, or -1.
      template <int dim, typename RegionPointer>
      int
      first_body(const std::vector<RegionPointer> &bodies, const dealii::Point<dim> &p)
      {
        for (unsigned int i = 0; i < bodies.size(); ++i)
          if (bodies[i]->contains(p))
            return static_cast<int>(i);
        return -1;
      }

      /// Every body must have at least one cell.
      template <int dim>
      void
      check_cell_counts(const std::vector<const Region<dim> *> &bodies,
                        const CoarseMesh<dim>                  &mesh,
                        const double                            h,
                        const std::string                      &where)
      {
        require(!mesh.cells.empty(), where,
                "the mesh of the bodies at h = " + to_string(h) + " has no cell");
        std::vector<std::size_t> count(bodies.size(), 0);
        for (const auto &cell : mesh.cells)
          ++count[cell.material_id];
        for (unsigned int i = 0; i < bodies.size(); ++i)
          require(count[i] > 0, where,
                  body_name(bodies, i) + " gets no cell at h = " + to_string(h) +
                    " (it is thinner than the cells, or covered by earlier bodies)");
      }
    } // namespace internal



  } // namespace Geometry
} // namespace hysteron

#endif
