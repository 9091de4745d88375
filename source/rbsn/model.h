#ifndef hysteron_rbsn_model_h
#define hysteron_rbsn_model_h

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <hysteron/base/checkpoint.h>
#include <hysteron/base/implicit_dynamics.h>
#include <hysteron/base/newton.h>
#include <hysteron/base/output.h>
#include <hysteron/rbsn/spring_law.h>
#include <hysteron/rbsn/springs.h>
#include <hysteron/run/stepping_method.h>
#include "rbsn/tessellation.h"
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>
#include <hysteron/scene/tables.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  class SparseLU;

  namespace RBSN
  {
    namespace Blocks
    {
      template <int dim>
      class Layout;
      template <int dim>
      class Nuclei;
    } // namespace Blocks

    /**
     * The Rigid-Body-Spring Network, the method `rbsn` (`set Method = rbsn`,
     * dissertation chapter 3; doc/rbsn.md, doc/rbsn3d.md): the scene's bodies are cut
     * into Voronoi cells around seeded random points; every cell is a rigid body with
     * the DoFs of its nucleus (2D: u, v, theta; 3D: u_x, u_y, u_z, theta_x, theta_y,
     * theta_z), and every common facet of two cells carries zero-length springs (2D:
     * normal, tangential, rotational; 3D: normal, two shear, two bending, torsion) with
     * the Voronoi scaled stiffnesses of eq. 3.9 and the spring law of `RBSN/Spring law`
     * (eq. 3.32-3.42). Static, quasi-static (Newton) and dynamic (Newmark / HHT with
     * Newton, or SUNDIALS' variable-order IDA) analyses, and brittle fracture of the
     * facets (Mohr-Coulomb with a tension cut-off, eq. 3.49-3.51). The driver
     * (Run::SteppingMethod) calls the hooks; each is defined in the file of its job.
     *
     * Under MPI the network is distributed. A large network is sampled block by block
     * (blocks.cc), each rank holding the nuclei of its blocks and of those around its
     * cells; a small one (one block) is sampled by every rank. The cells have global
     * numbers, the same on any number of ranks (block by block); each rank owns a
     * consecutive share of them along the blocks' Hilbert order (a block two ranks share
     * split by coordinate bisection), builds the Voronoi cells of its own nuclei from
     * them and a halo of the nuclei around them, and owns the facets whose first cell
     * (the lower number) is its own. The DoF vectors are distributed vectors with the
     * neighbouring ("ghost") cells of other ranks, the tangent is a Trilinos matrix of
     * the owned rows. The cells of a rank are numbered 0, 1, ...: its own first (in the
     * order of their global numbers), then its ghost cells (in the order of their
     * DoFs). The facets of owned cell c (those whose lower cell it is) are the local
     * facets [owned_facet_start[c], owned_facet_start[c + 1]), in the order of their
     * upper cells.
     */
    template <int dim>
    class Model : public Run::SteppingMethod<dim>
    {
    public:
      /// DoFs per cell: 3 (u, v, theta) in 2D, 6 (translations, rotations) in 3D.
      static constexpr unsigned int n_dofs = n_springs<dim>;

      Model();
      ~Model() override;

      static void
      declare_parameters(dealii::ParameterHandler &prm);

      /// The network, springs, system and conditions; writes no file.
      void
      setup() override;
      /// Why this analysis cannot be checkpointed ("" if it can).
      std::string
      checkpoint_unsupported() const override;
      /// The run's summary (the factorizations of a resumed run are this process's).
      std::string
      summary() const override;

      /// Base excitation (`Ground motion`) in the dynamic analyses, Newmark / HHT and
      /// variable order; the static and quasi-static ones refuse a record (parameters.cc).
      bool
      takes_ground_motion() const override
      {
        return true;
      }

      /// The values of the system matrix (this rank's rows), in the pattern's order.
      std::vector<double>
      matrix_values() const;
      void
      set_matrix_values(const std::vector<double> &values);

      /// A network predicted to have at most this many points (the integral of
      /// Spacing::predicted_points) is one sampling block, unless `Sampling block size`
      /// is given: every rank samples it, as before the tiling (doc/rbsn.md).
      static constexpr double single_block_points = dim == 2 ? 2e4 : 1e4;

    protected:
      // The driver's hooks (Run::SteppingMethod).
      /// Parse `subsection RBSN` and refuse bodies the network cannot hold (parameters.cc).
      void
      parse_parameters(dealii::ParameterHandler &prm) override;
      std::string
      label() const override
      {
        return "rbsn";
      }
      std::string
      field_name() const override
      {
        return "rbsn";
      }
      /// u and theta per cell.
      double
      size_of_state() const override
      {
        return double(n_dofs) * n_cells;
      }
      /// The tables (newton.csv or ida.csv, fracture.csv and the point tables).
      void
      open_outputs() override;
      /// Forces at t = 0, and the initial acceleration in dynamics.
      void
      initialize() override;
      double
      propose_step(double t) override;
      /// One increment with its fracture cycles (or, with variable order, the whole
      /// integration, calling step_finished() at each output time).
      bool
      advance(double &t, double dt) override;
      void
      write_rows(double t) override;
      void
      write_fields(double t, Output::FieldWriter &writer) override;
      /// springs.csv and cells.csv when asked for, the history plots.
      void
      finish(double t) override;
      /// The network's state as records keyed by cell (any number of ranks resumes
      /// it), the global state in @p global, this rank's assembled tangent in @p rank.
      void
      save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const override;
      void
      load(CheckpointReader              &global,
           std::vector<CheckpointReader> &rank_parts,
           const CheckpointDirectory     &directory) override;

    private:
      using Vector       = dealii::LinearAlgebra::distributed::Vector<double>;

      const Scene<dim> &
      scene() const
      {
        return this->get_scene();
      }

      /// The state the same on every rank (step control, counters, works, tables).
      template <class Archive>
      void
      serialize_global(Archive &ar);

      /// Owned cell @p c in a checkpoint: its DoF values and the springs of its facets.
      template <class Archive>
      void
      serialize_cell(Archive &ar, unsigned int c);

      /// This rank's incrementally assembled tangent (read back on as many ranks only).
      template <class Archive>
      void
      serialize_tangent(Archive &ar);

      using SpringVector = typename SpringLaw<dim>::Vector;
      using SpringMatrix = typename SpringLaw<dim>::Matrix;
      using dof_index    = dealii::types::global_dof_index;

      /// A kinematic condition on cell DoFs (a scene boundary or a rigid body).
      struct Dirichlet
      {
        std::string               name;
        int                       boundary = -1, rigid = -1;
        std::vector<unsigned int> dofs; ///< local DoFs: n_dofs local cell + component
      };

      /// A load on cells: a force and moment per cell, times the load's value.
      struct LoadSet
      {
        unsigned int                          load = 0;
        std::vector<unsigned int>             cells;  ///< owned local cells
        std::vector<dealii::Tensor<1, dim>>   arm;    ///< moment arm of each contribution (traction)
        std::vector<double>                   weight; ///< force = weight value(t)
      };

      // Set-up.
      /// The nuclei, their partition over the ranks, and this rank's cells, ghost cells
      /// and facets with their mass properties (network.cc).
      void
      build_network();
      /// The user's and the boundary points, merged (every rank).
      std::vector<dealii::Point<dim>>
      fixed_points() const;
      /// The side of the sampling blocks: `Sampling block size`, or from the predicted
      /// points (0: one block).
      double
      sampling_block_side() const;
      /// The nuclei of a network of one block: the @p fixed points and every body's
      /// random points in turn.
      std::vector<dealii::Point<dim>>
      sample_one_block(const std::vector<dealii::Point<dim>> &fixed) const;
      /// The random points of a tiled network, block by block (collective).
      void
      sample_blocks(const std::vector<dealii::Point<dim>> &fixed,
                    const Blocks::Layout<dim>             &layout,
                    Blocks::Nuclei<dim>                   &nuclei) const;
      /// The whole network on this rank, from every nucleus (@p all).
      void
      build_whole_tessellation(const std::vector<dealii::Point<dim>> &all);
      /// This rank's part of the tessellation: its cells (a share of the cells of
      /// @p nuclei), their ghost cells and facets, from a halo of nuclei around them.
      void
      build_local_tessellation(Blocks::Nuclei<dim> &nuclei);
      /// owned_facet_start from the facets (sorted by their cells).
      void
      number_owned_facets();
      /// The box of the nuclei, the cells' bodies and the owned cells' mass properties.
      void
      setup_cells();
      /// Refuse bodies the network cannot hold; the shapes of the others (parse_parameters()).
      void
      check_bodies();
      /// The springs of the owned facets: stiffnesses, B and the spring law (springs.cc).
      void
      setup_springs();
      /// The stiffnesses and B of facet @p f between the cells of bodies @p ba and @p bb
      /// (materials @p ma, @p mb) into @p sp and the spring law's @p facet.
      void
      spring_geometry(const Facet<dim>               &f,
                      const BodyDescription<dim>     &ba,
                      const BodyDescription<dim>     &bb,
                      const Material::Interface<dim> &ma,
                      const Material::Interface<dim> &mb,
                      Springs<dim>                   &sp,
                      FacetSprings<dim>              &facet) const;
      /// The sparsity pattern and the solvers (linear_system.cc).
      void
      setup_system();
      /// History sets, Dirichlet sets and loads (conditions.cc).
      void
      setup_conditions();
      void
      setup_history_sets();
      /// The DoFs of every boundary condition and rigid body (a DoF belongs to the first).
      void
      setup_dirichlet();
      void
      setup_loads();
      /// How close a nucleus must be to a face or region to be selected.
      double
      selection_tolerance() const
      {
        return 1e-9 * scale;
      }
      /// @p n summed over the network's ranks.
      unsigned long
      global_count(const std::size_t n) const
      {
        return dealii::Utilities::MPI::sum<unsigned long>(n, network_communicator());
      }
      /// Static analyses: refuse a network part whose rigid-body motions are free (supports.cc).
      void
      check_supports() const;
      /// The connected parts of the network over all its facets, or over the intact ones
      /// with @p intact_only: the part of every local cell into @p part (parts numbered in
      /// the order of their lowest global cell number, the same on any number of ranks),
      /// their number of cells into @p sizes, and for each part the rigid-body motions its
      /// supports leave free (empty: held).
      std::vector<std::vector<std::string>>
      network_parts(bool intact_only, std::vector<unsigned int> &part, std::vector<unsigned long> &sizes) const;

      /// What a break did to the network (fracture.csv, console).
      struct Separation
      {
        unsigned long          cells    = 0; ///< of the smaller fragment it cut off (0: none)
        unsigned long          released = 0; ///< cells it released from the static system
        dealii::Point<dim>     centroid, released_centroid;
        dealii::Tensor<1, dim> load; ///< the external force on the released cells [N]
      };
      /// The fragments over the intact facets, and (static analyses) the cells of the
      /// fragments that nothing holds: released, their DoFs keep their values.
      void
      update_fragments();
      /// What the break of the facet between the global cells @p a and @p b did, after
      /// update_fragments(), given the released cells before it (every rank).
      Separation
      separation(unsigned int a, unsigned int b, const std::vector<bool> &released_before) const;
      /// The area (2D) or volume (3D) of owned cell @p c.
      double
      cell_measure(const unsigned int c) const
      {
        if constexpr (dim == 2)
          return network.cells[c].area;
        else
          return network.cells[c].volume;
      }

      // Steps.
      void
      make_constraints(const double t0, const double t1, const bool predictor);
      /// The residual (and with @p matrix the tangent) at u_trial, time t1, step dt. The
      /// tangent is built from scratch, or (matrix_current) updated by the facets whose
      /// tangent changed since it was assembled (assembly.cc).
      bool
      assemble(const double t1, const double dt, const bool matrix, const bool update_springs);
      /// One evaluation of assemble() (assembly.h).
      class Assembly;
      /// The right-hand side of a local matrix and vector as
      /// distribute_local_to_global(K, r, dofs, matrix, rhs, true) makes it, without the matrix.
      void
      add_local_rhs(const dealii::FullMatrix<double> &K, const dealii::Vector<double> &r, const std::vector<dof_index> &dofs);
      /// Add the local matrix @p K to the free rows and columns of the system matrix.
      void
      add_local_change(dealii::FullMatrix<double> &K, const std::vector<dof_index> &dofs);
      bool
      solve_step(const double t, const double dt);
      /// One attempt of solve_step(): predictor and Newton iterations.
      bool
      newton_step(const double t, const double dt);
      /// Accept the trial state of a step of @p dt (in which facets @p broke).
      void
      commit(const double dt, const bool broke);
      /// Whether the dynamics have Rayleigh damping (energy.csv then has damping_work).
      bool
      damped() const
      {
        return dynamic() && (dynamics.rayleigh_mass > 0 || dynamics.rayleigh_stiffness > 0);
      }
      /// The facets' deformation increments B (u_trial - u) of a step, before commit()
      /// takes them (a damped analysis; broken facets 0).
      std::vector<double>
      deformation_increments() const;
      /// This rank's work of the damping forces over a step, the trapezoidal rule
      /// 1/2 du^T C (v0 + v1) with the step's deformation increments @p d_delta.
      double
      step_damping_work(const Vector &v0, const std::vector<double> &d_delta) const;
      /// x = K^-1 rhs (the owned entries; the caller distributes the constraints).
      void
      solve_linear(Vector &x);
      /// Whether the factors (or the AMG hierarchy) must be rebuilt for the current matrix:
      /// the one refactorization policy of every solver (the caller then rebuilds them).
      bool
      renew_factors();
      /// The error of a singular tangent (every solver's).
      static RuntimeError
      singular_tangent();

      // MPI (parallel.cc).
      /// More than one part: the network is distributed over the ranks.
      bool
      distributed() const
      {
        return n_parts > 1;
      }
      /// The system is a Trilinos matrix (several ranks, or an iterative solver).
      bool
      trilinos_system() const
      {
        return distributed() || linear_solver != "direct";
      }
      /// The communicator of the network's sums: the scene's when distributed, else
      /// this rank alone (a replicated network).
      MPI_Comm
      network_communicator() const;
      /// The DoF partition (owned and ghost DoFs), the vectors and the sparsity of the
      /// Trilinos matrix.
      void
      setup_parallel_system();
      /// solve_linear() on the distributed matrix.
      void
      solve_distributed(Vector &x);
      /// solve_distributed() with cg / gmres and ML: the preconditioner is rebuilt when
      /// @p renew (renew_factors()).
      void
      solve_iterative(Vector &x, bool renew);
      /// solve_distributed() with `Distributed direct solver = UMFPACK`: the matrix and the
      /// right-hand side gathered on rank 0 and solved there (SparseLU), the solution sent back.
      void
      solve_gathered(Vector &x, bool renew);
      /// Add a local matrix and vector through the constraints to the system of this rank.
      void
      add_local(const dealii::FullMatrix<double> &K,
                const dealii::Vector<double>     &r,
                const std::vector<dof_index>     &dofs,
                bool                              with_matrix);
      /// A facet to break: the largest fracture ratio R > 1 over the network.
      struct Break
      {
        double        R     = 0;
        long long     facet = -1; ///< global facet number, -1: none
        unsigned int  owner = 0;  ///< its rank
        int           local = -1; ///< on its owner: the local facet
      };
      Break
      facet_to_break() const;
      /// The facets broken in the current attempt of an increment (since the converged
      /// state): their number on every rank, the local ones, their fracture.csv rows and
      /// the messages of the fragments they released.
      struct Breaks
      {
        unsigned int                     n = 0;
        std::vector<unsigned int>        local;
        std::vector<std::vector<double>> rows;
        std::vector<std::string>         messages;
      };
      /// Break facets and solve the step from @p t again until none has R > 1; false if
      /// the step did not converge (fracture.cc).
      bool
      fracture_cycles(const double t, const double dt, Breaks &breaks);
      /// Break @p broken at @p t1 (every rank); returns its midpoint.
      dealii::Point<dim>
      break_facet(const Break &broken, const double t1, Breaks &breaks);
      /// The facets of @p breaks intact again.
      void
      undo_breaks(Breaks &breaks);
      /// The rows and messages of @p breaks out.
      void
      write_breaks(Breaks &breaks);
      /// Undo and write @p breaks, and stop the run with @p what.
      [[noreturn]] void
      fail_at_t(Breaks &breaks, const std::string &what);
      /// The fracture ratio R and the stresses s_n, s_t of facet @p e at its trial forces.
      std::array<double, 3>
      fracture_ratio(unsigned int e) const;
      void
      external_forces(const double t, Vector &f) const;
      /// The increment of prescribed local DoF @p dof of @p set from t0 to t1.
      double
      prescribed_increment(const Dirichlet &set, const unsigned int dof, const double t0, const double t1) const;
      /// The velocity of a prescribed DoF of @p set at the start @p t of a step of length
      /// @p dt: exact for velocities and rigid bodies, the step's mean velocity
      /// (g(t + dt) - g(t)) / dt of a prescribed displacement g (the FEM's rule,
      /// BoundaryDescription::step_velocity), 0 without a step.
      double
      prescribed_velocity(const Dirichlet &set, const unsigned int dof, const double t, const double dt) const;
      /// The mass matrix of owned cell @p c about its nucleus (eq. 3.12 and its 3D form).
      void
      cell_mass_matrix(const unsigned int c, dealii::FullMatrix<double> &M) const;
      /// Dynamic analyses: velocities, kinetic energy.
      bool
      dynamic() const
      {
        return analysis == Analysis::implicit_dynamics || analysis == Analysis::variable_order;
      }
      /// Initial velocities and accelerations (dynamics).
      void
      initial_state();
      /// Newton's force level: the last evaluation's, at least 1e-3 of the largest so far
      /// and 1e-6 of the predictor's out-of-balance force (a motion without load).
      double
      force_level() const
      {
        return std::max({last_force_level, 1e-3 * force_scale, 1e-6 * predictor_level});
      }
      /// H1 of spring @p i of facet @p e for output; 0 for linear or broken springs.
      double
      h1(const unsigned int e, const unsigned int i) const
      {
        const Springs<dim> &sp = springs[e];
        return sp.hysteretic && !sp.broken ? spring_law->h1(e, i, sp.state.data()) : 0.0;
      }
      /// The cell and facet of every probe point (a point outside the bodies is refused).
      void
      locate_probes();
      void
      open_tables();
      void
      write_spring_table() const;
      /// cells.csv: every cell (gathered on rank 0 in the order of the cells).
      void
      write_cell_table() const;
      /// The probe values of local cell @p c (-1: none) at @p x and facet @p e (-1: none)
      /// into @p out (the cell's columns, then the facet's; zeros where none).
      void
      point_values(const int c, const int e, const dealii::Point<dim> &x, double *out) const;
      /// With a ground motion, the probes' relative accelerations a_c + alpha x (p - x_c)
      /// of their cells (n_probes x dim, zeros for the probes of other ranks' cells), the
      /// linearized rigid motion the probe's u and v columns are; empty without a record.
      std::vector<double>
      probe_accelerations() const;
      /// The number of cell columns of point_columns().
      static constexpr unsigned int n_cell_columns = 3 * dim + 2 * (n_dofs - dim);
      /// The number of columns of point_columns() without the additional ones.
      static constexpr unsigned int n_base_columns = n_cell_columns + 2 * n_dofs + 3;
      /// The Love-Weber stress and the strain fitted to the facets' jumps of every owned
      /// cell, for `Output/Additional columns` (cell_tensors.cc; collective).
      void
      cell_tensors(std::vector<dealii::SymmetricTensor<2, dim>> &stress,
                   std::vector<dealii::SymmetricTensor<2, dim>> &strain) const;
      /// The pseudo-inverse of the symmetric @p N.
      static dealii::Tensor<2, dim>
      pseudo_inverse(const dealii::SymmetricTensor<2, dim> &N);
      /// The additional columns of a cell with @p stress, @p strain and @p material at the
      /// point whose x, u, v (the first 3 dim values of point_values()) are in @p base.
      void
      additional_values(const double                          *base,
                        const dealii::SymmetricTensor<2, dim> &stress,
                        const dealii::SymmetricTensor<2, dim> &strain,
                        const Material::Interface<dim>        &material,
                        double                                *out) const;
      /// The material of every scene body.
      std::vector<const Material::Interface<dim> *>
      body_materials() const;

      // Analysis = variable order (variable_order.cc): the DAE in (u, v, s) and IDA.
      class VariableOrder;
      static void
      declare_variable_order_parameters(dealii::ParameterHandler &prm);
      void
      parse_variable_order_parameters(dealii::ParameterHandler &prm);
      /// Integrate from 0 to the end time, reporting the output times k @p output_interval
      /// to step_finished() (the driver writes tables and fields there); returns the end time.
      double
      integrate_variable_order(const double output_interval);

      // Output.
      std::vector<std::string>
      point_columns() const;
      void
      write_vtu(std::ostream &out) const;

      // Local numbering.
      /// The global number of local DoF @p i.
      dof_index
      global_dof(const unsigned int i) const
      {
        return n_dofs * cell_block[i / n_dofs] + i % n_dofs;
      }
      /// The global DoFs of facet @p e's cells (a's, then b's).
      void
      facet_dofs(const unsigned int e, std::vector<dof_index> &dofs) const;
      /// The local DoFs of facet @p e's cells (a's, then b's).
      std::array<unsigned int, 2 * n_dofs>
      facet_local_dofs(const unsigned int e) const;

      // Parameters.
      Spacing<dim>                    spacing; ///< `Minimum distance` d(x), sampled by build_network()
      double                          block_size = 0; ///< `Sampling block size` [m]; 0: automatic
      double                          d_m = 0; ///< the constant d_m, or the smallest d of a function
      bool                            points_on_boundary = true;
      std::vector<dealii::Point<dim>> extra_points;
      double                          boundary_h   = 0; ///< 0 until build_network(): d_m / 4
      double                          shear_ratio  = 0;
      double                          moment_yield = 0.25;
      std::string                     spring_law_name;
      std::unique_ptr<SpringLaw<dim>> spring_law; ///< `RBSN/Spring law`
      Analysis                        analysis     = Analysis::quasi_static;
      double                          time_step    = 0;
      unsigned int                    n_increments = 100;
      NewtonParameters                newton;
      ImplicitDynamicsParameters      dynamics;
      FractureParameters              fracture;
      VariableOrderParameters         variable_order;
      bool                            spring_table = false;
      bool                            cell_table   = false; ///< `Write cell table`
      double                          reuse_tolerance = 0; ///< `Tangent reuse tolerance`
      bool                            incremental_assembly = true; ///< `Incremental assembly`
      std::string                     distributed_solver;  ///< `Distributed direct solver`
      std::string                     linear_solver;       ///< `Linear solver`: direct, cg, gmres
      double                          solver_tolerance = 1e-10;
      unsigned int                    solver_max_iterations = 1000;
      unsigned long                   n_linear_iterations = 0;

      // The whole network: its numbers of cells and facets, the box of its nuclei.
      std::uint64_t                   n_cells         = 0;
      unsigned int                    n_blocks        = 1; ///< of the sampling (blocks.cc)
      unsigned long                   n_global_facets = 0;
      std::vector<dealii::Point<dim>> nuclei_box; ///< the lower and upper corner of the nuclei

      // This rank's network: its cells (rigid bodies, the owned ones first), facets
      // (springs) and bodies. network.cells holds the owned cells' geometry,
      // network.facets the owned facets (a, b: local cells).
      Tessellation<dim>                          network;
      unsigned int                               n_owned_cells = 0;
      std::vector<unsigned int>                  cell_id;    ///< global number of every local cell
      std::vector<dealii::Point<dim>>            local_nuclei; ///< the nucleus of every local cell
      std::vector<unsigned int>                  owned_facet_start; ///< see the class's description
      std::vector<dof_index>                     cell_block; ///< its DoFs are n_dofs block + k
      std::vector<unsigned long>                 facet_id;   ///< global number of every owned facet
      std::vector<unsigned int>                  cell_body;  ///< of every local cell
      std::vector<double>                        cell_mass;  ///< of the owned cells
      std::vector<dealii::Tensor<1, dim>>        cell_offset; ///< centroid - nucleus
      /// The inertia about the nucleus per owned cell: 2D the polar moment (in [0][0]),
      /// 3D the tensor J = rho (tr(S) I - S), S the second moment about the nucleus.
      std::vector<dealii::SymmetricTensor<2, dim>> cell_inertia;
      std::vector<Springs<dim>>                  springs;
      std::vector<const Geometry::Region<dim> *> body_shapes;
      std::vector<unsigned int>                  mesh_body; ///< shape index -> scene body
      double                                     scale = 1;
      bool                                       consistent_tangent = true;

      // Linear algebra: n_dofs DoFs per cell.
      dealii::SparsityPattern      pattern;
      dealii::SparseMatrix<double> matrix;
      std::unique_ptr<SparseLU>    direct; ///< UMFPACK, the symbolic analysis kept

      // MPI: the parts of the network (ranks; 1 for a replicated network), this rank's DoFs.
      unsigned int                                            n_parts = 1, part = 0;
      dealii::IndexSet                                        owned_dofs, relevant_dofs;
      std::shared_ptr<const dealii::Utilities::MPI::Partitioner> partitioner;
      dealii::TrilinosWrappers::SparseMatrix                  parallel_matrix, factored_parallel;
      dealii::SolverControl                                   parallel_control{1, 0};
      std::unique_ptr<dealii::TrilinosWrappers::SolverDirect> parallel_direct; ///< Amesos
      /// cg / gmres: ML algebraic multigrid with the cells' rigid-body modes.
      std::unique_ptr<dealii::TrilinosWrappers::PreconditionAMG> amg;
      std::vector<double>                                        null_space;
      /// The matrix of the factors in `direct` (solve_linear() refactorizes on change).
      dealii::SparseMatrix<double>      factored_matrix;
      bool                              factorized = false, stale_factors = false;
      double                            previous_residual = 0;
      unsigned long                     n_factorizations  = 0;
      unsigned long                     n_exact_retries   = 0; ///< steps modified Newton failed
      dealii::AffineConstraints<double> constraints;
      /// Incremental assembly: the tangent D of every facet in the assembled matrix (broken:
      /// none), and whether the matrix is that sum with the current constrained DoFs and
      /// step (else the next assembly starts from zero), as does the assembly after
      /// max_incremental_updates updates. A checkpoint holds this state and the matrix, so
      /// that a resumed run takes the same steps bit for bit.
      std::vector<SpringMatrix>     assembled_tangent;
      std::vector<bool>             facet_in_matrix;
      bool                          matrix_current = false;
      double                        matrix_dt      = 0;
      unsigned int                  incremental_updates = 0;
      static constexpr unsigned int max_incremental_updates = 100;
      unsigned long                 n_matrix_assemblies = 0, n_full_assemblies = 0;
      unsigned long                 n_facet_evaluations = 0, n_facet_updates = 0;
      /// f_int, f_ext and inertia: the last evaluation (an iterate); f_ext_old and
      /// reaction_old (f_int + inertia - f_ext): the converged state, which the output reads.
      /// u, u_trial, v and a keep their ghost values up to date.
      Vector u, u_trial, v, a, rhs, f_int, f_ext, f_ext_old, inertia, reaction_old;
      std::vector<Dirichlet> dirichlet;
      std::vector<int>       dof_set; ///< the Dirichlet set of each local DoF, -1 if free
      std::vector<LoadSet>   load_sets;
      double                 force_scale = 0, last_force_level = 0, predictor_level = 0;

      // Bookkeeping.
      PointData::Tables<dim>               tables;
      /// newton.csv (Newton's iterations), ida.csv with variable order (the integrator's statistics)
      std::unique_ptr<Output::TimeTable>   newton_table, fracture_table;
      /// The load increments (cuts and recovery).
      IncrementControl increments{1.0, 0};
      double internal_work = 0, external_work = 0, boundary_work = 0;
      double fracture_energy = 0; ///< released by breaks in static steps (in internal_work)
      /// The work of the Rayleigh damping forces C v (dynamics with a0 or a1 > 0).
      double damping_work = 0;
      unsigned long n_ida_steps = 0; ///< variable order: IDA's steps
      unsigned long n_newton = 0, n_broken = 0;
      unsigned int  n_cuts = 0;
      std::string   spring_failure;
      std::string   solver_failure; ///< a singular tangent in the last attempt
      /// Per probe: its global cell and facet (-1: none) and, on their owners, the local ones.
      std::vector<long long>         probe_global_cell, probe_global_facet;
      std::vector<int>               probe_cell, probe_facet;
      /// `Output/History sets`: the owned cells of each set (nucleus on its box faces or in
      /// its region), and the set's number of cells.
      std::vector<std::vector<unsigned int>> history_cells;
      std::vector<unsigned long>             history_size;

      // Fragments (supports.cc): the part of every local cell over the intact facets, and
      // the cells a static analysis has released (their fragment is not held).
      std::vector<unsigned int>  fragment;
      std::vector<unsigned long> fragment_size; ///< cells of every fragment
      std::vector<bool>          released;
      std::vector<unsigned int> lone_cells; ///< local cells in fragments of one cell
      unsigned int              n_fragments = 0;
      unsigned long             n_released  = 0;
    };
  } // namespace RBSN
} // namespace hysteron

#endif
