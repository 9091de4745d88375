#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/particles/data_out.h>

#include <hysteron/base/energy_check.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include <hysteron/mpm/mpm.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>

namespace hysteron
{
  namespace MPM
  {
    namespace
    {
      template <int dim>
      dealii::Point<dim>
      parse_point(const std::string &text, const std::string &where)
      {
        return dealii::Point<dim>(parse_vector<dim>(text, where));
      }

      std::string
      format_point(const double *x, const unsigned int dim)
      {
        std::ostringstream s;
        s.precision(6);
        s << "(";
        for (unsigned int d = 0; d < dim; ++d)
          s << (d ? ", " : "") << x[d];
        s << ")";
        return s.str();
      }

      const char *const *const component_suffix = PointData::component_names;
    } // namespace



    template <int dim>
    Solver<dim>::Solver() = default;

    template <int dim>
    Solver<dim>::~Solver() = default;



    template <int dim>
    void
    Solver<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("MPM");
      {
        prm.enter_subsection("Grid");
        {
          prm.declare_entry("Lower corner",
                            "0, 0",
                            Patterns::Anything(),
                            "Lower corner of the background grid [m], 'x, y' or 'x, y, z'.");
          prm.declare_entry("Upper corner",
                            "1, 1",
                            Patterns::Anything(),
                            "Upper corner of the background grid [m]; rounded up to a whole "
                            "number of cells.");
          prm.declare_entry("Cell size",
                            "0.1",
                            Patterns::Double(),
                            "Edge length h of the square (cubic) grid cells [m], > 0.");
        }
        prm.leave_subsection();
        prm.declare_entry("Basis",
                          "cubic B-spline",
                          Patterns::Selection("linear|cubic B-spline"),
                          "Shape functions of the grid nodes: linear (2^dim nodes per point) or "
                          "cubic B-splines (4^dim nodes per point, C1: no grid-crossing error; "
                          "modified at the grid boundary so that partition of unity and linear "
                          "completeness hold; needs >= 3 cells per direction).");
        prm.declare_entry("Scheme",
                          "MUSL",
                          Patterns::Selection("MUSL|USL|USF"),
                          "When the stress is updated: MUSL (after the points, from remapped "
                          "nodal velocities; dissertation §4.2), USL (after, from the updated "
                          "nodal velocities) or USF (first, from the step's initial velocities).");
        prm.declare_entry("FLIP fraction",
                          "1",
                          Patterns::Double(),
                          "Blend of the point velocity update in [0, 1]: 1 is FLIP (v_p += "
                          "interpolated nodal velocity change; dissertation eq. 4.40), 0 is PIC "
                          "(v_p = interpolated nodal velocity, dissipative).");
        prm.declare_entry("Stress rate",
                          "small strain",
                          Patterns::Selection("small strain|Jaumann"),
                          "small strain: sigma += Delta sigma(d eps) (eq. 4.41); Jaumann: the "
                          "stress is also rotated with the spin, sigma += (W sigma - sigma W) dt "
                          "(objective; for large rotations). Internal tensors of the material "
                          "(back stress) are not rotated.");
        prm.declare_entry("Maximum CFL number",
                          "1",
                          Patterns::Double(),
                          "A fixed `Time/Time step` larger than this multiple of the critical "
                          "step h / max_p(c_p + |v_p|) (eq. 4.47) stops the run, > 0.");
        prm.declare_entry("Write particle table",
                          "false",
                          Patterns::Bool(),
                          "Write particles.csv at the end: one row per material point (id, body, "
                          "position, displacement, velocity, stress, von Mises stress, strain, "
                          "material state), sorted by id.");
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Solver<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      const Scene<dim> &scene = this->get_scene();
      {
        Section grid_section(prm, {"MPM", "Grid"});
        lower     = parse_point<dim>(grid_section.get("Lower corner"), grid_section.where("Lower corner"));
        upper     = parse_point<dim>(grid_section.get("Upper corner"), grid_section.where("Upper corner"));
        cell_size = grid_section.get_positive("Cell size");
        double n_total = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            require(upper[d] > lower[d],
                    grid_section.where("Upper corner"),
                    std::string("must be above the lower corner in ") + component_suffix[d]);
            const double n = std::ceil((upper[d] - lower[d]) / cell_size - 1e-9);
            require(n <= 1e6,
                    grid_section.where("Cell size"),
                    "gives " + std::to_string(static_cast<long>(n)) + " cells in one direction");
            n_cells[d] = std::max<unsigned int>(1, static_cast<unsigned int>(n));
            upper[d]   = lower[d] + n_cells[d] * cell_size;
            n_total *= n_cells[d];
          }
        require(n_total <= 2e8,
                grid_section.where("Cell size"),
                "the grid would have " + std::to_string(n_total) + " cells (at most 2e8)");
      }
      {
        Section s(prm, {"MPM"});
        basis_name = s.get("Basis");
        if (basis_name == "cubic B-spline")
          for (unsigned int d = 0; d < dim; ++d)
            require(n_cells[d] >= CubicBSpline1D::minimum_cells(),
                    "MPM/Grid/Cell size",
                    "the cubic B-spline basis needs at least " +
                      std::to_string(CubicBSpline1D::minimum_cells()) +
                      " cells per direction; the grid has " + std::to_string(n_cells[d]) +
                      " in " + component_suffix[d]);
        const std::string sc = s.get("Scheme");
        scheme = sc == "MUSL" ? Scheme::musl : sc == "USL" ? Scheme::usl : Scheme::usf;
        flip_fraction = s.get_non_negative("FLIP fraction");
        require(flip_fraction <= 1.0, s.where("FLIP fraction"), "must be in [0, 1] (got " + s.get("FLIP fraction") + ")");
        jaumann        = s.get("Stress rate") == "Jaumann";
        maximum_cfl    = s.get_positive("Maximum CFL number");
        particle_table = s.get_bool("Write particle table");
        probe_interval  = scene.output_control().probe_interval;
        average_regions = scene.output_control().average_regions;
      }

