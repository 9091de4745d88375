#ifndef hysteron_rbsn_model_h
#define hysteron_rbsn_model_h

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/base/index_set.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <hysteron/base/implicit_dynamics.h>
#include <hysteron/base/newton.h>
#include <hysteron/base/output.h>
#include <hysteron/base/checkpoint.h>
#include <hysteron/rbsn/spring_law.h>
#include <hysteron/rbsn/tessellation.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>
#include <hysteron/scene/tables.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  class SparseLU;

  namespace RBSN
  {
    enum class Analysis
    {
      linear_static,     ///< elastic springs, one solve per step
      quasi_static,      ///< Bouc-Wen springs, load stepping with Newton
      implicit_dynamics, ///< Newmark / HHT-alpha with Newton
      variable_order     ///< SUNDIALS IDA (variable-order BDF) on u, v and the spring states
    };

    /// Brittle fracture of the facets (eq. 3.49-3.51).
    struct FractureParameters
    {
      bool   enabled          = false;
      double tensile_strength = 0; ///< f_t [Pa]: the tension cut-off of the normal stress
      double cohesion         = 0; ///< c [Pa]: the shear strength at zero normal stress
      double friction         = 0; ///< tan of the friction angle
      unsigned int max_cycles = 1000; ///< breaks within one step before the run stops
    };

    /// `subsection RBSN/Variable order`: SUNDIALS IDA (variable_order.cc).
    struct VariableOrderParameters
    {
      double       relative_tolerance = 1e-6;
      double       absolute_tolerance = 0; ///< [m] on the displacements; 0: automatic
      unsigned int maximum_order      = 5; ///< of the BDF, 1..5
      double       maximum_step       = 0; ///< [s]; 0: unlimited
      double       initial_step       = 0; ///< [s]; 0: IDA's estimate
    };

    /**
     * One facet's three springs (normal, tangential, rotational): stiffness, the
     * converged and trial deformations, forces and state of the spring law (see
     * SpringLaw), and the tangent D = dF / d delta of the last evaluation.
     * Deformations delta = (delta_n, delta_t, phi) = B [u_a; u_b].
     */
    struct Springs
    {
      std::array<double, 3> k{};
      std::array<double, 3> delta{}, force{}, trial_delta{}, trial_force{};
      SpringLaw<2>::Matrix     tangent;              ///< diag(k) for linear springs
      std::vector<double>   state, trial_state;   ///< the law's (hysteretic springs only)
      std::array<double, 6> B_n{}, B_t{}; ///< the rows n and t of B (the third is (0, 0, -1, 0, 0, 1))
      double                thickness  = 1;
      bool                  hysteretic = false; ///< the spring law's (else linear springs)
      bool                  broken     = false;

      /// B(i, k): row i (n, t, phi) of B, column k of U_e.
      double
      B(const unsigned int i, const unsigned int k) const
      {
        return i == 0 ? B_n[k] : i == 1 ? B_t[k] : (k == 5 ? 1.0 : k == 2 ? -1.0 : 0.0);
      }

      /// The deformation (or its rate) B_i U of spring i for the facet's six DoF values @p U.
      template <typename VectorType>
      double
      deformation(const unsigned int i, const VectorType &U) const
      {
        if (i == 2)
          return U[5] - U[2];
        const auto &row = i == 0 ? B_n : B_t;
        double      s   = 0;
        for (unsigned int k = 0; k < 6; ++k)
          s += row[k] * U[k];
        return s;
      }
    };

    /// The scene on the network (see Solver). Two-dimensional.
    class Model
    {
    public:
      Model(const Scene<2> &scene, const Methods::Interface<2> &method, dealii::ParameterHandler &prm);
      ~Model();

      static void
      declare_parameters(dealii::ParameterHandler &prm);

      // What the driver (Run::SteppingMethod, through Solver) calls.
      /// The network, springs, system and conditions; writes no file.
      void
      setup();
      /// The tables (newton.csv or ida.csv, fracture.csv and the point tables).
      void
      open_outputs();
      /// Forces at t = 0, and the initial acceleration in dynamics.
      void
      initialize();
      double
      propose_step(double t);
      /// One increment with its fracture cycles (or, with variable order, the whole
      /// integration, reporting each output time to @p step_finished).
      bool
      advance(double &t, double dt, const std::function<void(double)> &step_finished);
      void
      write_rows(const double t)
      {
        write_table_rows(t);
      }
      void
      write_fields(double t, Output::FieldWriter &writer);
      /// springs.csv when asked for.
      void
      finish();
      /// Why this analysis cannot be checkpointed ("" if it can).
      std::string
      checkpoint_unsupported() const;
      void
      save(CheckpointWriter &out) const;
      void
      load(CheckpointReader &in);
      /// The values of the system matrix (this rank's rows), in the pattern's order.
      std::vector<double>
      matrix_values() const;
      void
      set_matrix_values(const std::vector<double> &values);

      /// The run's summary, with the driver's counts.
      std::string
      summary(unsigned long steps, unsigned int outputs) const;

      const Tessellation<2> &
      tessellation() const
      {
        return network;
      }

    private:
      using Vector = dealii::Vector<double>;

      /// A kinematic condition on cell DoFs (a scene boundary or a rigid body).
      struct Dirichlet
      {
        std::string               name;
        int                       boundary = -1, rigid = -1;
        std::vector<unsigned int> dofs; ///< 3 cell + component (2 = rotation)
      };

      /// A load on cells: a force and moment per cell, times the load's value.
      struct LoadSet
      {
        unsigned int                        load = 0;
        std::vector<unsigned int>           cells;
        std::vector<dealii::Tensor<1, 2>>   arm;    ///< moment arm of each contribution (traction)
        std::vector<double>                 weight; ///< force = weight value(t)
      };

      // Set-up.
      void
      build_network();
      void
      setup_springs();
      void
      setup_system();
      void
      setup_conditions();
      /// Static analyses: refuse a network part whose rigid-body motions are free (supports.cc).
      void
      check_supports() const;
      /// The connected parts of the network over all its facets, or over the intact ones
      /// with @p intact_only (the part of every cell into @p part), and for each part the
      /// rigid-body motions its supports leave free (empty: held).
      std::vector<std::vector<std::string>>
      network_parts(bool intact_only, std::vector<unsigned int> &part) const;

      /// What a break did to the network (fracture.csv, console).
      struct Separation
      {
        unsigned int         cells    = 0; ///< of the smaller fragment it cut off (0: none)
        unsigned int         released = 0; ///< cells it released from the static system
        dealii::Point<2>     centroid, released_centroid;
        dealii::Tensor<1, 2> load; ///< the external force on the released cells [N]
      };
      /// The fragments over the intact facets, and (static analyses) the cells of the
      /// fragments that nothing holds: released, their DoFs keep their values.
      void
      update_fragments();
      /// What the break of facet @p e did, after update_fragments(), given the released
      /// cells before it.
      Separation
      separation(unsigned int e, const std::vector<bool> &released_before) const;

      // Steps.
      void
      make_constraints(const double t0, const double t1, const bool predictor);
      /// The residual (and with @p matrix the tangent) at u_trial, time t1, step dt. The
      /// tangent is built from scratch, or (matrix_current) updated by the facets whose
      /// tangent changed since it was assembled.
      bool
      assemble(const double t1, const double dt, const bool matrix, const bool update_springs);
      /// The right-hand side of a local matrix and vector as
      /// distribute_local_to_global(K, r, dofs, matrix, rhs, true) makes it, without the matrix.
      void
      add_local_rhs(const dealii::FullMatrix<double>                     &K,
                    const dealii::Vector<double>                         &r,
                    const std::vector<dealii::types::global_dof_index> &dofs);
      /// Add the local matrix @p K to the free rows and columns of the system matrix.
      void
      add_local_change(dealii::FullMatrix<double> &K, const std::vector<dealii::types::global_dof_index> &dofs);
      bool
      solve_step(const double t, const double dt);
      /// One attempt of solve_step(): predictor and Newton iterations.
      bool
      newton_step(const double t, const double dt);
      /// Accept the trial state of a step of @p dt (in which facets @p broke).
      void
      commit(const double dt, const bool broke);
      void
      solve_linear(Vector &x);
      /// Whether the factors (or the AMG hierarchy) must be rebuilt for the current matrix:
      /// the one refactorization policy of every solver (the caller then rebuilds them).
      bool
      renew_factors();
      /// The error of a singular tangent (every solver's).
      static RuntimeError
      singular_tangent();

      // MPI (parallel.cc): the cells are partitioned over the ranks (METIS on the cell
      // graph); each rank evaluates the springs of its facets and assembles them into a
      // distributed Trilinos matrix, solved by UMFPACK on rank 0 or Amesos (KLU, MUMPS). The network, the DoF vectors and
      // (after every step) the springs' state are replicated on every rank.
      /// More than one MPI rank.
      bool
      distributed() const
      {
        return n_ranks > 1;
      }
      /// The system is a Trilinos matrix (several ranks, or an iterative solver).
      bool
      trilinos_system() const
      {
        return distributed() || linear_solver != "direct";
      }
      /// The owner of every cell and facet, the owned DoFs and the matrix's sparsity.
      void
      partition();
      /// Sum a replicated vector's rank contributions (the same bits on every rank).
      void
      sum_over_ranks(Vector &x) const;
      /// Every facet's converged spring state from its owner to all ranks.
      void
      synchronize_springs();
      /// solve_linear() on the distributed matrix.
      void
      solve_distributed(Vector &x);
      /// solve_distributed() with cg / gmres and ML: the preconditioner is rebuilt when
      /// @p renew (renew_factors()).
      void
      solve_iterative(Vector &x, bool renew);
      /// solve_distributed() with `Distributed direct solver = UMFPACK`: the matrix gathered
      /// on rank 0 and factorized there (SparseLU), the solution sent to every rank.
      void
      solve_gathered(Vector &x, bool renew);
      /// Add a local matrix and vector through the constraints to the system of this rank.
      void
      add_local(const dealii::FullMatrix<double>                     &K,
                const dealii::Vector<double>                         &r,
                const std::vector<dealii::types::global_dof_index> &dofs,
                bool                                                 with_matrix);
      /// The facet whose fracture ratio R is largest if above 1, else -1.
      int
      facet_to_break() const;
      void
      external_forces(const double t, Vector &f) const;
      /// The increment of a prescribed DoF of @p set from t0 to t1 (Dirichlet conditions).
      double
      prescribed_increment(const Dirichlet &set, const unsigned int dof, const double t0, const double t1) const;
      /// The velocity of a prescribed DoF of @p set at @p t (exact for velocities and rigid
      /// bodies, a central difference of a prescribed displacement).
      double
      prescribed_velocity(const Dirichlet &set, const unsigned int dof, const double t) const;
      /// The cell's mass matrix about its nucleus (eq. 3.12), DoFs (u, v, theta).
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
      /// The fracture.csv row of a break of @p facet at time @p t (its trial forces) and
      /// what it separated.
      std::vector<double>
      break_row(const unsigned int facet, const double t, const Separation &separated) const;
      /// H1 of spring @p i of facet @p e for output; 0 for linear or broken springs.
      double
      h1(const unsigned int e, const unsigned int i) const
      {
        const Springs &sp = springs[e];
        return sp.hysteretic && !sp.broken ? spring_law->h1(e, i, sp.state.data()) : 0.0;
      }
      /// The cell and facet of every probe point (a point outside the bodies is refused).
      void
      locate_probes();
      void
      open_tables();
      void
      write_spring_table() const;
      /// The probe / average values of cell @p c and facet @p e (-1: none) into @p out.
      void
      point_values(const unsigned int c, const int e, const dealii::Point<2> &x, double *out) const;

      // Analysis = variable order (variable_order.cc): the DAE in (u, v, s) and IDA.
      class VariableOrder;
      static void
      declare_variable_order_parameters(dealii::ParameterHandler &prm);
      void
      parse_variable_order_parameters(dealii::ParameterHandler &prm);
      /// Integrate from 0 to the end time, reporting the output times k @p output_interval
      /// to @p step_finished (the driver writes tables and fields there); returns the end time.
      double
      integrate_variable_order(const double output_interval,
                               const std::function<void(double)> &step_finished);

      // Output.
      std::vector<std::string>
      point_columns() const;
      void
      write_table_rows(const double t);
      void
      write_vtu(std::ostream &out) const;

      const Scene<2>              &scene;
      const Methods::Interface<2> &method;

      // Parameters.
      Spacing<2>                       spacing; ///< `Minimum distance` d(x), sampled by build_network()
      double                        d_m = 0; ///< the constant d_m, or the smallest d of a function
      bool                          points_on_boundary = true;
      std::vector<dealii::Point<2>> extra_points;
      double                        boundary_h   = 0; ///< 0 until build_network(): d_m / 4
      double                        shear_ratio  = 0;
      double                        moment_yield = 0.25;
      std::string                   spring_law_name;
      std::unique_ptr<SpringLaw<2>>    spring_law; ///< `RBSN/Spring law`
      Analysis                      analysis     = Analysis::quasi_static;
      double                        time_step    = 0;
      unsigned int                  n_increments = 100;
      NewtonParameters              newton;
      ImplicitDynamicsParameters    dynamics;
      FractureParameters            fracture;
      VariableOrderParameters       variable_order;
      bool                          spring_table = false;
      double                        reuse_tolerance = 0; ///< `Tangent reuse tolerance`
      bool                          incremental_assembly = true; ///< `Incremental assembly`
      std::string                   distributed_solver;  ///< `Distributed direct solver`
      std::string                   linear_solver;       ///< `Linear solver`: direct, cg, gmres
      double                        solver_tolerance = 1e-10;
      unsigned int                  solver_max_iterations = 1000;
      unsigned long                 n_linear_iterations = 0;

      // The network: cells (rigid bodies), facets (springs), bodies.
      Tessellation<2>                          network;
      std::vector<unsigned int>             cell_body;
      std::vector<double>                   cell_mass, cell_inertia; ///< about the nucleus
      std::vector<dealii::Tensor<1, 2>>     cell_offset;            ///< centroid - nucleus
      std::vector<Springs>                  springs;
      std::vector<const Geometry::Region<2> *> body_shapes;
      std::vector<unsigned int>             mesh_body; ///< shape index -> scene body
      double                                scale = 1;
      bool                                  consistent_tangent = true;

      // Linear algebra: 3 DoFs (u, v, theta) per cell.
      dealii::SparsityPattern           pattern;
      dealii::SparseMatrix<double>      matrix;
      std::unique_ptr<SparseLU>         direct; ///< UMFPACK, the symbolic analysis kept

      // MPI: ranks, the owner of every cell, the facets this rank evaluates, its DoFs.
      unsigned int                               n_ranks = 1, rank = 0;
      std::vector<unsigned int>                  cell_owner;
      std::vector<bool>                          owned_facet;
      std::vector<unsigned int>                  owned_facets;
      dealii::IndexSet                           owned_dofs;
      dealii::TrilinosWrappers::SparseMatrix     parallel_matrix, factored_parallel;
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
      std::vector<SpringLaw<2>::Matrix> assembled_tangent;
      std::vector<bool>              facet_in_matrix;
      bool                           matrix_current = false;
      double                         matrix_dt      = 0;
      unsigned int                   incremental_updates = 0;
      static constexpr unsigned int  max_incremental_updates = 100;
      unsigned long                  n_matrix_assemblies = 0, n_full_assemblies = 0;
      unsigned long                  n_facet_evaluations = 0, n_facet_updates = 0;
      /// f_int, f_ext and inertia: the last evaluation (an iterate); f_ext_old and
      /// reaction_old (f_int + inertia - f_ext): the converged state, which the output reads.
      Vector u, u_trial, v, a, rhs, f_int, f_ext, f_ext_old, inertia, reaction_old;
      std::vector<Dirichlet> dirichlet;
      std::vector<int>       dof_set; ///< the Dirichlet set of each DoF, -1 if free
      std::vector<LoadSet>   load_sets;
      double                 force_scale = 0, last_force_level = 0, predictor_level = 0;

      // Bookkeeping.
      PointData::Tables<2>                 tables;
      /// newton.csv (Newton's iterations), ida.csv with variable order (the integrator's statistics)
      std::unique_ptr<Output::TimeTable>   newton_table, fracture_table;
      /// The load increments (cuts and recovery).
      IncrementControl increments{1.0, 0};
      double internal_work = 0, external_work = 0, boundary_work = 0;
      double fracture_energy = 0; ///< released by breaks in static steps (in internal_work)
      unsigned long n_steps = 0; ///< variable order: IDA's steps
      unsigned long n_newton = 0, n_broken = 0;
      unsigned int  n_cuts = 0;
      std::string   spring_failure;
      std::string   solver_failure; ///< a singular tangent in the last attempt
      std::vector<int>              probe_cell, probe_facet;
      /// `Output/History sets`: the cells of each set (nucleus on its box faces or in its region).
      std::vector<std::vector<unsigned int>> history_cells;

      // Fragments (supports.cc): the part of every cell over the intact facets, and the
      // cells a static analysis has released (their fragment is not held).
      std::vector<unsigned int> fragment;
      std::vector<bool>         released;
      std::vector<unsigned int> lone_cells; ///< fragments of one cell (no intact facet)
      unsigned int              n_fragments = 0;
      unsigned long             n_released  = 0;
    };
  } // namespace RBSN
} // namespace hysteron

#endif
