// The MPM's part of a checkpoint: this rank's material points, bit for bit and in
// the order of the arrays (the order of the sums of every step), and the sums
// that a step carries over (works, reactions, the cell changes since the last sort).
#include "mpm/mpm.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &out) const
    {
      const auto &P = particles;
      out.section("mpm points");
      out.put(P.id);
      out.put(P.body);
      out.put(P.load);
      out.put(P.mass);
      out.put(P.volume0);
      out.put(P.thickness);
      out.put(P.load_factor);
      out.put(P.x0);
      out.put(P.cell);
      out.put(P.current.x);
      out.put(P.current.v);
      out.put(P.current.stress);
      out.put(P.current.strain);
      out.put(P.current.F);
      out.put(P.current.volume);
      out.put(P.current.material_state);
      out.section("mpm groups");
      out.put<std::uint64_t>(P.groups.size());
      for (const auto &g : P.groups)
        {
          // The group's template: the index of its material (or rigid body).
          unsigned int key = 0;
          for (unsigned int i = 0; i < group_templates.size(); ++i)
            if (group_templates[i].material == g.material &&
                (g.material != nullptr || group_templates[i].rigid_body == g.rigid_body))
              key = i;
          out.put(key);
          out.put(g.begin);
          out.put(g.end);
          out.put(g.state_offset);
        }
      out.section("mpm sums");
      out.put(internal_work);
      out.put(external_work);
      out.put(boundary_work);
      out.put(initial_kinetic_energy);
      out.put(max_speed);
      out.put(reactions);
      out.put(n_changed_cells);
      out.put(n_rebuilds);
      tables.save(out);
      if (grid_moves)
        {
          // Where the grid is (a checkpoint of a fixed grid has no such section).
          out.section("mpm grid motion");
          const Lattice<dim> &lattice = grid->lattice();
          out.put(std::vector<double>(&lattice.origin[0], &lattice.origin[0] + dim));
          out.put(std::vector<double>(lattice.h.begin(), lattice.h.end()));
          out.put(grid_table_time);
        }
    }



    template <int dim>
    void
    Solver<dim>::load(CheckpointReader &in)
    {
      using namespace dealii;
      auto &P = particles;
      // What the conditions did before the checkpoint is not stored: no idle warning.
      boundary_acted.assign(boundaries.size(), true);
      in.section("mpm points");
      in.get(P.id);
      const std::size_t n = P.id.size();
      in.get(P.body);
      in.get(P.load);
      in.get(P.mass);
      in.get(P.volume0);
      in.get(P.thickness);
      in.get(P.load_factor);
      in.get(P.x0);
      in.get(P.cell);
      in.get(P.current.x);
      in.get(P.current.v);
      in.get(P.current.stress);
      in.get(P.current.strain);
      in.get(P.current.F);
      in.get(P.current.volume);
      in.get(P.current.material_state);
      for (const std::size_t size : {P.body.size(), P.load.size(), P.mass.size(), P.x0.size(),
                                     P.cell.size(), P.current.x.size(), P.current.v.size(),
                                     P.current.stress.size(), P.current.F.size(),
                                     P.current.volume.size()})
        if (size != n)
          in.refuse("the material points' arrays have different lengths");
      P.next.resize(n, P.current.material_state.size());

      in.section("mpm groups");
      P.groups.resize(in.get<std::uint64_t>());
      for (auto &g : P.groups)
        {
          const auto key = in.get<unsigned int>();
          if (key >= group_templates.size())
            in.refuse("a group of material points has no material in this scene");
          g = group_templates[key];
          in.get(g.begin);
          in.get(g.end);
          in.get(g.state_offset);
          if (g.end > n || g.begin > g.end ||
              g.state_offset + std::size_t(g.end - g.begin) * g.n_state >
                P.current.material_state.size())
            in.refuse("a group of material points lies outside the arrays");
        }

      in.section("mpm sums");
      in.get(internal_work);
      in.get(external_work);
      in.get(boundary_work);
      in.get(initial_kinetic_energy);
      in.get(max_speed);
      in.get(reactions);
      in.get(n_changed_cells);
      in.get(n_rebuilds);
      tables.load(in);
      if (grid_moves)
        {
          in.section("mpm grid motion");
          std::vector<double> origin, h;
          in.get(origin);
          in.get(h);
          in.get(grid_table_time);
          if (origin.size() != dim || h.size() != dim)
            in.refuse("the moving grid's corner or cell sizes have the wrong dimension");
          Lattice<dim> moved = grid->lattice();
          for (unsigned int d = 0; d < dim; ++d)
            {
              if (!(h[d] > 0) || !std::isfinite(origin[d]))
                in.refuse("the moving grid's corner or cell sizes are not valid");
              moved.origin[d] = origin[d];
              moved.h[d]      = h[d];
            }
          grid->move(moved);
        }

      // The ParticleHandler holds the same points (identity, owner, output): it is
      // refilled from the arrays, and handler_index maps its order to theirs.
      using PI                    = PropertiesIndex<dim>;
      const Lattice<dim> &lattice = grid->lattice();
      handler->clear_particles();
      std::vector<double> properties(n_properties, 0.0);
      for (std::size_t s = 0; s < n; ++s)
        {
          const Point<dim> &x    = P.current.x[s];
          const auto        cell = lattice.cell_of(x);
          const unsigned int cid = grid->cell_id(cell);
          if (!grid->owns_cell(cid))
            in.refuse("material point " + std::to_string(P.id[s]) +
                      " lies outside this rank's cells");
          // The constant slots (to_handler() writes the others below).
          properties[PI::body]      = P.body[s];
          properties[PI::load]      = P.load[s];
          properties[PI::mass]      = P.mass[s];
          properties[PI::volume0]   = P.volume0[s];
          properties[PI::thickness] = P.thickness[s];
          insert_into_handler(x, P.id[s], make_array_view(std::as_const(properties)));
        }
      handler->update_cached_numbers();
      std::vector<std::pair<types::particle_index, unsigned int>> by_id(n);
      for (std::size_t s = 0; s < n; ++s)
        by_id[s] = {P.id[s], static_cast<unsigned int>(s)};
      std::sort(by_id.begin(), by_id.end());
      P.handler_index.resize(n);
      unsigned int k = 0;
      for (const auto &particle : *handler)
        {
          const auto it = std::lower_bound(by_id.begin(),
                                           by_id.end(),
                                           std::make_pair(particle.get_id(), 0u));
          P.handler_index[it->second] = k++;
        }
      to_handler();

      for (auto &probe : probes)
        probe.local = -1;
      for (std::size_t s = 0; s < n; ++s)
        for (auto &probe : probes)
          if (P.id[s] == probe.id)
            probe.local = s;
      left_subdomain = false;
      failed_point   = -1;
    }

    template void Solver<2>::save(CheckpointWriter &) const;
    template void Solver<3>::save(CheckpointWriter &) const;
    template void Solver<2>::load(CheckpointReader &);
    template void Solver<3>::load(CheckpointReader &);
  } // namespace MPM
} // namespace hysteron