      // The scene's bodies must lie in the grid.
      const auto &bodies = scene.body_descriptions();
      require(!bodies.empty(), "Body names", "the mpm method needs at least one body");
      bool deformable = false;
      for (const auto &body : bodies)
        {
          deformable = deformable || !body.rigid;
          // A body whose bounding box leaves the grid is checked exactly: fill the
          // ring of cells just outside the grid; a point there means the grid
          // would cut the body (a quarter cylinder written as box - (all - cylinder)
          // has a larger bounding box but no point outside).
          const auto box = body.shape.bounding_box();
          for (unsigned int d = 0; d < dim; ++d)
            if (box.lower_bound(d) < lower[d] - 1e-12 * cell_size ||
                box.upper_bound(d) > upper[d] + 1e-12 * cell_size)
              {
                Geometry::FillLattice<dim> ring{lower, cell_size, n_cells};
                for (unsigned int e = 0; e < dim; ++e)
                  {
                    ring.origin[e] -= cell_size;
                    ring.n_cells[e] += 2;
                  }
                const auto outside = Geometry::fill<dim>(
                  body.shape, ring, body.particles_per_cell,
                  [&](const std::array<unsigned int, dim> &c) {
                    for (unsigned int e = 0; e < dim; ++e)
                      if (c[e] == 0 || c[e] == ring.n_cells[e] - 1)
                        return true;
                    return false;
                  });
                require(outside.empty(),
                        "Body " + body.name + "/Shape",
                        std::string("the body reaches outside the grid in ") + component_suffix[d] +
                          " (body from " + std::to_string(box.lower_bound(d)) + " to " +
                          std::to_string(box.upper_bound(d)) + ", grid from " +
                          std::to_string(lower[d]) + " to " + std::to_string(upper[d]) + ")");
              }
        }
      require(deformable, "Body names", "the mpm method needs at least one body that is not rigid");
    }



