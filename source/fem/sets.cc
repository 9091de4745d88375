// Named sets in the FEM: the physical groups of a Gmsh mesh file (boundary faces or
// cells with a tag, looked up by name or number) and the load-displacement histories
// of `Output/History sets`.
#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include "fem/fem.h"

#include <algorithm>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    typename Solver<dim>::PhysicalGroup
    Solver<dim>::physical_group(const std::string &group, const std::string &where) const
    {
      require(generator == "file",
              where,
              "the physical group '" + group + "' needs a Gmsh mesh (FEM/Mesh/Generator = file); "
              "a generated mesh has none (use Faces or a Region)");
      const MPI_Comm comm = this->get_scene().mpi_communicator();
      // Which tags the mesh has on its boundary faces and on its cells (all ranks).
      const auto present = [&](const unsigned int tag, const bool faces) {
        bool found = false;
        for (const auto &cell : triangulation->active_cell_iterators())
          if (!found && cell->is_locally_owned())
            {
              if (!faces)
                found = in_cell_group(cell, tag);
              else
                for (const unsigned int f : cell->face_indices())
                  found = found || (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == tag);
            }
        return dealii::Utilities::MPI::logical_or(found, comm);
      };
      std::string known;
      for (const auto &[name, dim_tag] : physical_names)
        known += (known.empty() ? "'" : ", '") + name + "' (dimension " + std::to_string(dim_tag.first) +
                 ", tag " + std::to_string(dim_tag.second) + ")";
      const std::string file = "'" + mesh_file + "'";

      PhysicalGroup result;
      const auto    named = physical_names.find(group);
      if (named != physical_names.end())
        {
          const unsigned int group_dim = named->second.first;
          require(group_dim + 1 == dim || group_dim == dim,
                  where,
                  "the physical group '" + group + "' of " + file + " has dimension " +
                    std::to_string(group_dim) + "; a set is a group of boundary " +
                    (dim == 2 ? "lines (dimension 1) or of surfaces (dimension 2)" :
                                "surfaces (dimension 2) or of volumes (dimension 3)"));
          result.faces = group_dim + 1 == dim;
          result.tag   = named->second.second;
          require(present(result.tag, result.faces),
                  where,
                  "the physical group '" + group + "' of " + file + " has no " +
                    (result.faces ? "boundary face" : "cell") + " in the mesh (a group of faces must "
                    "lie on the boundary; Gmsh saves only the elements of physical groups once "
                    "any group is defined, so the bodies need a group too)");
          return result;
        }
      // A number: the tag of a group of boundary faces or of cells, whichever the mesh has.
      long tag = -1;
      try
        {
          tag = dealii::Utilities::string_to_int(group);
        }
      catch (const dealii::ExceptionBase &)
        {
          // Not a number: a name that the mesh does not have (below).
        }
      require(tag > 0,
              where,
              "the mesh file " + file + " has no physical group named '" + group + "'; its named groups: " +
                (known.empty() ? std::string("none") : known) + " (or give a group's number)");
      result.tag            = static_cast<unsigned int>(tag);
      const bool as_faces   = present(result.tag, true);
      const bool as_cells   = present(result.tag, false);
      require(as_faces || as_cells,
              where,
              "no boundary face and no cell of " + file + " has the physical tag " + group);
      require(!(as_faces && as_cells),
              where,
              "the physical tag " + group + " of " + file + " is on boundary faces and on cells: "
              "name the group in Gmsh and give its name");
      result.faces = as_faces;
      return result;
    }



    template <int dim>
    std::vector<std::pair<dealii::types::global_dof_index, unsigned int>>
    Solver<dim>::group_dofs(const PhysicalGroup &group) const
    {
      std::vector<std::pair<dealii::types::global_dof_index, unsigned int>> result;
      std::vector<dealii::types::global_dof_index> dofs(fe->n_dofs_per_cell()), face_dofs(fe->n_dofs_per_face());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (!cell->is_artificial())
          {
            if (!group.faces)
              {
                if (!in_cell_group(cell, group.tag))
                  continue;
                cell->get_dof_indices(dofs);
                for (unsigned int i = 0; i < dofs.size(); ++i)
                  result.emplace_back(dofs[i], fe->system_to_component_index(i).first);
                continue;
              }
            for (const unsigned int f : cell->face_indices())
              if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == group.tag)
                {
                  cell->face(f)->get_dof_indices(face_dofs);
                  for (unsigned int i = 0; i < face_dofs.size(); ++i)
                    result.emplace_back(face_dofs[i], fe->face_system_to_component_index(i).first);
                }
          }
      std::sort(result.begin(), result.end());
      result.erase(std::unique(result.begin(), result.end()), result.end());
      return result;
    }



    template <int dim>
    void
    Solver<dim>::setup_set_histories()
    {
      const Scene<dim> &scene = this->get_scene();
      const MPI_Comm    comm  = scene.mpi_communicator();
      const auto [lower, upper] = mesh_box.get_boundary_points();
      const double tolerance    = 1e-9 * u_scale;
      history_sets.clear();
      for (const unsigned int k : scene.output_control().history_sets)
        {
          const SetDescription<dim> &d = scene.set_descriptions()[k];
          HistorySet                 set;
          if (!d.physical_group.empty())
            {
              for (const auto &[dof, c] : group_dofs(physical_group(d.physical_group, d.where() + "/Physical group")))
                if (owned_dofs.is_element(dof))
                  {
                    set.dofs.push_back(dof);
                    set.components.push_back(c);
                  }
            }
          else
            for (unsigned int i = 0; i < owned_dofs.n_elements(); ++i)
              {
                const dealii::Point<dim> &x = owned_support[i];
                bool in = d.has_region && d.region.contains(x, tolerance);
                for (const unsigned int face : d.faces)
                  in = in || std::abs(x[face / 2] - (face % 2 == 0 ? lower[face / 2] : upper[face / 2])) <= tolerance;
                if (in)
                  {
                    set.dofs.push_back(owned_dofs.nth_index_in_set(i));
                    set.components.push_back(owned_component[i]);
                  }
              }
          // The mean over the set's nodes: one DoF per node and component.
          std::vector<double> count(dim, 0.0);
          for (const unsigned int c : set.components)
            count[c] += 1;
          dealii::Utilities::MPI::sum(count, comm, count);
          require(count[0] > 0,
                  d.where(),
                  "selects no node of the fem mesh (faces are those of the mesh's bounding box; "
                  "a region must contain mesh nodes)");
          for (unsigned int c = 0; c < dim; ++c)
            set.weight[c] = 1.0 / count[c];
          history_sets.push_back(std::move(set));
        }
    }



    template <int dim>
    std::vector<double>
    Solver<dim>::set_history_values() const
    {
      // Per set: the mean displacement of its nodes, the force of the supports on them
      // (f_int + M a + C v - f_ext of the converged state, as in reactions.csv) and the
      // external force on them (loads and weight, as nodal forces); this rank's part.
      std::vector<double> values(history_sets.size() * 3 * dim, 0.0);
      for (unsigned int s = 0; s < history_sets.size(); ++s)
        {
          const HistorySet &set = history_sets[s];
          double           *row = values.data() + s * 3 * dim;
          for (unsigned int k = 0; k < set.dofs.size(); ++k)
            {
              const auto         dof = set.dofs[k];
              const unsigned int c   = set.components[k];
              row[c] += set.weight[c] * u(dof);
              row[dim + c] += reaction_old(dof);
              row[2 * dim + c] += f_ext_old(dof);
            }
        }
      return values;
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron
