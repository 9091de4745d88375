// Boundary conditions and rigid bodies on the grid: the nodes of each condition, and the
// nodal velocities they set (with the reactions and the boundary work).
#include <deal.II/base/mpi.h>

#include "mpm/mpm.h"

#include <algorithm>
#include <array>
#include <iostream>
#include <map>
#include <sstream>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::setup_boundaries()
    {
      const Scene<dim> &scene = this->get_scene();
      const auto       &lattice = grid->lattice();
      boundaries.clear();
      for (const auto &description : scene.boundary_descriptions())
        {
          BoundaryNodes b;
          b.name       = description.name;
          b.type       = static_cast<unsigned int>(description.type);
          b.components = description.components;
          // (node, normal direction, normal sign) in the order of the box's nodes.
          std::vector<std::array<int, 3>> selected;
          grid->for_each_relevant_node([&](const unsigned int n) {
            const auto i = grid->lattice_index(n);
            for (const unsigned int face : description.faces)
              {
                const unsigned int d = face / 2;
                if (i[d] == (face % 2 == 0 ? 0 : static_cast<int>(lattice.n_cells[d])))
                  selected.push_back({{int(n), int(d), face % 2 == 0 ? 1 : -1}});
              }
            if (description.has_region &&
                description.region.contains(grid->node_position(n), 1e-9 * cell_size))
              selected.push_back({{int(n), 0, 0}});
          });
          std::stable_sort(selected.begin(), selected.end(), [](const auto &a, const auto &b) { return a[0] < b[0]; });
          for (const auto &[n, d, sign] : selected)
            {
              b.nodes.push_back(n);
              b.normal_direction.push_back(d);
              b.normal_sign.push_back(sign);
            }
          const unsigned long n_nodes = dealii::Utilities::MPI::sum<unsigned long>(
            std::count_if(b.nodes.begin(), b.nodes.end(), [&](const unsigned int n) { return grid->is_owned(n); }),
            grid->mpi_communicator());
          // A condition acts on grid nodes: one that selects none acts on nothing.
          require(n_nodes > 0,
                  description.where(),
                  "selects no grid node (the background grid is " + grid_extent(grid->lattice()) + ")");
          boundaries.push_back(std::move(b));
        }
      refuse_conflicting_boundaries();
      boundary_acted.assign(boundaries.size(), false);
    }



    template <int dim>
    void
    Solver<dim>::refuse_conflicting_boundaries() const
    {
      // The conditions that prescribe each component of a node, in the order of the scene:
      // a later one must prescribe the same motion as the first (ConditionOverlaps), so that
      // the order in which apply_boundary_conditions() imposes them does not matter.
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      ConditionOverlaps<dim> overlaps(scene.boundary_descriptions(), scene.time_control().end_time, "grid node");
      std::map<unsigned int, std::array<int, dim>> first;
      for (unsigned int b = 0; b < boundaries.size(); ++b)
        for (unsigned int k = 0; k < boundaries[b].nodes.size(); ++k)
          {
            const auto        &bc   = boundaries[b];
            const Type         type = static_cast<Type>(bc.type);
            const unsigned int n    = bc.nodes[k];
            auto [entry, added]     = first.try_emplace(n);
            if (added)
              entry->second.fill(-1);
            for (unsigned int c = 0; c < dim; ++c)
              {
                const bool prescribed = type == Type::fixed || (type == Type::roller && c == bc.normal_direction[k]) ||
                                        ((type == Type::velocity || type == Type::displacement) && bc.components[c]);
                if (!prescribed)
                  continue;
                int &owner = entry->second[c];
                if (owner < 0)
                  owner = b;
                else
                  overlaps.check(owner, b, c, grid->node_position(n));
              }
          }
      overlaps.throw_if_any(grid->mpi_communicator());
    }



    template <int dim>
    std::string
    Solver<dim>::grid_extent(const Lattice<dim> &lattice) const
    {
      const auto         upper = lattice.upper();
      std::ostringstream s;
      for (unsigned int d = 0; d < dim; ++d)
        s << (d > 0 ? " x [" : "[") << lattice.origin[d] << ", " << upper[d] << "]";
      return s.str();
    }



    template <int dim>
    void
    Solver<dim>::warn_about_idle_boundaries() const
    {
      const Scene<dim> &scene = this->get_scene();
      for (unsigned int b = 0; b < boundaries.size(); ++b)
        if (dealii::Utilities::MPI::max(boundary_acted[b] ? 1 : 0, grid->mpi_communicator()) == 0 &&
            scene.is_root())
          std::cerr << "hysteron: warning: Boundary " << boundaries[b].name
                    << ": no material point came near its grid nodes during the run, so it "
                       "acted on nothing (check its Faces or Region)"
                    << std::endl;
    }



    template <int dim>
    void
    Solver<dim>::apply_boundary_conditions(const double t, const double dt, const bool record)
    {
      using Type             = typename BoundaryDescription<dim>::Type;
      constexpr unsigned int C = 1 + 2 * dim;
      double *const          node = grid->data().data();
      const auto            &scene_boundaries = this->get_scene().boundary_descriptions();

      // Set component c of node r to `target`: the velocity change joins the
      // FLIP increment, and m * change / dt is the reaction force on the body.
      const auto impose = [&](double *r, const unsigned int c, const double target, const unsigned int n,
                              dealii::Tensor<1, dim> &reaction) {
        const double change = target - r[1 + c];
        r[1 + c]            = target;
        if (record)
          {
            r[1 + dim + c] += change;
            if (grid->is_owned(n))
              {
                reaction[c] += r[0] * change / dt;
                boundary_work += r[0] * change * target;
              }
          }
      };

      for (unsigned int b = 0; b < boundaries.size(); ++b)
        {
          const auto            &bc   = boundaries[b];
          const Type             type = static_cast<Type>(bc.type);
          dealii::Tensor<1, dim> prescribed;
          if (type == Type::velocity)
            prescribed = scene_boundaries[b].step_velocity(t, dt, dealii::Point<dim>());
          for (unsigned int k = 0; k < bc.nodes.size(); ++k)
            {
              const unsigned int n = bc.nodes[k];
              double *const      r = node + std::size_t(n) * C;
              if (!(r[0] > small_mass))
                continue;
              boundary_acted[b] = true;
              const unsigned int d = bc.normal_direction[k];
              switch (type)
                {
                  case Type::fixed:
                    for (unsigned int c = 0; c < dim; ++c)
                      impose(r, c, 0.0, n, reactions[b]);
                    break;
                  case Type::displacement:
                    // u may depend on the node's position: its mean velocity over the step.
                    prescribed = scene_boundaries[b].step_velocity(t, dt, grid->node_position(n));
                    [[fallthrough]];
                  case Type::velocity:
                    for (unsigned int c = 0; c < dim; ++c)
                      if (bc.components[c])
                        impose(r, c, prescribed[c], n, reactions[b]);
                    break;
                  case Type::roller:
                    impose(r, d, 0.0, n, reactions[b]);
                    break;
                  case Type::wall:
                    // Lower face (sign +1): the body may not move in -d; upper face: not in +d.
                    impose(r, d, bc.normal_sign[k] > 0 ? std::max(r[1 + d], 0.0) : std::min(r[1 + d], 0.0), n, reactions[b]);
                    break;
                  case Type::absorbing: // dashpots in the velocity update (absorbing.cc)
                    break;
                }
            }
        }

      // Nodes touched by a rigid body move with it.
      if (!rigid_nodes.empty())
        {
          const auto &bodies = this->get_scene().body_descriptions();
          std::vector<dealii::Tensor<1, dim>> v(bodies.size());
          for (unsigned int b = 0; b < bodies.size(); ++b)
            if (bodies[b].rigid)
              v[b] = bodies[b].rigid_velocity_at(t);
          for (const unsigned int n : rigid_nodes)
            {
              double *const r = node + std::size_t(n) * C;
              if (!(r[0] > small_mass))
                continue;
              const unsigned int b = rigid_node_body[n] - 1;
              for (unsigned int c = 0; c < dim; ++c)
                impose(r, c, v[b][c], n, reactions[boundaries.size() + b]);
            }
        }

      // Contact: the bodies' own velocities (rigid bodies act here, not on rigid_nodes).
      if (contact)
        apply_contact(t, dt, record);
    }



    template void Solver<2>::setup_boundaries();
    template void Solver<3>::setup_boundaries();
    template std::string Solver<2>::grid_extent(const Lattice<2> &) const;
    template std::string Solver<3>::grid_extent(const Lattice<3> &) const;
    template void Solver<2>::warn_about_idle_boundaries() const;
    template void Solver<3>::warn_about_idle_boundaries() const;
    template void Solver<2>::apply_boundary_conditions(double, double, bool);
    template void Solver<3>::apply_boundary_conditions(double, double, bool);
  } // namespace MPM
} // namespace hysteron
