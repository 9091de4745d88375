// The material points: the bodies filled with points (before the grid, whose partition
// they weigh), the points' creation in the ParticleHandler, and the copies between the
// handler and the step's contiguous arrays (from_handler(), to_handler()).
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include "mpm/mpm.h"

#include <algorithm>
#include <climits>
#include <limits>
#include <map>
#include <tuple>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>
#include <utility>

namespace hysteron
{
  namespace MPM
  {
    namespace
    {
      const char *const *const component_suffix = PointData::component_names;

      /**
       * The material point nearest to a probe: this rank's, then all ranks'. Ties go
       * to the smallest (body, lattice cell id, place in the cell), the order of the
       * fill, so that the choice is the same on any number of ranks.
       */
      template <int dim>
      struct ProbeCandidate
      {
        double                        distance = std::numeric_limits<double>::max();
        std::array<unsigned int, 3>   order{{UINT_MAX, UINT_MAX, UINT_MAX}};
        dealii::types::particle_index id = 0;
        std::array<double, dim>       x{};

        void
        consider(const double                       r,
                 const std::array<unsigned int, 3> &o,
                 const dealii::types::particle_index i,
                 const dealii::Point<dim>          &p)
        {
          if (std::tie(r, o) < std::tie(distance, order))
            {
              distance = r;
              order    = o;
              id       = i;
              for (unsigned int d = 0; d < dim; ++d)
                x[d] = p[d];
            }
        }

        ProbeCandidate
        nearest(const MPI_Comm comm) const
        {
          ProbeCandidate result;
          for (const auto &c : dealii::Utilities::MPI::all_gather(comm, *this))
            result.consider(c.distance, c.order, c.id, c.position());
          return result;
        }

        dealii::Point<dim>
        position() const
        {
          dealii::Point<dim> p;
          for (unsigned int d = 0; d < dim; ++d)
            p[d] = x[d];
          return p;
        }
      };
    } // namespace



    template <int dim>
    void
    Solver<dim>::setup_grid()
    {
      const Scene<dim> &scene = this->get_scene();
      grid = std::make_unique<BackgroundGrid<dim>>(scene.mpi_communicator());
      // A point reaches one node beyond its cell with the cubic B-splines (4 per direction).
      grid->create(lower, cell_size, n_cells, basis_name == "linear" ? 0 : 1);
      const auto &bodies = scene.body_descriptions();
      const Geometry::FillLattice<dim> fill_lattice{lower, cell_size, n_cells};
      // The points of this rank's cells (every rank fills only its own part of the lattice).
      const auto fill_owned = [&](const unsigned int b) {
        const auto [first, last] = grid->owned_cell_range();
        for (unsigned int d = 0; d < dim; ++d)
          if (first[d] > last[d])
            return std::vector<dealii::Point<dim>>();
        return Geometry::fill<dim>(bodies[b].shape,
                                   fill_lattice,
                                   bodies[b].particles_per_cell,
                                   first,
                                   last,
                                   [&](const std::array<unsigned int, dim> &c) { return grid->owns_cell(c); });
      };
      if (grid->is_parallel())
        {
          // The work of a block: its material points plus `Cell weight` per grid cell, counted
          // in the blocks of the first (equal) partition; p4est then balances the work.
          const Lattice<dim> &lattice = grid->initial_lattice_geometry();
          std::map<std::array<unsigned int, dim>, double> work;
          for (unsigned int b = 0; b < bodies.size(); ++b)
            for (const auto &x : fill_owned(b))
              work[grid->block_of(lattice.cell_of(x))] += 1.0;
          grid->repartition([&](const std::array<unsigned int, dim> &block) {
            double cells = 1;
            for (unsigned int d = 0; d < dim; ++d)
              cells *= std::min((block[d] + 1) * grid->block_size(), n_cells[d]) - block[d] * grid->block_size();
            const auto it = work.find(block);
            return static_cast<unsigned int>(
              std::llround(100 * ((it == work.end() ? 0.0 : it->second) + cell_weight * cells)));
          });
        }
      grid->setup_nodes(1 + 2 * dim);

      body_points.clear();
      for (unsigned int b = 0; b < bodies.size(); ++b)
        body_points.push_back(fill_owned(b));
      // Two bodies in one place would put two material points (twice the mass) there.
      for (unsigned int b = 1; b < bodies.size(); ++b)
        for (unsigned int a = 0; a < b; ++a)
          {
            unsigned long n_inside = 0, n_points = body_points[b].size();
            for (const auto &x : body_points[b])
              n_inside += bodies[a].shape.contains(x) ? 1 : 0;
            n_inside = dealii::Utilities::MPI::sum(n_inside, scene.mpi_communicator());
            n_points = dealii::Utilities::MPI::sum(n_points, scene.mpi_communicator());
            require(n_inside == 0,
                    "Body " + bodies[b].name + "/Shape",
                    "overlaps Body " + bodies[a].name + ": " + std::to_string(n_inside) + " of its " +
                      std::to_string(n_points) +
                      " material points lie inside that body's shape (two bodies in one place would "
                      "double the mass there)");
          }
      node_stamp.reset(grid->n_local_nodes(), grid->sparse_box());
      rigid_node_body.reset(grid->n_local_nodes(), grid->sparse_box());
      grid->track_reached_nodes(node_stamp.data(), &stamp);
      active_nodes.clear();
      rigid_nodes.clear();
    }