    template <int dim>
    void
    Solver<dim>::setup_grid()
    {
      const Scene<dim> &scene = this->get_scene();
      // Fill the bodies first (every rank, same order): the points per cell
      // weigh the cells when p4est partitions them, so that ranks get equal work.
      Lattice<dim> lattice;
      lattice.origin  = lower;
      lattice.h       = cell_size;
      lattice.n_cells = n_cells;
      const Geometry::FillLattice<dim> fill_lattice{lower, cell_size, n_cells};
      std::vector<unsigned int>        points_per_cell;
      if (dealii::Utilities::MPI::n_mpi_processes(scene.mpi_communicator()) > 1)
        points_per_cell.assign(std::accumulate(n_cells.begin(), n_cells.end(), 1u, std::multiplies<>()), 0);
      body_points.clear();
      for (const auto &body : scene.body_descriptions())
        {
          body_points.push_back(Geometry::fill(body.shape, fill_lattice, body.particles_per_cell));
          if (!points_per_cell.empty())
            for (const auto &x : body_points.back())
              {
                const auto         c  = lattice.cell_of(x);
                unsigned int       id = 0;
                for (int d = dim - 1; d >= 0; --d)
                  id = id * n_cells[d] + c[d];
                ++points_per_cell[id];
              }
        }
      grid = std::make_unique<BackgroundGrid<dim>>(scene.mpi_communicator());
      grid->initialize(lower, cell_size, n_cells, 1 + 2 * dim, points_per_cell);
      node_stamp.assign(grid->n_local_nodes(), 0);
      rigid_node_body.assign(grid->n_local_nodes(), 0);
      active_nodes.clear();
      rigid_nodes.clear();
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
      handler      = std::make_unique<Particles::ParticleHandler<dim>>(grid->triangulation(),
                                                                     mapping,
                                                                     n_properties);

      // Every rank generates all points in the same order (so the ids, load
      // counts and probe points agree) and keeps those in its own cells.
      const Lattice<dim> &lattice = grid->lattice();
      load_count.assign(loads.size() + 1, 0);
      std::vector<double>    properties(n_properties);
      types::particle_index  next_id = 0;
      std::vector<double>    best_distance(probes.size(), std::numeric_limits<double>::max());
      for (unsigned int b = 0; b < bodies.size(); ++b)
        {
          const auto &body   = bodies[b];
          const auto &points = body_points[b];
          require(!points.empty(),
                  "Body " + body.name + "/Shape",
                  "the body holds no material point (points sit at the centres of the " +
                    std::to_string(body.particles_per_cell) + "^" + std::to_string(dim) +
                    " sub-cells of each grid cell: refine the grid or raise `Particles per "
                    "cell`)");
          const auto  &group     = group_templates[group_of_body[b]];
          const double thickness = dim == 2 ? body.thickness : 1.0;
          const double volume    = std::pow(lattice.h / body.particles_per_cell, dim) * thickness;
          const double density =
            scene.material(body.material, "Body " + body.name + "/Material").density();
          for (const auto &x : points)
            {
              const types::particle_index id = next_id++;
              unsigned int                load = 0;
              if (!body.rigid)
                for (unsigned int l = 0; l < loads.size() && load == 0; ++l)
                  if (loads[l].region.contains(x, 1e-9 * lattice.h))
                    load = l + 1;
              ++load_count[load];
              for (unsigned int i = 0; i < probes.size(); ++i)
                if (!body.rigid)
                  {
                    const double distance = x.distance(probes[i].point);
                    if (distance < best_distance[i])
                      {
                        best_distance[i]            = distance;
                        probes[i].id                = id;
                        probes[i].initial_position = x;
                      }
                  }

              const auto         cell = lattice.cell_of(x);
              const unsigned int cid  = grid->cell_id(cell);
              if (!grid->owns_cell(cid))
                continue;
              std::fill(properties.begin(), properties.end(), 0.0);
              properties[PI::mass]      = density * volume;
              properties[PI::volume0]   = volume;
              properties[PI::volume]    = volume;
              properties[PI::thickness] = thickness;
              properties[PI::body]      = b;
              properties[PI::load]      = load;
              const Tensor<1, dim> v =
                body.rigid ? evaluate_in_time<dim>(*body.rigid_velocity, 0.0) : body.velocity_at(x);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  properties[PI::velocity + d]                       = v[d];
                  properties[PI::deformation_gradient + d * dim + d] = 1.0;
                }
              if (group.material != nullptr && group.n_state > 0)
                group.material->initialize_state(
                  view(properties.data() + PI::n_fixed, group.n_state));
              Point<dim> reference;
              for (unsigned int d = 0; d < dim; ++d)
                reference[d] = (x[d] - lattice.origin[d]) / lattice.h - cell[d];
              handler->insert_particle(x, reference, id, grid->cell_iterator(cid), make_array_view(properties));
            }
        }
      n_global_particles = next_id;
      body_points.clear();
      body_points.shrink_to_fit();
      handler->update_cached_numbers();
      for (unsigned int l = 1; l < load_count.size(); ++l)
        require(load_count[l] > 0,
                "Load " + loads[l - 1].name + "/Region",
                "the region contains no material point of a deformable body");
      load_per_point.assign(loads.size() + 1, Tensor<1, dim>());
      reactions.assign(scene.boundary_descriptions().size() + bodies.size(), Tensor<1, dim>());
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

