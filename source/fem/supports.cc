// Are the supports enough for a quasi-static analysis? Each connected part of the
// mesh must have its rigid-body motions prevented by Dirichlet conditions, or the
// stiffness matrix is singular and Newton drifts.
#include <hysteron/base/rigid_modes.h>
#include <hysteron/fem/fem.h>

#include <algorithm>
#include <map>
#include <set>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    Solver<dim>::check_supports() const
    {
      using namespace dealii;
      if (analysis != Analysis::quasi_static)
        return; // the mass matrix makes the dynamic system regular

      // The coarse cells joined through shared vertices: the mesh's connected parts.
      // Refinement does not change them, and every rank holds the whole coarse mesh.
      const unsigned int        n_coarse = triangulation->n_cells(0);
      ConnectedParts            connected(n_coarse);
      std::vector<unsigned int> vertex_cell(triangulation->n_vertices(), numbers::invalid_unsigned_int);
      for (auto cell = triangulation->begin(0); cell != triangulation->end(0); ++cell)
        for (const unsigned int v : cell->vertex_indices())
          {
            unsigned int &first = vertex_cell[cell->vertex_index(v)];
            if (first == numbers::invalid_unsigned_int)
              first = cell->index();
            else
              connected.join(first, cell->index());
          }
      const std::vector<unsigned int> part    = connected.parts();
      const unsigned int              n_parts = n_coarse == 0 ? 0 : *std::max_element(part.begin(), part.end()) + 1;

      std::vector<BoundingBox<dim>>      boxes(n_parts);
      std::vector<bool>                  seen(n_parts, false);
      std::vector<std::set<std::string>> names(n_parts);
      const auto                        &bodies = this->get_scene().body_descriptions();
      for (auto cell = triangulation->begin(0); cell != triangulation->end(0); ++cell)
        {
          const unsigned int p = part[cell->index()];
          for (const unsigned int v : cell->vertex_indices())
            {
              if (!seen[p])
                boxes[p] = BoundingBox<dim>(std::make_pair(cell->vertex(v), cell->vertex(v)));
              seen[p] = true;
              boxes[p].merge_with(BoundingBox<dim>(std::make_pair(cell->vertex(v), cell->vertex(v))));
            }
          if (cell->material_id() < mesh_to_body.size())
            names[p].insert(bodies[mesh_to_body[cell->material_id()]].name);
        }
      std::vector<Point<dim>> centres(n_parts);
      std::vector<double>     sizes(n_parts);
      for (unsigned int p = 0; p < n_parts; ++p)
        {
          centres[p] = boxes[p].center();
          sizes[p]   = std::max(boxes[p].get_boundary_points().first.distance(boxes[p].get_boundary_points().second), 1e-300);
        }

      // Every constrained DoF of a locally owned cell, with the part of its coarse ancestor.
      std::map<types::global_dof_index, unsigned int> listed;
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        listed.emplace(constrained_list[k], k);
      RigidModeCheck<dim>                  check(centres, sizes);
      // A solid of revolution has one rigid-body motion only, the translation along the
      // axis (y): a radial "translation" or an in-plane rotation strains the hoop direction.
      const bool                           axisymmetric = this->get_scene().axisymmetric();
      std::vector<int>                     axially_held(n_parts, 0);
      std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            typename Triangulation<dim>::cell_iterator coarse = cell;
            while (coarse->level() > 0)
              coarse = coarse->parent();
            cell->get_dof_indices(dofs);
            for (const auto dof : dofs)
              if (const auto it = listed.find(dof); it != listed.end())
                {
                  check.add_displacement(part[coarse->index()],
                                         constrained_point[it->second],
                                         constrained_component[it->second]);
                  if (constrained_component[it->second] == 1)
                    axially_held[part[coarse->index()]] = 1;
                }
          }
      check.sum(this->get_scene().mpi_communicator());
      Utilities::MPI::max(axially_held, this->get_scene().mpi_communicator(), axially_held);

      for (unsigned int p = 0; p < n_parts; ++p)
        {
          const auto free = axisymmetric ? (axially_held[p] ? std::vector<std::string>() :
                                                              std::vector<std::string>{"translation in y, along the axis"}) :
                                           check.free_modes(p);
          if (free.empty())
            continue;
          std::string where, modes;
          for (const auto &n : names[p])
            where += (where.empty() ? "Body " : ", Body ") + n;
          for (const auto &m : free)
            modes += (modes.empty() ? "" : ", ") + m;
          throw InputError(where.empty() ? "Boundary names" : where,
                           "unsupported structure: its supports leave a rigid-body motion free (" + modes +
                             "), so the stiffness matrix of a quasi-static analysis is singular. Add "
                             "a fixed, roller, velocity or displacement boundary that prevents it, or "
                             "use FEM/Analysis = implicit dynamics");
        }
    }

    template void Solver<2>::check_supports() const;
    template void Solver<3>::check_supports() const;
  } // namespace FEM
} // namespace hysteron