    template <int dim>
    void
    Solver<dim>::setup_groups()
    {
      using PI                = PropertiesIndex<dim>;
      const Scene<dim> &scene = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      // Groups: one per material of the deformable bodies, one per rigid body.
      group_of_body.assign(bodies.size(), 0);
      group_templates.clear();
      particles.n_state_slots = 0;
      state_names.clear();
      for (unsigned int b = 0; b < bodies.size(); ++b)
        {
          typename ParticleStore<dim>::Group g;
          if (bodies[b].rigid)
            g.rigid_body = b;
          else
            {
              g.material   = &scene.material(bodies[b].material, "Body " + bodies[b].name + "/Material");
              g.n_state    = g.material->n_state_variables();
              g.wave_speed = g.material->elasticity().p_wave_speed();
              if (g.n_state > particles.n_state_slots)
                {
                  particles.n_state_slots = g.n_state;
                  state_names             = g.material->state_variable_names();
                }
            }
          unsigned int found = group_templates.size();
          for (unsigned int i = 0; i < group_templates.size(); ++i)
            if (!bodies[b].rigid && group_templates[i].material == g.material)
              found = i;
          if (found == group_templates.size())
            group_templates.push_back(g);
          group_of_body[b] = found;
        }

      n_properties = PI::n_fixed + particles.n_state_slots;
      handler      = std::make_unique<dealii::Particles::ParticleHandler<dim>>(grid->triangulation(),
                                                                             mapping,
                                                                             n_properties);
    }