      // First pass: the sort key of every point (handler order): group, cell, id.
      std::vector<types::particle_index> ids(n);
      std::vector<unsigned int>          key(n), cells(n);
      {
        unsigned int k = 0;
        for (const auto &particle : *handler)
          {
            ids[k]   = particle.get_id();
            key[k]   = group_of_body[static_cast<unsigned int>(particle.get_properties()[PI::body])];
            cells[k] = grid->cell_id(lattice.cell_of(particle.get_location()));
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
          const Point<dim>   x     = particle.get_location();
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
          // Load share: a total force is split evenly; a traction acts on the
          // point's face, of area V / l_p with l_p = (V / thickness)^(1/dim).
          P.load_factor[s] = 0;
          if (P.load[s] > 0)
            {
              if (loads[P.load[s] - 1].type == LoadDescription<dim>::Type::force)
                P.load_factor[s] = 1.0 / load_count[P.load[s]];
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
    Solver<dim>::to_handler()
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
          particle.set_location(P.current.x[s]);
        }
    }



    template <int dim>
    void
    Solver<dim>::setup_boundaries()
    {
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      const auto       &lattice = grid->lattice();
      boundaries.clear();
      for (const auto &description : scene.boundary_descriptions())
        {
          BoundaryNodes b;
          b.name       = description.name;
          b.type       = static_cast<unsigned int>(description.type);
          b.components = description.components;
          for (unsigned int n = 0; n < grid->n_local_nodes(); ++n)
            {
              if (!grid->is_relevant(n))
                continue;
              const auto i = grid->lattice_index(n);
              for (const unsigned int face : description.faces)
                {
                  const unsigned int d = face / 2;
                  if (i[d] == (face % 2 == 0 ? 0 : static_cast<int>(lattice.n_cells[d])))
                    {
                      b.nodes.push_back(n);
                      b.normal_direction.push_back(d);
                      b.normal_sign.push_back(face % 2 == 0 ? 1 : -1);
                    }
                }
              if (description.has_region &&
                  description.region.contains(grid->node_position(n), 1e-9 * lattice.h))
                {
                  b.nodes.push_back(n);
                  b.normal_direction.push_back(0);
                  b.normal_sign.push_back(0);
                }
            }
          const unsigned long n_nodes = dealii::Utilities::MPI::sum<unsigned long>(
            std::count_if(b.nodes.begin(), b.nodes.end(), [&](const unsigned int n) { return grid->is_owned(n); }),
            grid->mpi_communicator());
          require(n_nodes > 0 || description.type != Type::fixed || !description.has_region,
                  "Boundary " + description.name + "/Region",
                  "the region contains no grid node");
          boundaries.push_back(std::move(b));
        }
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
              v[b] = evaluate_in_time<dim>(*bodies[b].rigid_velocity, t);
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
    }



    template <int dim>
    double
    Solver<dim>::critical_time_step() const
    {
      const double speed = grid->is_parallel() ?
                             dealii::Utilities::MPI::max(max_speed, grid->mpi_communicator()) :
                             max_speed;
      return speed > 0 ? cell_size / speed : std::numeric_limits<double>::max();
    }



    template <int dim>
    void
    Solver<dim>::open_tables()
    {
      tables.open(this->get_scene(), this->output_directory(), PointData::columns<dim>(state_names));
    }



    template <int dim>
    std::vector<std::string>
    Solver<dim>::point_columns() const
    {
      return PointData::columns<dim>(state_names);
    }



    template <int dim>
    void
    Solver<dim>::point_values(const unsigned int s, double *r) const
    {
      const auto &P     = particles;
      const auto *group = &P.groups[0];
      for (const auto &g : P.groups)
        if (s >= g.begin && s < g.end)
          group = &g;
      const double *state = P.current.material_state.data() + group->state_offset +
                            std::size_t(s - group->begin) * group->n_state;
      PointData::values<dim>(P.current.x[s],
                             P.current.x[s] - P.x0[s],
                             P.current.v[s],
                             P.current.stress[s],
                             P.current.strain[s],
                             group->material,
                             view(state, group->n_state),
                             state_names.size(),
                             r);
    }



    template <int dim>
    void
    Solver<dim>::write_particle_table() const
    {
      const Scene<dim>  &scene   = this->get_scene();
      const auto         columns = point_columns();
      const unsigned int n       = columns.size() + 2;
      std::vector<double> rows(particles.size() * n);
      for (unsigned int s = 0; s < particles.size(); ++s)
        {
          rows[s * n]     = particles.id[s];
          rows[s * n + 1] = particles.body[s];
          point_values(s, rows.data() + s * n + 2);
        }
      std::vector<std::vector<double>> all{rows};
      if (grid->is_parallel())
        all = dealii::Utilities::MPI::gather(grid->mpi_communicator(), rows, 0);
      if (!scene.is_root())
        return;
      std::vector<std::vector<double>> table;
      for (const auto &part : all)
        for (std::size_t i = 0; i < part.size(); i += n)
          table.emplace_back(part.begin() + i, part.begin() + i + n);
      std::sort(table.begin(), table.end());
      std::vector<std::string> header{"id", "body"};
      header.insert(header.end(), columns.begin(), columns.end());
      Output::CsvWriter out(this->output_file("particles.csv"), header);
      for (const auto &row : table)
        out.add_row(row);
      out.commit();
    }



    template <int dim>
    void
    Solver<dim>::write_table_rows(const double t)
    {
      using namespace dealii;
      using PI                = PropertiesIndex<dim>;
      const Scene<dim> &scene = this->get_scene();
      const auto       &P     = particles;
      MPI_Comm          comm  = grid->mpi_communicator();

      // Probes: the owner fills its rows, the others contribute zeros.
      const unsigned int  n_values = tables.n_point_values();
      std::vector<double> rows(probes.size() * n_values, 0.0);
      for (unsigned int i = 0; i < probes.size(); ++i)
        if (probes[i].local >= 0)
          point_values(probes[i].local, rows.data() + i * n_values);

      // Mass-weighted averages over the points that started in each region.
      std::vector<double> averages(average_regions.size() * (1 + n_values), 0.0);
      std::vector<double> values(n_values);
      for (unsigned int i = 0; i < average_regions.size(); ++i)
        for (const auto &group : P.groups)
          if (group.material != nullptr)
            for (unsigned int s = group.begin; s < group.end; ++s)
              if (average_regions[i].contains(P.x0[s], 1e-9 * cell_size))
                {
                  double *a = averages.data() + i * (1 + n_values);
                  point_values(s, values.data());
                  a[0] += P.mass[s];
                  for (unsigned int c = 0; c < n_values; ++c)
                    a[1 + c] += P.mass[s] * values[c];
                }

      // Energies of this rank's points: kinetic and elastic strain energy.
      double kinetic = 0, strain_energy = 0;
      for (const auto &group : P.groups)
        for (unsigned int s = group.begin; s < group.end; ++s)
          {
            kinetic += 0.5 * P.mass[s] * P.current.v[s].norm_square();
            if (group.material != nullptr)
              strain_energy +=
                P.current.volume[s] *
                PointData::strain_energy_density(*group.material,
                                                 P.current.stress[s],
                                                 P.current.strain[s],
                                                 view(P.current.material_state.data() +
                                                        group.state_offset +
                                                        std::size_t(s - group.begin) * group.n_state,
                                                      group.n_state));
          }
      // Reactions in the columns of reactions.csv: boundaries, then rigid bodies.
      std::vector<Tensor<1, dim>> r(reactions.begin(), reactions.begin() + boundaries.size());
      const auto                 &bodies = scene.body_descriptions();
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          r.push_back(reactions[boundaries.size() + b]);
      tables.write(t, rows, averages, {{kinetic, strain_energy, internal_work, external_work, boundary_work}}, r, comm);
    }



    template <int dim>
    void
    Solver<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      to_handler();
      using PI = PropertiesIndex<dim>;
      std::vector<std::string> names = PI::names(state_names);
      names.resize(n_properties, "unused");
      auto interpretations = PI::interpretations(state_names.size());
      interpretations.resize(n_properties, dealii::DataComponentInterpretation::component_is_scalar);
      dealii::Particles::DataOut<dim> out;
      out.build_patches(*handler, names, interpretations);
      writer.write(out, t);
    }



    template <int dim>
    std::string
    Solver<dim>::describe_failure(const double t) const
    {
      std::string message;
      if (failed_point >= 0)
        {
          const unsigned int s = failed_point;
          double             x[3], x_new[3];
          for (unsigned int d = 0; d < dim; ++d)
            {
              x[d]     = particles.current.x[s][d];
              x_new[d] = particles.next.x[s][d];
            }
          std::ostringstream m;
          m.precision(6);
          m << "mpm: " << failure << " in the step from t = " << t << " s (step "
            << this->n_steps() + 1 << "): material point " << particles.id[s] << " of body '"
            << this->get_scene().body_descriptions()[particles.body[s]].name << "' at "
            << format_point(x, dim);
          if (failure == "a material point left the grid")
            m << " moved to " << format_point(x_new, dim) << " (grid from "
              << format_point(&lower[0], dim) << " to " << format_point(&upper[0], dim)
              << "; enlarge MPM/Grid or check the loads and boundary conditions)";
          if (step_dt > step_critical)
            m << "; the fixed time step " << step_dt << " s is " << step_dt / step_critical
              << " times the critical step " << step_critical
              << " s = h / max_p(c_p + |v_p|) (MPM/Maximum CFL number = " << maximum_cfl
              << "): the explicit scheme is probably unstable, use Time/Time step <= " << step_critical
              << " s";
          m << ".";
          message = m.str();
        }
      if (!grid->is_parallel())
        return message;
      for (const auto &m : dealii::Utilities::MPI::all_gather(grid->mpi_communicator(), message))
        if (!m.empty())
          return m;
      return "";
    }



