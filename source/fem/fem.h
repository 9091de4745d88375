#ifndef hysteron_fem_fem_h
#define hysteron_fem_fem_h

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/quadrature_point_data.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include "base/direct_solver.h"
#include <hysteron/base/implicit_dynamics.h>
#include <hysteron/base/newton.h>
#include <hysteron/base/output.h>
#include <hysteron/geometry/mesh.h>
#include <hysteron/geometry/region.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/point_data.h>
#include <hysteron/run/stepping_method.h>
#include <hysteron/scene/tables.h>
#include <hysteron/scene/scene.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * The hysteretic finite element method (`set Method = fem`): the scene's
   * bodies meshed with quadrilaterals / hexahedra, FESystem(FE_Q(p), dim) with
   * p = 1 or 2, any registered material at the quadrature points, and three
   * analyses: quasi-static (load or displacement control in increments),
   * implicit dynamics (Newmark / HHT-alpha) and explicit dynamics (central
   * differences with a lumped mass, the MPM's setting). See doc/fem.md.
   */
  namespace FEM
  {
    enum class Analysis
    {
      quasi_static,      ///< equilibrium f_int(u) = f_ext(t) at each increment (Newton)
      implicit_dynamics, ///< Newmark / HHT-alpha with Newton
      explicit_dynamics  ///< central differences, lumped mass
    };

    enum class LinearSolver
    {
      automatic, ///< direct up to `Direct solver limit` DoFs, else CG (symmetric) or GMRES
      direct,    ///< Trilinos Amesos (KLU)
      cg,        ///< CG with ML algebraic multigrid (symmetric tangents)
      gmres      ///< GMRES with ML algebraic multigrid
    };

    /**
     * The quadrature-point data of one locally owned cell (one object per cell
     * in a CellDataStorage): the converged stress, strain and material state at
     * the end of the last step, and the trial values of the current Newton
     * iterate (recomputed from the converged ones at every evaluation, so the
     * path-dependent material only ever sees increments from a converged state).
     * Arrays are per quadrature point, contiguous, so that one material update
     * call serves the whole cell.
     */
    template <int dim>
    struct CellHistory
    {
      const Material::Interface<dim>              *material  = nullptr;
      unsigned int                                 body      = 0;
      unsigned int                                 n_state   = 0;
      std::vector<dealii::SymmetricTensor<2, dim>> stress, strain;  ///< converged
      std::vector<double>                          state;           ///< converged, n_q x n_state
      std::vector<dealii::SymmetricTensor<2, dim>> trial_stress, increment;
      std::vector<double>                          trial_state;
      std::vector<dealii::SymmetricTensor<4, dim>> tangent;
      /// Axisymmetric only (else empty): the hoop strain increments u_r / r and the tangent
      /// terms of the hoop strain.
      std::vector<double>                               hoop_increment;
      std::vector<Material::HoopTangent<dim>>           hoop_tangent;
      /// JxW times the thickness t(x_q) (axisymmetric: times 2 pi r_q): the reference volume
      std::vector<double>                          weight;
      /// The volume of the points in the converged and in the trial configuration: the
      /// weights times det F (updated Lagrangian), else the weights.
      std::vector<double>                          volume, trial_volume;
      std::vector<dealii::Point<dim>>              point;  ///< quadrature points (reference configuration)

      /// The converged state, in a checkpoint (the trial state is recomputed from it).
      template <class Archive>
      void
      serialize(Archive &ar)
      {
        ar &stress &strain &state &volume &tangent;
      }

      /// 2D: sigma_zz at point q of the trial (or the converged) state (the hoop stress
      /// of an axisymmetric model).
      double
      out_of_plane_stress(const unsigned int q, const bool trial) const
      {
        double eps_zz = 0, sigma_zz = 0;
        material->out_of_plane(strain[q],
                               trial ? trial_stress[q] : stress[q],
                               dealii::ArrayView<const double>((trial ? trial_state : state).data() +
                                                                 q * n_state,
                                                               n_state),
                               eps_zz,
                               sigma_zz);
        return sigma_zz;
      }
    };

    template <int dim>
    class CellKernels;

    /// See the namespace documentation.
    template <int dim>
    class Solver : public Run::SteppingMethod<dim>
    {
      /// The cell kernels of assemble() read the discretisation, loads and state.
      friend class CellKernels<dim>;

    public:
      Solver();
      ~Solver() override;

      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      setup() override;

      std::string
      summary() const override;

      std::string
      checkpoint_unsupported() const override
      {
        return "";
      }

      bool
      takes_continuum_materials() const override
      {
        return true;
      }

      /// Base excitation in dynamic analyses (quasi-static ones refuse a record).
      bool
      takes_ground_motion() const override
      {
        return true;
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

      // The driver's hooks (Run::SteppingMethod): the loop is the driver's.
      std::string
      label() const override
      {
        return "fem";
      }
      double
      size_of_state() const override
      {
        return dof_handler.n_dofs();
      }
      std::string
      field_name() const override
      {
        return "fem";
      }
      void
      open_outputs() override;
      double
      propose_step(double t) override;
      bool
      advance(double &t, double dt) override;
      void
      write_rows(double t) override
      {
        write_table_rows(t);
      }
      void
      write_fields(double t, Output::FieldWriter &writer) override;
      void
      finish(double t) override;
      void
      save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const override;
      void
      load(CheckpointReader &global, std::vector<CheckpointReader> &rank_parts, const CheckpointDirectory &directory) override;

      /// The global part (the same on every rank) and a rank's part of the state, for
      /// save() and load() alike.
      template <class Archive>
      void
      serialize_global(Archive &ar);
      template <class Archive>
      void
      serialize_rank(Archive &ar);

    private:
      using Vector = dealii::TrilinosWrappers::MPI::Vector;
      using Matrix = dealii::TrilinosWrappers::SparseMatrix;

      /// What an evaluation of the discrete equations assembles.
      enum class Assemble
      {
        forces,  ///< f_int, f_ext and the residual
        residual_and_matrix ///< ... and the (effective) tangent matrix
      };

      /// A Dirichlet condition on DoFs: a scene boundary (index b) or a rigid body.
      struct DirichletSet
      {
        std::string                                 name;
        int                                         boundary = -1; ///< scene boundary, or -1
        int                                         rigid    = -1; ///< scene body, or -1
        std::vector<dealii::types::global_dof_index> dofs;         ///< locally relevant
        std::vector<unsigned int>                   components;   ///< of each dof
      };

      /// A load and how it acts on the mesh (see setup_loads()).
      struct LoadSet
      {
        enum class Kind
        {
          volume,  ///< a total force spread uniformly over the material in the region
          nodal,   ///< a total force shared evenly by the nodes in the region
          traction ///< a force per area on the boundary faces in the region
        };
        unsigned int load  = 0;   ///< index in the scene's loads
        Kind         kind  = Kind::volume;
        int          group = -1;  ///< a Gmsh group's tag (faces: traction kind; cells: volume), or -1
        double       scale = 0;   ///< volume: 1 / selected volume; nodal: 1 / nodes; traction: 1
        std::vector<dealii::types::global_dof_index> nodal_dofs; ///< owned, with components
        std::vector<unsigned int>                   nodal_components;
      };

      struct Probe
      {
        dealii::Point<dim> point;
        int                owner = -1; ///< rank that evaluates it
        // The nearest quadrature point (on the owner): cell and index.
        typename dealii::Triangulation<dim>::active_cell_iterator cell;
        unsigned int                                              q = 0;
        dealii::Point<dim>                                        q_point;
        // The cell containing the point and its reference coordinates (owner).
        typename dealii::DoFHandler<dim>::active_cell_iterator dof_cell;
        dealii::Point<dim>                                     reference;
        bool has_cell = false; ///< this rank evaluates the displacement at the point
        bool has_q    = false; ///< this rank owns the nearest quadrature point
      };

      // Parameters.
      unsigned int  degree       = 1;
      /// `FEM/B-bar`: the dilatation of every strain replaced by its mean over the cell.
      bool          b_bar        = false;
      /// `FEM/Kinematics = updated Lagrangian`: equilibrium in the current configuration,
      /// strain increments and the Jaumann rotation of the stress at the step's midpoint.
      bool          finite_strain = false;
      Analysis      analysis     = Analysis::quasi_static;
      double        fem_time_step = 0;
      unsigned int  n_increments = 100;
      double        maximum_cfl  = 1;
      std::string   generator    = "automatic";
      double        cell_size    = 0;
      double        boundary_resolution = 0; ///< segment length of curved boundaries, 0: h/2
      unsigned int  refinements  = 0;
      std::string   mesh_file;
      /// `FEM/Mesh/Cell shape = simplex`: generated meshes split into triangles / tetrahedra.
      bool          generate_simplices = false;
      NewtonParameters newton;
      ImplicitDynamicsParameters dynamics;
      LinearSolver  solver_type = LinearSolver::automatic;
      unsigned long direct_limit = 100000;
      unsigned int  threads      = 1; ///< `FEM/Threads` (0: the cores / the ranks)
      std::string   direct_package = "Amesos_Klu";
      double        solver_tolerance = 1e-10;
      unsigned int  solver_max_iterations = 5000;
      bool          quadrature_table = false;

      // Set-up.
      /// The mesh of the deformable bodies (mesh.cc): a structured mesh as a coarse mesh on
      /// every rank and global refinements (p4est), any other mesh made whole on rank 0 and
      /// distributed (make_distributed_mesh()); then set_mesh_box().
      void
      make_mesh();
      /// A structured mesh of quadrilaterals / hexahedra as a parallel::distributed
      /// triangulation; false (nothing made) if it cannot be coarsened enough
      /// (Geometry::coarse_structured_mesh()).
      bool
      make_structured_mesh(const std::vector<const Geometry::Region<dim> *> &shapes);
      /// The whole structured or unstructured mesh of @p shapes (@p kind), on rank 0.
      Geometry::CoarseMesh<dim>
      generated_mesh(const std::vector<const Geometry::Region<dim> *> &shapes, const std::string &kind) const;
      /// Refuse a structured mesh of @p volume that misses part of the bodies' volume.
      void
      check_staircase(const std::vector<const Geometry::Region<dim> *> &shapes, const double volume) const;
      /**
       * Rank 0 reads (Gmsh) or generates the mesh of kind @p kind, checks its cells, assigns
       * bodies, splits it into simplices (Cell shape), refines, partitions and describes it;
       * each rank keeps its cells and their neighbours (parallel::fullydistributed). Errors
       * of rank 0 are thrown on every rank (distributed_mesh.cc).
       */
      void
      make_distributed_mesh(const std::vector<const Geometry::Region<dim> *> &shapes, const std::string &kind);
      /// Refuse a mesh of @p coarse_cells cells, refined @p levels + `Refinements` times,
      /// that does not fit into the machine's memory (@p serial: rank 0 holds it whole
      /// while it sets it up).
      void
      check_memory(const double coarse_cells, const unsigned int levels, const bool serial) const;
      /// The mesh's bounding box, the length scale and the checks of an axisymmetric mesh.
      void
      set_mesh_box();
      void
      setup_system();
      void
      setup_history();
      /// The support point and component of every DoF of the locally relevant cells, and
      /// of every owned DoF (owned_support, owned_component).
      void
      map_support_points(std::map<dealii::types::global_dof_index, dealii::Point<dim>> &support,
                         std::map<dealii::types::global_dof_index, unsigned int>       &component);
      void
      setup_dirichlet();
      /// Quasi-static: refuse a mesh part whose rigid-body motions are free (supports.cc).
      void
      check_supports() const;
      /// Warn (once) when Q1 without B-bar or P1 meets a nearly incompressible material.
      void
      warn_about_locking() const;
      void
      setup_loads();
      void
      setup_probes();
      void
      setup_dynamics();

      // Named sets (sets.cc): Gmsh physical groups and the `History sets` tables.
      /// A physical group of the mesh file: boundary faces or cells with this tag.
      struct PhysicalGroup
      {
        bool         faces = true; ///< a group of boundary faces (else of cells)
        unsigned int tag   = 0;
      };
      /// The group named (or numbered) @p group; an InputError at @p where unless the
      /// mesh file has it.
      PhysicalGroup
      physical_group(const std::string &group, const std::string &where) const;
      /// Whether the (locally owned or ghost) @p cell lies in cell group @p tag.
      template <typename Iterator>
      bool
      in_cell_group(const Iterator &cell, const unsigned int tag) const
      {
        return !cell_group.empty() && cell_group[cell->active_cell_index()] == tag;
      }
      /// The locally relevant DoFs of @p group (nodes of its faces or cells), with their components.
      std::vector<std::pair<dealii::types::global_dof_index, unsigned int>>
      group_dofs(const PhysicalGroup &group) const;
      /// The owned DoFs of every history set and the weights of their means (after setup_dirichlet()).
      void
      setup_set_histories();
      /// This rank's part of the history rows: per set the mean displacement, the reaction and the load.
      std::vector<double>
      set_history_values() const;

      /**
       * The constraints of a step to time @p t1: every prescribed DoF gets the
       * increment of its prescribed displacement from the converged state
       * (@p predictor) or 0 (later Newton iterations).
       */
      void
      make_constraints(const double t1, const bool predictor);

      /**
       * Evaluate the discrete equations at the iterate @p u_iterate (ghosted) of
       * the step from the converged state (u_n at t_n) to t1: material updates at
       * every quadrature point (trial state), f_int, f_ext(t1), and into
       * system_rhs (condensed, = -residual) and, on request, system_matrix.
       * Returns false (on every rank) if a material update failed; the message
       * is in material_failure.
       */
      bool
      assemble(const Vector  &u_iterate,
               const double   t1,
               const double   dt,
               const Assemble what,
               const bool     update_material = true);

      /// The mass system of the initial acceleration M a0 = f_ext(0) - f_int(0) - C v0.
      void
      assemble_mass_system();

      /// y = K0 x (elastic stiffness, matrix-free); @p x ghosted.
      void
      elastic_stiffness_product(const Vector &x, Vector &y) const;

      /// force += factor C v (Rayleigh damping with the lumped mass and the lumped dashpots
      /// of absorbing boundaries, explicit dynamics).
      void
      damping_force(const Vector &velocity, Vector &force, const double factor) const;

      // Absorbing boundaries (absorbing.cc): Lysmer-Kuhlemeyer dashpots on boundary faces.
      /// The faces of every absorbing boundary; refuses one that selects none.
      void
      setup_absorbing();
      /// The dashpots' damping matrix C_b of the locally owned @p cell (its absorbing faces,
      /// its material); false (C untouched) if it has no absorbing face. @p ffv needs values,
      /// quadrature points, JxW and normals.
      bool
      absorbing_matrix(const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
                       dealii::FEFaceValues<dim>                                    &ffv,
                       dealii::FullMatrix<double>                                   &C) const;
      /// C_b v for the ghosted @p velocity (owned entries), or, with @p lumped, the row sums
      /// of C_b over each node's component times v.
      Vector
      absorbing_force(const Vector &velocity, const bool lumped = false) const;

      /// The prescribed displacement increment of constrained DoF @p k (constrained_list) over [t0, t1].
      double
      prescribed_increment(const unsigned int k, const double t0, const double t1) const;

      /// The prescribed velocity of constrained DoF @p k at t (displacement: the mean of the step ending at t).
      double
      prescribed_velocity(const unsigned int k, const double t, const double dt) const;

      /// Whether the volume load @p l acts at x of a cell that it loads (a group loads all of
      /// its cells' points, a region those in it).
      bool
      in_region(const unsigned int l, const dealii::Point<dim> &x) const
      {
        return load_sets[l].group >= 0 || load_regions[l]->contains(x, 1e-9 * u_scale);
      }

      /// Whether the traction of load @p l acts on face @p f of @p cell: a boundary face in
      /// the group, or whose centre lies in the region.
      template <typename Iterator>
      bool
      loads_face(const unsigned int l, const Iterator &cell, const unsigned int f) const
      {
        const auto face = cell->face(f);
        return face->at_boundary() &&
               (load_sets[l].group >= 0 ? face->boundary_id() == static_cast<unsigned int>(load_sets[l].group) :
                                          load_regions[l]->contains(face->center(), 1e-9 * u_scale));
      }

      /// The force level of the last evaluation that Newton's tolerance refers to (at
      /// least 1e-3 of the largest so far, so that unloading converges, and 1e-6 of the
      /// predictor's out-of-balance force, so that a motion without load converges).
      double
      force_level() const
      {
        return std::max({last_force_level, 1e-3 * force_scale, 1e-6 * predictor_level});
      }

      /// The round-off floor 64 eps sqrt(N) of a residual of N entries, relative to
      /// the force level (a tighter tolerance would iterate on noise).
      double
      residual_floor() const
      {
        return hysteron::residual_floor(dof_handler.n_dofs());
      }

      /// A row of newton.csv.
      void
      log_newton(const double       t1,
                 const double       dt,
                 const unsigned int iteration,
                 const double       residual,
                 const double       alpha);

      /// Solve system_matrix du = system_rhs; returns the iterations (0 for direct).
      unsigned int
      solve_linear(Vector &du);

      /// One implicit step (quasi-static or Newmark) from t to t + dt; false if Newton failed.
      bool
      implicit_step(const double t, const double dt);

      /// One explicit central-difference step from t to t + dt.
      void
      explicit_step(const double t, const double dt);
      /// Project the nodes of u_trial that crossed a wall back onto it (v_half and the
      /// walls' @p contact forces take the change of momentum); returns the walls' work.
      double
      project_on_walls(const double dt, Vector &v_half, std::vector<dealii::Tensor<1, dim>> &contact);

      /// Accept the trial state as converged (stresses, states, strains, work, vectors).
      void
      commit(const double t1, const double dt);

      /// The critical step of central differences, 2 / omega_max (power iteration).
      double
      critical_time_step();

      // Output.
      void
      open_tables();
      void
      write_table_rows(const double t);
      void
      write_quadrature_table() const;

      /// The reaction (force of the constraint on the body) of every Dirichlet set: this rank's part.
      std::vector<dealii::Tensor<1, dim>>
      reactions() const;

      // The discretisation: quadrilaterals / hexahedra or triangles / tetrahedra (FE_SimplexP,
      // Gauss-simplex rules) on a p4est triangulation (structured meshes) or a fully
      // distributed one (every other mesh).
      std::unique_ptr<dealii::parallel::TriangulationBase<dim>> triangulation;
      bool                                               simplex = false;
      std::unique_ptr<dealii::FESystem<dim>>            fe;
      std::unique_ptr<dealii::Mapping<dim>>             mapping;
      dealii::DoFHandler<dim>                           dof_handler;
      std::unique_ptr<dealii::Quadrature<dim>>          quadrature;
      std::unique_ptr<dealii::Quadrature<dim - 1>>      face_quadrature;
      dealii::IndexSet                                  owned_dofs, relevant_dofs;
      dealii::AffineConstraints<double>                 constraints;
      Matrix                                            system_matrix;
      Vector                                            system_rhs;
      dealii::CellDataStorage<typename dealii::Triangulation<dim>::cell_iterator, CellHistory<dim>>
        history;
      std::vector<CellHistory<dim> *>               cell_history; ///< by active cell index (owned cells)
      std::vector<const Material::Interface<dim> *> body_material;
      std::vector<unsigned int>                     body_to_mesh; ///< scene body -> material id
      std::vector<unsigned int>                     mesh_to_body;
      /// Generator = file: the physical tag of every locally owned and ghost cell (by active
      /// cell index), and the named groups ($PhysicalNames: name -> dimension, tag).
      std::vector<unsigned int>                                   cell_group;
      std::map<std::string, std::pair<unsigned int, unsigned int>> physical_names;
      /// `History sets`: the owned DoFs of each set, their components and the weight 1 / n_c
      /// of the mean over the set's nodes of each component.
      struct HistorySet
      {
        std::vector<dealii::types::global_dof_index> dofs;
        std::vector<unsigned int>                   components;
        std::array<double, dim>                     weight{};
      };
      std::vector<HistorySet> history_sets;
      std::vector<std::string>                      state_names;
      bool                                          symmetric_tangent = true;
      bool                                          consistent_tangent = true;

      // Prescribed motion and loads.
      std::vector<DirichletSet>             dirichlet;
      std::vector<dealii::types::global_dof_index> constrained_list; ///< relevant, all sets
      std::vector<int>                      constrained_set;  ///< set of each listed dof
      std::vector<unsigned int>             constrained_component;
      std::vector<dealii::Point<dim>>       constrained_point; ///< support point of each listed dof
      std::vector<LoadSet>                  load_sets;
      std::vector<const Geometry::Region<dim> *> load_regions;
      std::vector<bool>                     cell_in_load; ///< per (active cell index, load set)
      std::vector<dealii::Point<dim>>       owned_support;   ///< support point of each owned DoF
      std::vector<unsigned int>             owned_component; ///< component of each owned DoF
      /// Wall conditions (explicit dynamics): per wall, the normal direction, side and position.
      struct Wall
      {
        unsigned int set = 0, direction = 0;
        bool         lower = true;
        double       position = 0;
      };
      std::vector<Wall>                     walls;
      std::vector<dealii::types::global_dof_index> wall_dofs; ///< owned dofs of normal components
      std::vector<double>                   wall_reference;  ///< their reference coordinate
      std::vector<unsigned int>             wall_of_dof;
      std::vector<dealii::Tensor<1, dim>>   wall_forces;     ///< per Dirichlet set, last step
      /// Absorbing boundaries: per condition the Gmsh group of its faces (tag, or -1) or the
      /// faces of the mesh's bounding box (2 d + side, as BoundaryDescription::faces).
      struct Absorber
      {
        int                       group = -1;
        std::vector<unsigned int> faces;
      };
      std::vector<Absorber>                 absorbers;
      /// Whether face @p f of @p cell is a boundary face of an absorbing boundary (of @p only).
      bool
      absorbs_face(const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
                   const unsigned int                                            f,
                   const Absorber                                               *only = nullptr) const;

      // The state: displacement, velocity, acceleration (owned and ghosted), the
      // forces, and the lumped mass of explicit dynamics. f_int, f_ext and inertia are
      // those of the last evaluation (an iterate); f_int_old, f_ext_old and reaction_old
      // (f_int + inertia - f_ext) those of the converged state, which the output reads.
      Vector u, u_ghost, v, v_ghost, a, a_ghost, u_trial;
      Vector f_int, f_ext, f_int_old, f_ext_old, inertia, lumped_mass, reaction_old;
      /// Explicit dynamics with absorbing boundaries: the row-sum-lumped (diagonal) C_b.
      Vector absorbing_lumped;
      /// The vectors of the state (a checkpoint's cell records hold their values).
      std::array<Vector *, 10>
      state_vectors()
      {
        return {{&u, &v, &a, &u_trial, &f_int, &f_ext, &f_int_old, &f_ext_old, &inertia, &reaction_old}};
      }
      dealii::BoundingBox<dim> mesh_box;
      double                   u_scale = 0;    ///< characteristic length for tolerances [m]
      double                   force_scale = 0; ///< largest force norm seen (Newton floor)
      double                   last_force_level = 0;
      double                   predictor_level  = 0; ///< |residual| of the step's predictor
      double                   current_dt = 0;  ///< the step being solved

      // Diagnostics and bookkeeping.
      std::string                                      material_failure;
      std::vector<Probe>                               probes;
      PointData::Tables<dim>                           tables;
      std::unique_ptr<Output::TimeTable>               newton_table;
      /// Work of this rank's cells and DoFs since t = 0 (summed when a row is written).
      double internal_work = 0, external_work = 0, boundary_work = 0;
      /// Whether a dynamic analysis has Rayleigh damping (a0 or a1 > 0).
      bool
      has_rayleigh_damping() const
      {
        return analysis != Analysis::quasi_static &&
               (dynamics.rayleigh_mass > 0 || dynamics.rayleigh_stiffness > 0);
      }
      /// y = C v = a0 M v + a1 K0 v with the consistent mass (implicit dynamics), matrix-free,
      /// for the damping work; @p velocity with ghosts.
      Vector
      rayleigh_force(const Vector &velocity) const;
      /// Work of the Rayleigh damping forces C v (dissipated; the damping_work column of
      /// energy.csv in dynamic analyses with Rayleigh damping).
      double damping_work = 0;
      unsigned long n_newton = 0, n_cuts = 0, n_linear = 0;
      /// Wall time of the material updates inside assemble() (the timer table has the
      /// sections "FEM assembly", which includes them, and "FEM linear solve").
      double material_seconds = 0;
      /// The load increments (their cuts and recovery); the nominal step is set at set-up.
      IncrementControl increments{1.0, 0};
      /// The nominal step was checked against the critical step of explicit dynamics.
      bool          step_checked = false;
      double        critical_step = 0;
      /// Explicit dynamics: the kinetic energy at t = 0 (whole mesh; < 0 before the
      /// first step), for the divergence check of explicit_step().
      double        initial_kinetic = -1;
      std::string   solver_name;
      /// direct: Amesos with the symbolic analysis of the (fixed) pattern kept over the run.
      std::unique_ptr<KeptDirectSolver> direct_solver;
      /// cg / gmres: ML on the rigid-body modes of the mesh, kept while it serves (solvers.cc).
      std::unique_ptr<dealii::TrilinosWrappers::PreconditionAMG> amg;
      std::vector<double> amg_null_space;       ///< the modes' values on the owned rows
      bool                reuse_preconditioner = true; ///< `Preconditioner reuse`
      unsigned int        amg_reference_iterations = 0; ///< of the first solve after a set-up
      unsigned long       n_amg_setups = 0;
      /// Build the AMG hierarchy of the current system matrix.
      void
      setup_amg();
    };
  } // namespace FEM
} // namespace hysteron

#endif
