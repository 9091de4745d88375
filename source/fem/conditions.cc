// The FEM's boundary conditions (Dirichlet sets, walls) and loads (volume, nodal, traction).
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>

#include <hysteron/base/newton.h>
#include <hysteron/base/parameters.h>
#include "fem/fem.h"
#include <hysteron/geometry/mesh.h>

#include "base/implicit_step.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>
namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    Solver<dim>::map_support_points(std::map<dealii::types::global_dof_index, dealii::Point<dim>> &support,
                                    std::map<dealii::types::global_dof_index, unsigned int>       &component)
    {
      dealii::DoFTools::map_dofs_to_support_points(*mapping, dof_handler, support);
      std::vector<dealii::types::global_dof_index> dofs(fe->n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (!cell->is_artificial())
          {
            cell->get_dof_indices(dofs);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              component[dofs[i]] = fe->system_to_component_index(i).first;
          }

      // Support point and component of every owned DoF (loads, walls, start vectors).
      owned_support.resize(owned_dofs.n_elements());
      owned_component.resize(owned_dofs.n_elements());
      for (const auto &[dof, p] : support)
        if (owned_dofs.is_element(dof))
          {
            owned_support[owned_dofs.index_within_set(dof)]   = p;
            owned_component[owned_dofs.index_within_set(dof)] = component[dof];
          }
    }



    template <int dim>
    void
    Solver<dim>::setup_dirichlet()
    {
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      std::map<dealii::types::global_dof_index, dealii::Point<dim>> support;
      std::map<dealii::types::global_dof_index, unsigned int>       component;
      map_support_points(support, component);

      const double tolerance = 1e-9 * u_scale;
      dirichlet.clear();
      wall_forces.clear();
      walls.clear();
      // A DoF that two conditions select belongs to the first (its reaction); the two
      // must prescribe the same motion there (ConditionOverlaps), else the scene is refused.
      std::map<dealii::types::global_dof_index, int> taken;
      ConditionOverlaps<dim> overlaps(scene.boundary_descriptions(), scene.time_control().end_time, "node of the fem mesh");
      unsigned long selected = 0; // by the current condition, shared DoFs included
      const auto add = [&](DirichletSet &set, const dealii::types::global_dof_index dof, const unsigned int c, const int index) {
        ++selected;
        if (const auto first = taken.find(dof); first != taken.end())
          {
            if (set.rigid < 0 && dirichlet[first->second].rigid < 0)
              overlaps.check(dirichlet[first->second].boundary, set.boundary, c, support[dof]);
            return;
          }
        taken[dof] = index;
        set.dofs.push_back(dof);
        set.components.push_back(c);
      };
      for (unsigned int b = 0; b < scene.boundary_descriptions().size(); ++b)
        {
          const auto  &d = scene.boundary_descriptions()[b];
          DirichletSet set;
          set.name     = d.name;
          set.boundary = b;
          const int index = dirichlet.size();
          if (d.type == Type::absorbing)
            {
              // Dashpots on faces (setup_absorbing()), not a constraint.
              dirichlet.push_back(set);
              continue;
            }
          if (d.type == Type::wall)
            {
              // Unilateral: handled by the explicit step, not as a constraint.
              for (const unsigned int face : d.faces)
                {
                  Wall w;
                  w.set       = index;
                  w.direction = face / 2;
                  w.lower     = face % 2 == 0;
                  w.position  = w.lower ? mesh_box.lower_bound(w.direction) :
                                          mesh_box.upper_bound(w.direction);
                  walls.push_back(w);
                }
              dirichlet.push_back(set);
              continue;
            }
          const auto [lower, upper] = mesh_box.get_boundary_points();
          selected                  = 0;
          if (!d.physical_group.empty())
            {
              // The nodes of a Gmsh group's faces or cells.
              for (const auto &[dof, c] : group_dofs(physical_group(d.physical_group, "Boundary " + d.name + "/Set")))
                if (d.type == Type::fixed || d.components[c])
                  add(set, dof, c, index);
            }
          else
            for (const auto &[dof, p] : support)
              if (d.prescribes(p, component[dof], lower, upper, tolerance))
                add(set, dof, component[dof], index);
          const unsigned long n = dealii::Utilities::MPI::sum<unsigned long>(selected, scene.mpi_communicator());
          require(n > 0,
                  d.where(),
                  "selects no node of the fem mesh (faces are those of the mesh's bounding "
                  "box; a region must contain mesh nodes)");
          dirichlet.push_back(std::move(set));
        }
      overlaps.throw_if_any(scene.mpi_communicator());
      // Rigid bodies prescribe their motion on the mesh nodes inside them.
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          {
            DirichletSet set;
            set.name        = bodies[b].name;
            set.rigid       = b;
            const int index = dirichlet.size();
            for (const auto &[dof, p] : support)
              if (bodies[b].shape.contains(p, tolerance))
                add(set, dof, component[dof], index);
            const unsigned long n = dealii::Utilities::MPI::sum<unsigned long>(set.dofs.size(), scene.mpi_communicator());
            require(n > 0,
                    "Body " + bodies[b].name + "/Shape",
                    "the rigid body touches no node of the fem mesh (it acts on the nodes of "
                    "the deformable bodies that lie in its shape)");
            dirichlet.push_back(std::move(set));
          }

      constrained_list.clear();
      constrained_set.clear();
      constrained_component.clear();
      constrained_point.clear();
      for (unsigned int s = 0; s < dirichlet.size(); ++s)
        for (unsigned int k = 0; k < dirichlet[s].dofs.size(); ++k)
          {
            constrained_list.push_back(dirichlet[s].dofs[k]);
            constrained_set.push_back(s);
            constrained_component.push_back(dirichlet[s].components[k]);
            constrained_point.push_back(support[dirichlet[s].dofs[k]]);
          }

      // Walls act on the normal components of all owned DoFs.
      wall_dofs.clear();
      wall_reference.clear();
      wall_of_dof.clear();
      for (unsigned int w = 0; w < walls.size(); ++w)
        for (const auto &[dof, p] : support)
          if (owned_dofs.is_element(dof) && component[dof] == walls[w].direction && !taken.count(dof))
            {
              wall_dofs.push_back(dof);
              wall_reference.push_back(p[walls[w].direction]);
              wall_of_dof.push_back(w);
            }
      wall_forces.assign(dirichlet.size(), dealii::Tensor<1, dim>());
    }



    template <int dim>
    void
    Solver<dim>::make_constraints(const double t1, const bool predictor)
    {
      constrain_prescribed(constraints,
                           relevant_dofs,
                           constrained_list,
                           predictor ? std::function<double(unsigned int)>(
                                         [&](const unsigned int k) { return prescribed_increment(k, t1 - current_dt, t1); }) :
                                       nullptr);
    }



    template <int dim>
    void
    Solver<dim>::setup_loads()
    {
      // A total force acts on the material in its region as a uniform body force
      // F / V (V: the volume of the quadrature points in the region, so that the
      // total is exact); a region without quadrature points shares F evenly among
      // the mesh nodes in it (a point load). A traction acts on the boundary faces
      // whose centre lies in the region.
      using Type              = typename LoadDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      MPI_Comm          comm  = scene.mpi_communicator();
      const auto       &loads = scene.load_descriptions();
      const double      tolerance = 1e-9 * u_scale;
      load_sets.clear();
      load_regions.clear();
      for (unsigned int l = 0; l < loads.size(); ++l)
        {
          LoadSet set;
          set.load = l;
          set.kind = loads[l].type == Type::traction ? LoadSet::Kind::traction : LoadSet::Kind::volume;
          if (!loads[l].physical_group.empty())
            {
              // A group of faces carries a traction (a force: spread as a uniform one), a
              // group of cells a force spread over their volume.
              const std::string   where = "Load " + loads[l].name + "/Set";
              const PhysicalGroup group = physical_group(loads[l].physical_group, where);
              require(group.faces || loads[l].type == Type::force,
                      where,
                      "a traction acts on boundary faces, but the physical group '" +
                        loads[l].physical_group + "' is a group of cells (use Type = force)");
              set.group = group.tag;
              set.kind  = group.faces ? LoadSet::Kind::traction : LoadSet::Kind::volume;
            }
          load_sets.push_back(set);
          load_regions.push_back(&loads[l].region);
        }
      const unsigned int n_loads = load_sets.size();
      cell_in_load.assign(triangulation->n_active_cells() * n_loads, false);
      std::vector<double> selected(n_loads, 0.0);
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h     = *cell_history[cell->active_cell_index()];
            const std::size_t       first = cell->active_cell_index() * n_loads;
            for (unsigned int l = 0; l < n_loads; ++l)
              if (load_sets[l].kind == LoadSet::Kind::volume)
                {
                  if (load_sets[l].group >= 0 && !in_cell_group(cell, load_sets[l].group))
                    continue;
                  for (unsigned int q = 0; q < h.point.size(); ++q)
                    if (in_region(l, h.point[q]))
                      {
                        selected[l] += h.weight[q];
                        cell_in_load[first + l] = true;
                      }
                }
              else
                for (const unsigned int f : cell->face_indices())
                  if (loads_face(l, cell, f))
                    {
                      selected[l] += cell->face(f)->measure() *
                                     scene.thickness_at(scene.body_descriptions()[h.body], cell->face(f)->center());
                      cell_in_load[first + l] = true;
                    }
          }
      dealii::Utilities::MPI::sum(selected, comm, selected);
      for (unsigned int l = 0; l < n_loads; ++l)
        {
          LoadSet &set = load_sets[l];
          if (set.kind == LoadSet::Kind::traction)
            {
              require(selected[l] > 0,
                      "Load " + loads[l].name + (loads[l].set.empty() ? "/Region" : "/Set"),
                      "contains the centre of no boundary face of the fem mesh");
              // A force on a group of faces: the traction F / area.
              set.scale = loads[l].type == Type::force ? 1.0 / selected[l] : 1.0;
              continue;
            }
          if (selected[l] > 0 || set.group >= 0)
            {
              require(selected[l] > 0, "Load " + loads[l].name + "/Set", "the group has no cell");
              set.scale = 1.0 / selected[l];
              continue;
            }
          // A point load: the nodes in the region share the force evenly.
          set.kind = LoadSet::Kind::nodal;
          for (unsigned int k = 0; k < owned_dofs.n_elements(); ++k)
            if (load_regions[l]->contains(owned_support[k], tolerance))
              {
                set.nodal_dofs.push_back(owned_dofs.nth_index_in_set(k));
                set.nodal_components.push_back(owned_component[k]);
              }
          const double nodes =
            dealii::Utilities::MPI::sum<double>(set.nodal_dofs.size(), comm) / double(dim);
          require(nodes > 0,
                  "Load " + loads[l].name + "/Region",
                  "contains no quadrature point and no node of the fem mesh");
          set.scale = 1.0 / nodes;
        }
    }



    template void Solver<2>::map_support_points(std::map<dealii::types::global_dof_index, dealii::Point<2>> &,
                                                std::map<dealii::types::global_dof_index, unsigned int> &);
    template void Solver<3>::map_support_points(std::map<dealii::types::global_dof_index, dealii::Point<3>> &,
                                                std::map<dealii::types::global_dof_index, unsigned int> &);
    template void Solver<2>::setup_dirichlet();
    template void Solver<3>::setup_dirichlet();
    template void Solver<2>::make_constraints(const double, const bool);
    template void Solver<3>::make_constraints(const double, const bool);
    template void Solver<2>::setup_loads();
    template void Solver<3>::setup_loads();
  } // namespace FEM
} // namespace hysteron
