// Are the supports enough for a quasi-static analysis? Each connected part of the
// mesh must have its rigid-body motions prevented by Dirichlet conditions, or the
// stiffness matrix is singular and Newton drifts.
#include <deal.II/base/mpi.h>

#include <deal.II/grid/grid_tools.h>

#include <hysteron/base/rigid_modes.h>
#include "fem/fem.h"

#include <algorithm>
#include <limits>
#include <map>
#include <set>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /**
       * The connected parts of a distributed mesh (cells joined through shared vertices),
       * without the whole mesh on any rank: the locally owned and ghost cells are joined on
       * each rank; every part is labelled with the smallest global index of its cells, found
       * by taking each local part's minimum and handing the owned cells' labels to the
       * ranks that have them as ghosts until no label changes anywhere (at most about one
       * round per rank a part spans). Returns the part of every active cell (by active cell
       * index; owned cells only), numbered 0, 1, ... in the order of the labels on every rank,
       * and their number in @p n_parts.
       */
      template <int dim>
      std::vector<unsigned int>
      connected_parts(const dealii::parallel::TriangulationBase<dim> &tria, unsigned int &n_parts)
      {
        using namespace dealii;
        using Label = types::global_cell_index;
        const unsigned int n_cells = tria.n_active_cells();
        ConnectedParts     local(n_cells);
        std::vector<unsigned int> vertex_cell(tria.n_vertices(), numbers::invalid_unsigned_int);
        std::vector<Label>        label(n_cells, numbers::invalid_dof_index);
        for (const auto &cell : tria.active_cell_iterators())
          if (!cell->is_artificial())
            {
              label[cell->active_cell_index()] = cell->global_active_cell_index();
              for (const unsigned int v : cell->vertex_indices())
                {
                  unsigned int &first = vertex_cell[cell->vertex_index(v)];
                  if (first == numbers::invalid_unsigned_int)
                    first = cell->active_cell_index();
                  else
                    local.join(first, cell->active_cell_index());
                }
            }
        const std::vector<unsigned int> component = local.parts();
        const unsigned int n_components = n_cells == 0 ? 0 : *std::max_element(component.begin(), component.end()) + 1;
        for (bool changed = true; Utilities::MPI::logical_or(changed, tria.get_communicator());)
          {
            changed = false;
            std::vector<Label> smallest(n_components, numbers::invalid_dof_index);
            for (unsigned int c = 0; c < n_cells; ++c)
              smallest[component[c]] = std::min(smallest[component[c]], label[c]);
            for (unsigned int c = 0; c < n_cells; ++c)
              if (smallest[component[c]] < label[c])
                {
                  label[c] = smallest[component[c]];
                  changed  = true;
                }
            GridTools::exchange_cell_data_to_ghosts<Label, parallel::TriangulationBase<dim>>(
              tria,
              [&](const auto &cell) { return std_cxx17::optional<Label>(label[cell->active_cell_index()]); },
              [&](const auto &cell, const Label &owner) {
                if (owner < label[cell->active_cell_index()])
                  {
                    label[cell->active_cell_index()] = owner;
                    changed                          = true;
                  }
              });
          }
        std::vector<Label> labels;
        for (const auto &cell : tria.active_cell_iterators())
          if (cell->is_locally_owned())
            labels.push_back(label[cell->active_cell_index()]);
        std::sort(labels.begin(), labels.end());
        labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
        std::vector<Label> all;
        for (const auto &part : Utilities::MPI::all_gather(tria.get_communicator(), labels))
          all.insert(all.end(), part.begin(), part.end());
        std::sort(all.begin(), all.end());
        all.erase(std::unique(all.begin(), all.end()), all.end());
        n_parts = all.size();
        std::vector<unsigned int> part(n_cells, numbers::invalid_unsigned_int);
        for (const auto &cell : tria.active_cell_iterators())
          if (cell->is_locally_owned())
            part[cell->active_cell_index()] =
              std::lower_bound(all.begin(), all.end(), label[cell->active_cell_index()]) - all.begin();
        return part;
      }
    } // namespace



    template <int dim>
    void
    Solver<dim>::check_supports() const
    {
      using namespace dealii;
      if (analysis != Analysis::quasi_static)
        return; // the mass matrix makes the dynamic system regular

      // The mesh's connected parts, their bounding boxes and bodies (each rank adds its cells).
      const MPI_Comm                     comm    = this->get_scene().mpi_communicator();
      unsigned int                       n_parts = 0;
      const std::vector<unsigned int>    part    = connected_parts(*triangulation, n_parts);
      const auto                        &bodies  = this->get_scene().body_descriptions();
      std::vector<double>                lower(n_parts * dim, std::numeric_limits<double>::max());
      std::vector<double>                upper(n_parts * dim, -std::numeric_limits<double>::max());
      std::vector<unsigned int>          has_body(n_parts * mesh_to_body.size(), 0);
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const unsigned int p = part[cell->active_cell_index()];
            for (const unsigned int v : cell->vertex_indices())
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lower[p * dim + d] = std::min(lower[p * dim + d], cell->vertex(v)[d]);
                  upper[p * dim + d] = std::max(upper[p * dim + d], cell->vertex(v)[d]);
                }
            has_body[p * mesh_to_body.size() + cell->material_id()] = 1;
          }
      Utilities::MPI::min(lower, comm, lower);
      Utilities::MPI::max(upper, comm, upper);
      Utilities::MPI::max(has_body, comm, has_body);
      std::vector<std::set<std::string>> names(n_parts);
      for (unsigned int p = 0; p < n_parts; ++p)
        for (unsigned int m = 0; m < mesh_to_body.size(); ++m)
          if (has_body[p * mesh_to_body.size() + m])
            names[p].insert(bodies[mesh_to_body[m]].name);

      std::vector<Point<dim>> centres(n_parts);
      std::vector<double>     sizes(n_parts);
      for (unsigned int p = 0; p < n_parts; ++p)
        {
          Point<dim> lo, hi;
          for (unsigned int d = 0; d < dim; ++d)
            {
              lo[d] = lower[p * dim + d];
              hi[d] = upper[p * dim + d];
            }
          centres[p] = 0.5 * (lo + hi);
          sizes[p]   = std::max(lo.distance(hi), 1e-300);
        }

      // Every constrained DoF of a locally owned cell, with the part of that cell.
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
            const unsigned int p = part[cell->active_cell_index()];
            cell->get_dof_indices(dofs);
            for (const auto dof : dofs)
              if (const auto it = listed.find(dof); it != listed.end())
                {
                  check.add_displacement(p, constrained_point[it->second], constrained_component[it->second]);
                  if (constrained_component[it->second] == 1)
                    axially_held[p] = 1;
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