    template <int dim>
    std::string
    Solver<dim>::check_energy(const double t, const double dt, const double critical) const
    {
      // Divergence (energy_diverged()) of the deformable points: an unstable step, too large
      // for the grid or with points in cells whose nodes carry little mass. One sum per
      // step, an MPI reduction only on several ranks.
      std::array<double, 4> sums{{kinetic_energy, internal_work, std::abs(external_work), boundary_work}};
      if (grid->is_parallel())
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums.data(), sums.size()),
                                    grid->mpi_communicator(),
                                    dealii::ArrayView<double>(sums.data(), sums.size()));
      const double input = initial_kinetic_energy + sums[2] + std::abs(sums[3]);
      if (!energy_diverged(sums[0] + sums[1], input))
        return "";
      std::ostringstream m;
      m << "mpm: the explicit scheme diverged in the step from t = " << t << " s (step "
        << this->n_steps() + 1 << ", time step " << dt << " s = " << dt / critical
        << " times the critical step h / max_p(c_p + |v_p|) = " << critical
        << " s): the kinetic energy plus the internal work " << sums[0] + sums[1]
        << " J is more than twice the energy put in (" << input
        << " J: initial kinetic energy, work of gravity, loads, boundaries and rigid bodies). "
        << "Reduce Time/CFL factor or Time/Time step; with the linear basis, points crossing "
        << "into cells whose nodes carry little mass also cause this (a finer point "
        << "spacing or the cubic B-spline basis helps).";
      return m.str();
    }



    template <int dim>
    void
    Solver<dim>::setup()
    {
      const Scene<dim> &scene = this->get_scene();
      setup_grid();
      probes.clear();
      for (const auto &p : scene.output_control().probe_points)
        {
          Probe probe;
          probe.point = p;
          probes.push_back(probe);
        }
      generate_particles();
      from_handler();
      setup_boundaries();
      // The smallest mass a node may have and still get a velocity.
      double m_min = std::numeric_limits<double>::max();
      for (const double m : particles.mass)
        m_min = std::min(m_min, m);
      m_min      = dealii::Utilities::MPI::min(m_min, scene.mpi_communicator());
      small_mass = 1e-12 * m_min;
      // The basis is chosen once: the step kernel is a template of it.
      step_kernel = basis_name == "linear" ? &Solver::template step<Linear1D> :
                                             &Solver::template step<CubicBSpline1D>;

      scene.console() << "mpm: " << n_global_particles << " material points, grid of ";
      for (unsigned int d = 0; d < dim; ++d)
        scene.console() << (d ? " x " : "") << n_cells[d];
      scene.console() << " cells (h = " << cell_size << " m), " << basis_name << " basis" << std::endl;
    }



    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      open_tables();
    }



    template <int dim>
    void
    Solver<dim>::initialize()
    {
      internal_work = external_work = boundary_work = 0;
      initial_kinetic_energy = 0;
      for (const auto &group : particles.groups)
        if (group.material != nullptr)
          for (unsigned int p = group.begin; p < group.end; ++p)
            initial_kinetic_energy += 0.5 * particles.mass[p] * particles.current.v[p].norm_square();
      if (grid->is_parallel())
        initial_kinetic_energy = dealii::Utilities::MPI::sum(initial_kinetic_energy, grid->mpi_communicator());
    }



    template <int dim>
    double
    Solver<dim>::propose_step(const double t)
    {
      const auto  &time     = this->get_scene().time_control();
      const double critical = critical_time_step();
      double       dt       = time.cfl_factor * critical;
      if (!time.automatic_time_step())
        {
          dt = time.time_step;
          if (dt > maximum_cfl * critical)
            {
              std::ostringstream m;
              m << "mpm: the time step " << dt << " s is above the critical step " << critical
                << " s = h / max_p(c_p + |v_p|) (eq. 4.47) times MPM/Maximum CFL number = "
                << maximum_cfl << " at t = " << t << " s (step " << this->n_steps() + 1
                << "): the explicit scheme would be unstable. Use Time/Time step <= "
                << maximum_cfl * critical << " or 0 (automatic).";
              throw Run::StepFailure(m.str());
            }
        }
      step_critical = critical;
      step_dt       = std::min(dt, time.end_time - t);
      return step_dt;
    }



    template <int dim>
    bool
    Solver<dim>::advance(double &t, const double dt)
    {
      // The work sums and reactions of the state t: a failed step leaves them so.
      const std::array<double, 3> work_at_t{{internal_work, external_work, boundary_work}};
      reactions_at_t = reactions; // a member: no allocation per step
      const auto fail_at_t = [&](const std::string &what) {
        internal_work = work_at_t[0];
        external_work = work_at_t[1];
        boundary_work = work_at_t[2];
        reactions     = reactions_at_t;
        throw Run::StepFailure(what);
      };
      (this->*step_kernel)(t, dt);
      bool failed = failed_point >= 0;
      if (grid->is_parallel())
        failed = dealii::Utilities::MPI::logical_or(failed, grid->mpi_communicator());
      if (failed)
        fail_at_t(describe_failure(t));
      if (const std::string diverged = check_energy(t, dt, step_critical); !diverged.empty())
        fail_at_t(diverged);
      particles.commit();
      t += dt;

      // Points that left this rank's cells go to their new owner; many cell
      // changes restore the cell order of the arrays (locality).
      // (sorting is collective: every rank decides the same)
      bool rebuild = left_subdomain || n_changed_cells > particles.size() / 4 + 16;
      if (grid->is_parallel())
        rebuild = dealii::Utilities::MPI::logical_or(rebuild, grid->mpi_communicator());
      if (rebuild)
        {
          dealii::TimerOutput::Scope timing(this->get_scene().timer(), "sort and migrate");
          to_handler();
          handler->sort_particles_into_subdomains_and_cells();
          from_handler();
          ++n_rebuilds;
        }
      return true;
    }



    template <int dim>
    void
    Solver<dim>::finish(const double)
    {
      if (particle_table)
        write_particle_table();
    }



    template <int dim>
    std::string
    Solver<dim>::summary() const
    {
      return std::to_string(this->n_steps()) + " steps, " + std::to_string(n_global_particles) +
             " material points, " + std::to_string(this->n_outputs()) + " outputs";
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



    template struct PropertiesIndex<2>;
    template struct PropertiesIndex<3>;
    template struct ParticleStore<2>;
    template struct ParticleStore<3>;
    template class Solver<2>;
    template class Solver<3>;
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::MPM::Solver,
                         "mpm",
                         "the explicit Material Point Method (dissertation ch. 4): bodies of "
                         "material points on a Cartesian background grid (subsection MPM), "
                         "Body/Boundary/Load subsections, probes, energies and particle VTU output");
