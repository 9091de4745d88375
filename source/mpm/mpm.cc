// The MPM's parameters, set-up and the driver's hooks (Run::SteppingMethod): the glue
// between the driver and the pieces in particles.cc, conditions.cc, output.cc and step.h.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/energy_check.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/memory.h>
#include <hysteron/base/parameters.h>
#include "mpm/mpm.h"

#include <algorithm>
#include <cmath>
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

      /**
       * Refuse a run whose material points and grid cannot fit into the memory of the
       * ranks, before the points are made. The points: k^dim per cell of volume h^dim of
       * each body inside the grid (k = Particles per cell). The resident bytes per point
       * (ParticleHandler, point arrays, material states, the nodes they reach) and per grid
       * cell (p4est, the node arrays' untouched zero pages) are the slopes of the peak RSS
       * of one-step runs of 3 sizes, rounded up: 580 B per point in 2D (4e4 ... 6.4e5
       * points), 880 B in 3D (3.3e4 ... 2.6e5), 3 B per grid cell (a 0.1 m cube in grids of
       * 50^3 ... 100^3 cells), measured by
       *   benchmarks/memory_estimate.py --hysteron build/hysteron --only mpm
       * (each run /usr/bin/time -v hysteron scene.prm, "Maximum resident set size").
       */
      template <int dim>
      void
      check_memory(const Scene<dim>                   &scene,
                   const dealii::Point<dim>           &lower,
                   const dealii::Point<dim>           &upper,
                   const double                        cell_size,
                   const std::array<unsigned int, dim> &n_cells)
      {
        constexpr double bytes_per_point[2] = {600, 900};
        constexpr double bytes_per_cell[2]  = {16, 16};
        double           points             = 0;
        for (const auto &body : scene.body_descriptions())
          {
            const auto box     = body.shape.bounding_box();
            double     in_grid = 1; // the volume of the body's box inside the grid
            for (unsigned int d = 0; d < dim; ++d)
              in_grid *= std::max(0.0, std::min(box.upper_bound(d), upper[d]) - std::max(box.lower_bound(d), lower[d]));
            const double volume = body.shape.volume_estimate(); // infinite for an unbounded shape
            points += std::min(volume, in_grid) / std::pow(cell_size, dim) * std::pow(body.particles_per_cell, dim);
          }
        double cells = 1;
        for (unsigned int d = 0; d < dim; ++d)
          cells *= n_cells[d];
        const MPI_Comm     comm    = scene.mpi_communicator();
        const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
        const double       bytes   = Memory::largest_share(points, n_ranks, dim) * bytes_per_point[dim - 2] +
                                 Memory::largest_share(cells, n_ranks, dim) * bytes_per_cell[dim - 2];
        std::ostringstream what;
        what.precision(3);
        what << "about " << Memory::count(points) << " material points (" << bytes_per_point[dim - 2]
             << " B each) and " << Memory::count(cells) << " grid cells (" << bytes_per_cell[dim - 2] << " B each)";
        Memory::require_fits(comm, bytes, "MPM/Grid/Cell size", what.str(),
                             "use a coarser MPM/Grid/Cell size, fewer Particles per cell, smaller bodies or more "
                             "machines");
      }
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
          prm.declare_entry("Cell weight",
                            "0.01",
                            Patterns::Double(),
                            "The work of one grid cell, counted in material points [-], >= 0, "
                            "when the grid is split between MPI ranks: each rank gets an equal "
                            "share of (material points + Cell weight x grid cells). A cell without "
                            "points costs nothing in a step and little memory (a few bytes per "
                            "node), a point about 1 kB and the work of a step: the default "
                            "balances the points, and splits a grid's empty regions too.");
          declare_grid_motion_parameters(prm);
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
                          Patterns::Selection(SchemeRegistry<3>::pattern_string()),
                          "The update scheme: the order of the phases of a step, i.e. when and "
                          "from which nodal velocities the stress is updated. Registered:" +
                            SchemeRegistry<3>::documentation());
        SchemeRegistry<3>::declare_parameters(prm);
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
                          "(objective; for large rotations); the material's tensor state (plastic "
                          "strain, back stress) turns with it. The FEM's counterpart is "
                          "FEM/Kinematics = updated Lagrangian.");
        prm.declare_entry("Maximum CFL number",
                          "1",
                          Patterns::Double(),
                          "A fixed `Time/Time step` larger than this multiple of the critical "
                          "step h / max_p(c_p + |v_p|) (eq. 4.47) stops the run, > 0.");
        declare_damping_parameters(prm);
        prm.enter_subsection("Contact");
        {
          prm.declare_entry("Enable",
                            "false",
                            Patterns::Bool(),
                            "Contact between bodies on the grid (doc/mpm.md, 'Contact between "
                            "bodies'): each body has its own nodal velocities where the nodal "
                            "masses of two or more bodies overlap; bodies there do not "
                            "interpenetrate, may separate and slide with Coulomb friction, and "
                            "rigid bodies act on the material through contact (their reaction "
                            "in reactions.csv) instead of prescribing the velocity of every grid "
                            "node they touch. false: one velocity field for all bodies (bodies "
                            "that meet move together, rigid bodies prescribe their nodes).");
          prm.declare_entry("Friction coefficient",
                            "0",
                            Patterns::Double(),
                            "Coulomb friction coefficient mu >= 0 [-] of every pair of bodies in "
                            "contact (0: frictionless), unless `Pair friction coefficients` "
                            "gives the pair its own.");
          prm.declare_entry("Pair friction coefficients",
                            "",
                            Patterns::Anything(),
                            "Friction coefficients [-] of particular pairs of bodies, "
                            "'body, body: mu' separated by ';' (e.g. 'block, plate: 0.3; "
                            "disk1, disk2: 0'); the other pairs take `Friction coefficient`.");
        }
        prm.leave_subsection();
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
        cell_weight = grid_section.get_non_negative("Cell weight");
        double n_total = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            require(upper[d] > lower[d],
                    grid_section.where("Upper corner"),
                    std::string("must be above the lower corner in ") + component_suffix[d]);
            require(cell_size <= (upper[d] - lower[d]) * (1 + 1e-9),
                    grid_section.where("Cell size"),
                    "is larger than the grid (" + grid_section.get("Cell size") + " m; the grid is " +
                      std::to_string(upper[d] - lower[d]) + " m wide in " + component_suffix[d] + ")");
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
        parse_grid_motion(prm);
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
        update_scheme = SchemeRegistry<dim>::create(s.get("Scheme"), s.where("Scheme"));
        flip_fraction = s.get_non_negative("FLIP fraction");
        require(flip_fraction <= 1.0, s.where("FLIP fraction"), "must be in [0, 1] (got " + s.get("FLIP fraction") + ")");
        jaumann        = s.get("Stress rate") == "Jaumann";
        maximum_cfl    = s.get_positive("Maximum CFL number");
        particle_table = s.get_bool("Write particle table");
        probe_interval  = scene.output_control().probe_interval;
        average_regions = scene.output_control().average_regions;
      }

      parse_contact(prm);
      parse_damping(prm);

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
                // The ring is 2 dim slabs one cell thick (the work follows the surface).
                bool outside = false;
                for (unsigned int e = 0; e < dim && !outside; ++e)
                  for (const unsigned int side : {0u, ring.n_cells[e] - 1})
                    {
                      std::array<unsigned int, dim> first{}, last;
                      for (unsigned int f = 0; f < dim; ++f)
                        last[f] = ring.n_cells[f] - 1;
                      first[e] = last[e] = side;
                      outside  = outside ||
                                !Geometry::fill<dim>(body.shape, ring, body.particles_per_cell, first, last)
                                   .empty();
                    }
                require(!outside,
                        "Body " + body.name + "/Shape",
                        std::string("the body reaches outside the grid in ") + component_suffix[d] +
                          " (body from " + std::to_string(box.lower_bound(d)) + " to " +
                          std::to_string(box.upper_bound(d)) + ", grid from " +
                          std::to_string(lower[d]) + " to " + std::to_string(upper[d]) + ")");
              }
        }
      require(deformable, "Body names", "the mpm method needs at least one body that is not rigid");
      scene.refuse_fem_only_sets("mpm");

      axisymmetric = scene.axisymmetric();
      if (axisymmetric)
        {
          // A uniform ground motion across the axis (x = r) has no axisymmetric part.
          require(scene.ground_motion().empty() || scene.ground_motion().direction()[0] == 0,
                  "Ground motion/Direction",
                  "has a radial (x) component in an axisymmetric scene: the ground of an "
                  "axisymmetric body can move along its axis only (Direction = 0, 1)");
          // x is the radius: the grid may not reach r < 0, and a grid that reaches the
          // axis needs v_r = 0 there (else the hoop strain v_r / r is unbounded).
          require(lower[0] >= 0,
                  "MPM/Grid/Lower corner",
                  "x is the radius r in an axisymmetric scene, so the grid must start at "
                  "r >= 0 (it starts at x = " + std::to_string(lower[0]) + ")");
          if (lower[0] == 0)
            {
              dealii::Point<dim> on_axis = lower;
              on_axis[1]                 = 0.5 * (lower[1] + upper[1]);
              bool held                  = false;
              for (const auto &b : scene.boundary_descriptions())
                held = held || b.prescribes(on_axis, 0, lower, upper, 1e-9 * cell_size);
              require(held,
                      "Boundary names",
                      "the axisymmetric grid reaches the axis (MPM/Grid/Lower corner x = 0) "
                      "but no boundary condition holds the radial velocity there: add a "
                      "Boundary with Type = roller and Faces = x- (v_r = 0 on the axis)");
            }
        }
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
          const auto &lattice = grid->lattice();
          const auto  top     = lattice.upper();
          if (failure == "a material point left the grid")
            m << " moved to " << format_point(x_new, dim) << " (grid from "
              << format_point(&lattice.origin[0], dim) << " to " << format_point(&top[0], dim)
              << "; enlarge MPM/Grid or check the loads and boundary conditions)";
          else if (failure == "a material point left the moving grid")
            m << " moved to " << format_point(x_new, dim) << ", outside the grid as it moved in the step (to "
              << grid_extent(last_moved_lattice) << "; "
              << (grid_motion == GridMotion::follow ?
                    "the grid follows the affine part of the followed bodies' motion, which a body "
                    "that is not followed, or one that deforms far from affinely (an impact), can "
                    "leave: enlarge MPM/Grid, follow only the translation (MPM/Grid/Motion/Stretch "
                    "= false) or keep the grid fixed)" :
                    "enlarge MPM/Grid or change MPM/Grid/Motion/Velocity and Stretch rate)");
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
      probes.clear();
      for (const auto &p : scene.output_control().probe_points)
        {
          Probe probe;
          probe.point = p;
          probes.push_back(probe);
        }
      load_per_point.assign(scene.load_descriptions().size() + 1, dealii::Tensor<1, dim>());
      probe_acceleration.assign(scene.ground_motion().empty() ? 0 : probes.size(), dealii::Tensor<1, dim>());
      reactions.assign(scene.boundary_descriptions().size() + scene.body_descriptions().size(),
                       dealii::Tensor<1, dim>());
      // The grid and the points: new, or from the checkpoint of --resume (the points go
      // into the arrays in load(), once the grid is where it was). The memory is checked
      // either way: a resume on fewer ranks gives each rank more of the points.
      check_memory<dim>(scene, lower, upper, cell_size, n_cells);
      if (this->resuming())
        setup_from_checkpoint();
      else
        {
          setup_grid();
          generate_particles();
          from_handler();
        }
      setup_boundaries();
      setup_grid_motion();
      setup_absorbing();
      // The smallest mass a node may have and still get a velocity.
      double m_min = std::numeric_limits<double>::max();
      for (const double m : particles.mass)
        m_min = std::min(m_min, m);
      m_min      = dealii::Utilities::MPI::min(m_min, scene.mpi_communicator());
      small_mass = 1e-12 * m_min;
      // The basis and contact are chosen once: the phase kernels are templates of them.
      if ((nodal_damping.active() || !dashpots.empty()) && !contact)
        mark_boundary_nodes();
      if (contact)
        {
          setup_contact();
          phases = basis_name == "linear" ? make_step_phases<dim, Linear1D, true>(*this) :
                                            make_step_phases<dim, CubicBSpline1D, true>(*this);
        }
      else
        phases = basis_name == "linear" ? make_step_phases<dim, Linear1D, false>(*this) :
                                          make_step_phases<dim, CubicBSpline1D, false>(*this);

      scene.console() << "mpm: " << n_global_particles << " material points, grid of ";
      for (unsigned int d = 0; d < dim; ++d)
        scene.console() << (d ? " x " : "") << n_cells[d];
      scene.console() << " cells (h = " << cell_size << " m), " << basis_name << " basis"
                      << (contact ? ", contact between bodies" : "")
                      << (damped() ? ", damping (MPM/Damping)" : "")
                      << (grid_motion == GridMotion::follow ?
                            ", the grid follows the bodies" :
                            grid_motion == GridMotion::prescribed ? ", the grid moves as prescribed" : "")
                      << std::endl;
    }



    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      open_tables();
      if (grid_moves && this->get_scene().is_root())
        {
          std::vector<std::string> columns{"time"};
          for (unsigned int d = 0; d < dim; ++d)
            columns.push_back(std::string("lower_") + component_suffix[d]);
          for (unsigned int d = 0; d < dim; ++d)
            columns.push_back(std::string("h_") + component_suffix[d]);
          grid_table =
            std::make_unique<Output::TimeTable>(this->output_file("grid.csv"), columns, this->run_record());
        }
    }



    template <int dim>
    void
    Solver<dim>::initialize()
    {
      internal_work = external_work = boundary_work = damping_work = 0;
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
                << " s = h / max_p(c_p + |v_p|) (eq. 4.47"
                << (stiffness_damping > 0 ? ", times sqrt(1 + xi^2) - xi for MPM/Damping/Rayleigh stiffness "
                                            "coefficient, xi = a1 max_p(c_p + |v_p|) / h" :
                                            "")
                << ") times MPM/Maximum CFL number = " << maximum_cfl << " at t = " << t << " s (step " << this->n_steps() + 1
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
      const std::array<double, 4> work_at_t{{internal_work, external_work, boundary_work, damping_work}};
      reactions_at_t = reactions; // a member: no allocation per step
      const auto fail_at_t = [&](const std::string &what) {
        internal_work = work_at_t[0];
        external_work = work_at_t[1];
        boundary_work = work_at_t[2];
        damping_work  = work_at_t[3];
        reactions     = reactions_at_t;
        throw Run::StepFailure(what);
      };
      begin_step(t);
      step_dt = dt; // the step's dt (the viscous work, the failure message)
      update_scheme->step(*phases, t, dt);
      // A moving grid: where it is after the step (collective, so before any decision).
      Lattice<dim> moved;
      if (grid_moves)
        if (const std::string refused = moved_lattice(t, dt, moved); !refused.empty())
          fail_at_t(refused);
      bool failed = failed_point >= 0;
      if (grid->is_parallel())
        failed = dealii::Utilities::MPI::logical_or(failed, grid->mpi_communicator());
      if (failed)
        fail_at_t(describe_failure(t));
      if (const std::string diverged = check_energy(t, dt, step_critical); !diverged.empty())
        fail_at_t(diverged);
      if (!probe_acceleration.empty())
        record_probe_accelerations(dt);
      particles.commit();
      t += dt;
      if (grid_moves)
        move_grid(moved);

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
      warn_about_idle_boundaries();
    }



    template <int dim>
    std::string
    Solver<dim>::summary() const
    {
      return std::to_string(this->n_steps()) + " steps, " + std::to_string(n_global_particles) +
             " material points, " + std::to_string(this->n_outputs()) + " outputs";
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::MPM::Solver,
                         "mpm",
                         "the explicit Material Point Method (dissertation ch. 4): bodies of "
                         "material points on a Cartesian background grid (subsection MPM), "
                         "Body/Boundary/Load subsections, probes, energies and particle VTU output");