    template <int dim>
    void
    Solver<dim>::generate_particles()
    {
      using namespace dealii;
      using PI              = PropertiesIndex<dim>;
      const Scene<dim> &scene = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      const auto       &loads  = scene.load_descriptions();
      setup_groups();

      // This rank's points (its cells' part of every body's fill). Their ids are the
      // same on any number of ranks: body by body, the blocks in the order of p4est's
      // curve (which is the order of the ranks' parts), within a block the fill's order
      // (cells lexicographically, then sub-cells), so that within a cell the ids keep
      // the fill's order.
      const Lattice<dim> &lattice = grid->lattice();
      const MPI_Comm      comm    = scene.mpi_communicator();
      std::map<std::array<unsigned int, dim>, unsigned int> block_position;
      for (const auto &b : grid->owned_blocks())
        block_position.emplace(b, block_position.size());
      std::vector<std::uint64_t> count(bodies.size()), first_id(bodies.size(), 0);
      for (unsigned int b = 0; b < bodies.size(); ++b)
        count[b] = body_points[b].size();
      {
        std::vector<std::uint64_t> before(bodies.size(), 0);
        int ierr = MPI_Exscan(count.data(), before.data(), bodies.size(), MPI_UINT64_T, MPI_SUM, comm);
        AssertThrowMPI(ierr);
        if (Utilities::MPI::this_mpi_process(comm) == 0)
          std::fill(before.begin(), before.end(), 0);
        std::vector<std::uint64_t> total(bodies.size());
        ierr = MPI_Allreduce(count.data(), total.data(), bodies.size(), MPI_UINT64_T, MPI_SUM, comm);
        AssertThrowMPI(ierr);
        std::uint64_t offset = 0;
        for (unsigned int b = 0; b < bodies.size(); ++b)
          {
            first_id[b] = offset + before[b];
            count[b]    = total[b];
            offset += total[b];
          }
        require(offset < std::numeric_limits<types::particle_index>::max(),
                "Body names",
                "the bodies hold " + std::to_string(offset) +
                  " material points, more than this deal.II build's 32-bit particle index allows");
        n_global_particles = offset;
      }

      load_count.assign(loads.size() + 1, 0);
      load_volume.assign(loads.size() + 1, 0.0);
      std::vector<double> properties(n_properties);
      // A probe follows its nearest material point of a deformable body; ties go to the
      // first in the fill's order (body, cell, place in the cell): the same on any ranks.
      std::vector<ProbeCandidate<dim>> best(probes.size());
      for (unsigned int b = 0; b < bodies.size(); ++b)
        {
          const auto &body   = bodies[b];
          const auto &points = body_points[b];
          require(count[b] > 0,
                  "Body " + body.name + "/Shape",
                  "the body holds no material point (points sit at the centres of the " +
                    std::to_string(body.particles_per_cell) + "^" + std::to_string(dim) +
                    " sub-cells of each grid cell: refine the grid or raise `Particles per "
                    "cell`)");
          std::vector<unsigned int> order(points.size()), cell_of_point(points.size());
          std::iota(order.begin(), order.end(), 0u);
          for (unsigned int i = 0; i < points.size(); ++i)
            cell_of_point[i] = block_position.at(grid->block_of(lattice.cell_of(points[i])));
          std::stable_sort(order.begin(), order.end(), [&](const unsigned int i, const unsigned int j) {
            return cell_of_point[i] < cell_of_point[j];
          });
          std::vector<types::particle_index> id(points.size());
          for (unsigned int k = 0; k < order.size(); ++k)
            id[order[k]] = first_id[b] + k;

          const auto  &group = group_templates[group_of_body[b]];
          // The point's share of the body: its sub-cell times the thickness there (2D;
          // axisymmetric: times the circumference 2 pi r).
          const double cell_volume = std::pow(cell_size / body.particles_per_cell, dim);
          const double density =
            scene.material(body.material, "Body " + body.name + "/Material").density();
          unsigned int previous_cell = std::numeric_limits<unsigned int>::max(), place = 0;
          for (unsigned int i = 0; i < points.size(); ++i)
            {
              const auto        &x    = points[i];
              const auto         cell = lattice.cell_of(x);
              const unsigned int cid  = grid->cell_id(cell);
              place                   = cid == previous_cell ? place + 1 : 0;
              previous_cell           = cid;
              unsigned int load       = 0;
              if (!body.rigid)
                for (unsigned int l = 0; l < loads.size() && load == 0; ++l)
                  if (loads[l].region.contains(x, 1e-9 * cell_size))
                    load = l + 1;
              // Axisymmetric: the ring around the axis, 2 pi r per unit of section area.
              const double thickness = scene.thickness_at(body, x);
              const double volume    = cell_volume * thickness;
              ++load_count[load];
              load_volume[load] += volume;
              if (!body.rigid)
                for (unsigned int p = 0; p < probes.size(); ++p)
                  best[p].consider(x.distance(probes[p].point), {{b, cid, place}}, id[i], x);

              std::fill(properties.begin(), properties.end(), 0.0);
              properties[PI::mass]      = density * volume;
              properties[PI::volume0]   = volume;
              properties[PI::volume]    = volume;
              properties[PI::thickness] = thickness;
              properties[PI::body]      = b;
              properties[PI::load]      = load;
              const Tensor<1, dim> v =
                body.rigid ? body.rigid_velocity_at(0.0) : body.velocity_at(x);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  properties[PI::velocity + d]                       = v[d];
                  properties[PI::deformation_gradient + d * dim + d] = 1.0;
                }
              if (group.material != nullptr && group.n_state > 0)
                group.material->initialize_state(
                  view(properties.data() + PI::n_fixed, group.n_state));
              insert_into_handler(x, id[i], make_array_view(std::as_const(properties)));
            }
        }
      Utilities::MPI::sum(make_array_view(std::as_const(load_count)), comm, make_array_view(load_count));
      Utilities::MPI::sum(make_array_view(std::as_const(load_volume)), comm, make_array_view(load_volume));
      // A probe follows its nearest material point; a point farther than a grid cell
      // diagonal from every one of them lies outside the deformable bodies.
      for (unsigned int p = 0; p < probes.size(); ++p)
        {
          const ProbeCandidate<dim> nearest = best[p].nearest(comm);
          if (!(nearest.distance <= std::sqrt(double(dim)) * cell_size))
            {
              std::ostringstream what;
              what << "the point (" << probes[p].point << ") lies outside the deformable bodies: ";
              if (nearest.distance < std::numeric_limits<double>::max())
                what << "the nearest material point is " << nearest.distance
                     << " m away (more than a grid cell diagonal, " << std::sqrt(double(dim)) * cell_size
                     << " m)";
              else
                what << "the scene has no deformable body";
              throw InputError("Output/Probe points", what.str());
            }
          probes[p].id               = nearest.id;
          probes[p].initial_position = nearest.position();
        }
      body_points.clear();
      body_points.shrink_to_fit();
      handler->update_cached_numbers();
      for (unsigned int l = 1; l < load_count.size(); ++l)
        require(load_count[l] > 0,
                "Load " + loads[l - 1].name + "/Region",
                "the region contains no material point of a deformable body");
    }



    template <int dim>
    void
    Solver<dim>::from_handler()
    {
      using namespace dealii;
      using PI                = PropertiesIndex<dim>;
      const Scene<dim> &scene = this->get_scene();
      const auto       &loads = scene.load_descriptions();
      const unsigned int n    = handler->n_locally_owned_particles();
      const Lattice<dim> &lattice = grid->lattice();
      // Where a point is: the handler holds the set-up's frame of a moving grid.
      const auto location = [&](const Particles::ParticleAccessor<dim> &particle) {
        return grid_moves ? grid->from_initial_frame(particle.get_location()) : particle.get_location();
      };

      // First pass: the sort key of every point (handler order): group, cell, id.
      std::vector<types::particle_index> ids(n);
      std::vector<unsigned int>          key(n), cells(n);
      {
        unsigned int k = 0;
        for (const auto &particle : *handler)
          {
            ids[k]   = particle.get_id();
            key[k]   = group_of_body[static_cast<unsigned int>(particle.get_properties()[PI::body])];
            cells[k] = grid->cell_id(lattice.cell_of(location(particle)));
            ++k;
          }
      }
      std::vector<unsigned int> order(n);
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](const unsigned int a, const unsigned int b) {
        return std::tie(key[a], cells[a], ids[a]) < std::tie(key[b], cells[b], ids[b]);
      });

      // Group ranges and state offsets.
      particles.groups.clear();
      std::size_t n_state_total = 0;
      for (unsigned int s = 0; s < n; ++s)
        {
          const unsigned int g = key[order[s]];
          if (particles.groups.empty() || g != current_group_key)
            {
              auto group         = group_templates[g];
              group.begin        = s;
              group.end          = s;
              group.state_offset = n_state_total;
              particles.groups.push_back(group);
              current_group_key = g;
            }
          auto &group = particles.groups.back();
          ++group.end;
          n_state_total += group.n_state;
        }

      auto &P = particles;
      P.id.resize(n);
      P.body.resize(n);
      P.load.resize(n);
      P.mass.resize(n);
      P.volume0.resize(n);
      P.thickness.resize(n);
      P.load_factor.resize(n);
      P.x0.resize(n);
      P.cell.resize(n);
      P.handler_index.resize(n);
      P.current.resize(n, n_state_total);
      P.next.resize(n, n_state_total);

      // Second pass (same order): copy every point straight to its place.
      std::vector<unsigned int> place(n), group_of(n);
      for (unsigned int s = 0; s < n; ++s)
        place[order[s]] = s;
      for (unsigned int g = 0; g < P.groups.size(); ++g)
        for (unsigned int s = P.groups[g].begin; s < P.groups[g].end; ++s)
          group_of[s] = g;
      unsigned int k = 0;
      for (const auto &particle : *handler)
        {
          const unsigned int s     = place[k];
          const auto        &group = P.groups[group_of[s]];
          const auto         q     = particle.get_properties();
          const Point<dim>   x     = location(particle);
          P.handler_index[s]       = k;
          P.id[s]                  = ids[k];
          P.cell[s]                = cells[k];
          ++k;
          P.body[s]           = static_cast<unsigned int>(q[PI::body]);
          P.load[s]           = static_cast<unsigned int>(q[PI::load]);
          P.mass[s]           = q[PI::mass];
          P.volume0[s]        = q[PI::volume0];
          P.thickness[s]      = q[PI::thickness];
          P.current.x[s]      = x;
          P.current.volume[s] = q[PI::volume];
          for (unsigned int d = 0; d < dim; ++d)
            {
              P.current.v[s][d] = q[PI::velocity + d];
              P.x0[s][d]        = x[d] - q[PI::displacement + d];
              for (unsigned int e = 0; e < dim; ++e)
                P.current.F[s][d][e] = q[PI::deformation_gradient + d * dim + e];
            }
          for (unsigned int c = 0; c < PI::n_sym; ++c)
            {
              const auto ij = SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
              P.current.stress[s][ij] = q[PI::stress + c];
              P.current.strain[s][ij] = q[PI::strain + c];
            }
          std::copy(q.begin() + PI::n_fixed,
                    q.begin() + PI::n_fixed + group.n_state,
                    P.current.material_state.begin() + group.state_offset +
                      std::size_t(s - group.begin) * group.n_state);
          // Load share: a total force is split by volume (evenly for a constant thickness);
          // a traction acts on the point's face, of area V / l_p with l_p = (V / thickness)^(1/dim).
          P.load_factor[s] = 0;
          if (P.load[s] > 0)
            {
              if (loads[P.load[s] - 1].type == LoadDescription<dim>::Type::force)
                P.load_factor[s] = P.volume0[s] / load_volume[P.load[s]];
              else
                P.load_factor[s] = P.volume0[s] / std::pow(P.volume0[s] / P.thickness[s], 1.0 / dim);
            }
        }

      for (auto &probe : probes)
        probe.local = -1;
      for (unsigned int s = 0; s < n; ++s)
        for (auto &probe : probes)
          if (P.id[s] == probe.id)
            probe.local = s;
      n_changed_cells = 0;
      left_subdomain  = false;

      // The speed that bounds the next step (eq. 4.47).
      max_speed = 0;
      for (const auto &group : P.groups)
        for (unsigned int s = group.begin; s < group.end; ++s)
          max_speed = std::max(max_speed, group.wave_speed + P.current.v[s].norm());
    }



    template <int dim>
    void
    ParticleStore<dim>::State::resize(const std::size_t n, const std::size_t n_material_state)
    {
      x.resize(n);
      v.resize(n);
      stress.resize(n);
      strain.resize(n);
      F.resize(n);
      volume.resize(n);
      material_state.resize(n_material_state);
    }



    template <int dim>
    void
    Solver<dim>::insert_into_handler(const dealii::Point<dim>              &x,
                                     const dealii::types::particle_index    id,
                                     const dealii::ArrayView<const double> &properties)
    {
      // The triangulation has the set-up's geometry: the point goes where its lattice
      // coordinates lie there (the same block, the same coordinates in it).
      const auto               cell = grid->lattice().cell_of(x);
      const dealii::Point<dim> y    = grid_moves ? grid->to_initial_frame(x) : x;
      handler->insert_particle(y, grid->unit_block_point(x, cell), id, grid->cell_iterator(cell), properties);
    }



    template <int dim>
    void
    Solver<dim>::to_handler(const bool physical_locations)
    {
      using namespace dealii;
      using PI = PropertiesIndex<dim>;
      const auto        &P = particles;
      const unsigned int n = P.size();
      std::vector<unsigned int> store_index(n);
      for (unsigned int s = 0; s < n; ++s)
        store_index[P.handler_index[s]] = s;
      std::vector<unsigned int> group_of(n);
      for (unsigned int g = 0; g < P.groups.size(); ++g)
        for (unsigned int s = P.groups[g].begin; s < P.groups[g].end; ++s)
          group_of[s] = g;

      unsigned int k = 0;
      for (auto &particle : *handler)
        {
          const unsigned int s     = store_index[k++];
          const auto        &group = P.groups[group_of[s]];
          auto               q     = particle.get_properties();
          const double      *state = P.current.material_state.data() + group.state_offset +
                                std::size_t(s - group.begin) * group.n_state;
          q[PI::volume] = P.current.volume[s];
          for (unsigned int d = 0; d < dim; ++d)
            {
              q[PI::velocity + d]     = P.current.v[s][d];
              q[PI::displacement + d] = P.current.x[s][d] - P.x0[s][d];
              for (unsigned int e = 0; e < dim; ++e)
                q[PI::deformation_gradient + d * dim + e] = P.current.F[s][d][e];
            }
          for (unsigned int c = 0; c < PI::n_sym; ++c)
            {
              const auto ij         = SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
              q[PI::stress + c] = P.current.stress[s][ij];
              q[PI::strain + c] = P.current.strain[s][ij];
            }
          // von Mises stress with the out-of-plane component in 2D.
          double sigma_zz = 0;
          if (dim == 2 && group.material != nullptr)
            {
              double eps_zz = 0;
              group.material->out_of_plane(P.current.strain[s],
                                           P.current.stress[s],
                                           view(state, group.n_state),
                                           eps_zz,
                                           sigma_zz);
            }
          const SymmetricTensor<2, dim> &sigma = P.current.stress[s];
          const double                   tr    = dealii::trace(sigma) + sigma_zz;
          double dev2 = (sigma * sigma) + sigma_zz * sigma_zz - tr * tr / 3.0;
          q[PI::von_mises] = std::sqrt(std::max(0.0, 1.5 * dev2));
          std::fill(q.begin() + PI::n_fixed, q.end(), 0.0);
          std::copy(state, state + group.n_state, q.begin() + PI::n_fixed);
          particle.set_location(grid_moves && !physical_locations ? grid->to_initial_frame(P.current.x[s]) :
                                                                   P.current.x[s]);
        }
    }



    template <int dim>
    std::vector<std::string>
    PropertiesIndex<dim>::names(const std::vector<std::string> &state_names)
    {
      std::vector<std::string> n{"mass", "volume0", "volume", "thickness", "body", "load"};
      for (unsigned int d = 0; d < dim; ++d)
        n.emplace_back("velocity");
      for (unsigned int d = 0; d < dim; ++d)
        n.emplace_back("displacement");
      for (unsigned int c = 0; c < n_sym; ++c)
        {
          const auto ij = dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
          n.push_back(std::string("stress_") + component_suffix[ij[0]] + component_suffix[ij[1]]);
        }
      n.emplace_back("von_mises");
      for (unsigned int c = 0; c < n_sym; ++c)
        {
          const auto ij = dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
          n.push_back(std::string("strain_") + component_suffix[ij[0]] + component_suffix[ij[1]]);
        }
      for (unsigned int d = 0; d < dim; ++d)
        for (unsigned int e = 0; e < dim; ++e)
          n.push_back(std::string("F_") + component_suffix[d] + component_suffix[e]);
      n.insert(n.end(), state_names.begin(), state_names.end());
      return n;
    }



    template <int dim>
    std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation>
    PropertiesIndex<dim>::interpretations(const unsigned int n_state)
    {
      using namespace dealii::DataComponentInterpretation;
      std::vector<DataComponentInterpretation> i(n_fixed + n_state, component_is_scalar);
      for (unsigned int d = 0; d < dim; ++d)
        {
          i[velocity + d]     = component_is_part_of_vector;
          i[displacement + d] = component_is_part_of_vector;
        }
      return i;
    }



    template void Solver<2>::setup_grid();
    template void Solver<3>::setup_grid();
    template void Solver<2>::setup_groups();
    template void Solver<3>::setup_groups();
    template void Solver<2>::generate_particles();
    template void Solver<3>::generate_particles();
    template void Solver<2>::from_handler();
    template void Solver<3>::from_handler();
    template void Solver<2>::to_handler(bool);
    template void Solver<3>::to_handler(bool);
    template void Solver<2>::insert_into_handler(const dealii::Point<2> &,
                                                 dealii::types::particle_index,
                                                 const dealii::ArrayView<const double> &);
    template void Solver<3>::insert_into_handler(const dealii::Point<3> &,
                                                 dealii::types::particle_index,
                                                 const dealii::ArrayView<const double> &);
    template struct PropertiesIndex<2>;
    template struct PropertiesIndex<3>;
    template struct ParticleStore<2>;
    template struct ParticleStore<3>;
  } // namespace MPM
} // namespace hysteron
