#ifndef hysteron_source_mpm_mpm_h
#define hysteron_source_mpm_mpm_h

#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/particles/particle_handler.h>

#include <hysteron/base/output.h>
#include <hysteron/geometry/region.h>
#include <hysteron/mpm/update_scheme.h>
#include <hysteron/run/stepping_method.h>
#include <hysteron/scene/point_data.h>
#include <hysteron/scene/tables.h>
#include <hysteron/scene/scene.h>

#include "mpm/grid.h"
#include "mpm/particles.h"

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace MPM
  {
    template <int dim, typename Basis, bool with_contact>
    class PhaseKernels;

    /**
     * The nodal part of `MPM/Damping` (doc/mpm.md, "Damping"): mass-proportional
     * Rayleigh damping -a0 m_i v_i and Cundall's local damping -alpha |f_i| sgn(v_i),
     * per component, in the momentum balance of a node.
     */
    struct NodalDamping
    {
      double mass  = 0; ///< a0 [1/s]
      double local = 0; ///< alpha [-]

      bool
      active() const
      {
        return mass > 0 || local > 0;
      }

      /**
       * The velocity change over @p dt of one component of a node with 1 / m = @p inv_m,
       * velocity @p v and force @p f, from m (v' - v) / dt = f - alpha |f| sgn(v) - (a0 m + c)
       * (v + v') / 2 (the viscous terms trapezoidal: exact decay to O((a0 dt)^3), any a0 dt
       * stable), with the dashpot c of absorbing boundaries given as @p extra = c / m.
       */
      double
      velocity_change(const double inv_m,
                      const double v,
                      const double f,
                      const double dt,
                      const double extra = 0) const
      {
        const double f_local = f - local * std::abs(f) * ((v > 0) - (v < 0));
        const double rate    = mass + extra;
        return dt * (f_local * inv_m - rate * v) / (1.0 + 0.5 * rate * dt);
      }

      /// The work the damping forces of velocity_change() take out over @p dt (mass @p m,
      /// change @p dv): dt v_mid (alpha |f| sgn(v) + a0 m v_mid), v_mid = v + dv / 2.
      double
      work(const double m, const double v, const double f, const double dv, const double dt) const
      {
        const double v_mid = v + 0.5 * dv;
        return dt * v_mid * (local * std::abs(f) * ((v > 0) - (v < 0)) + mass * m * v_mid);
      }
    };

    /**
     * The explicit Material Point Method (`set Method = mpm`), dissertation
     * chapter 4: bodies filled with material points that carry mass, velocity,
     * stress and the Bouc–Wen state; a fixed Cartesian background grid on which
     * the momentum equation is solved each step.
     *
     * One step (MUSL, §4.2) with shape functions N_i(x_p) of the step's start:
     *  1. P2G: m_i = sum_p N_ip m_p, p_i = sum_p N_ip m_p v_p,
     *     f_i = -sum_p V_p sigma_p grad N_ip + sum_p N_ip (m_p g + f_p);
     *  2. nodes: v_i = p_i / m_i, v_i' = v_i + dt f_i / m_i, boundary conditions on v_i';
     *  3. G2P: v_p' = alpha (v_p + sum N_ip (v_i' - v_i)) + (1 - alpha) sum N_ip v_i'
     *     (alpha: FLIP fraction), x_p' = x_p + dt sum N_ip v_i';
     *  4. MUSL: p_i = sum N_ip m_p v_p', v_i = p_i / m_i with boundary conditions;
     *  5. L_p = sum_i v_i (x) grad N_ip, d eps = sym(L_p) dt, F' = (I + L dt) F,
     *     V' = det F' V_0, stress and state by the material (optionally the
     *     Jaumann rotation sigma += (W sigma - sigma W) dt, W = skew L).
     * Axisymmetric (x = r): V_p and m_p are those of the ring 2 pi r_p around the
     * axis; f_i gains -sum_p N_ip V_p sigma_tt,p / r_p e_r (from the virtual hoop strain
     * delta u_r / r), the material takes d eps_tt = dt sum_i N_ip v_i,r / r_p and
     * V' = V det(I + L dt) (1 + d eps_tt).
     * USL takes v_i' in step 5 without the remap; USF updates the stress with
     * the velocities p_i / m_i of step 1 before the forces are computed.
     *
     * Each of these passes is a phase (StepPhases, update_scheme.h); the update
     * scheme (`MPM/Scheme`, a registered UpdateScheme: source/mpm/schemes/)
     * calls them in its order. The phase kernels are templates of the basis
     * (linear, cubic B-spline, step.h); basis and scheme are chosen once, at
     * set-up.
     *
     * The run loop (time steps, outputs, checkpoints, signals) is the driver's
     * (Run::SteppingMethod); this class implements the set-up, the step, the
     * state and the fields.
     */
    template <int dim>
    class Solver : public Run::SteppingMethod<dim>
    {
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

      /// Base excitation (doc/mpm.md "Base excitation"): the body force -a_g(t) d.
      bool
      takes_ground_motion() const override
      {
        return true;
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

      // The driver's hooks.
      std::string
      label() const override
      {
        return "mpm";
      }
      double
      size_of_state() const override
      {
        return n_global_particles;
      }
      std::string
      field_name() const override
      {
        return "particles";
      }
      void
      open_outputs() override;
      void
      initialize() override;
      double
      propose_step(double t) override;
      bool
      advance(double &t, double dt) override;
      void
      write_rows(double t) override
      {
        write_table_rows(t);
        if (grid_moves)
          write_grid_row(t);
      }
      void
      write_fields(double t, Output::FieldWriter &writer) override;
      void
      finish(double t) override;
      void
      save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const override;
      void
      load(CheckpointReader &global, std::vector<CheckpointReader> &rank_parts, const CheckpointDirectory &directory) override;

    private:
      struct BoundaryNodes
      {
        std::string               name;
        unsigned int              type = 0; ///< BoundaryDescription::Type
        std::vector<unsigned int> nodes;    ///< local grid nodes
        std::vector<int>          normal_sign; ///< wall: +1 / -1 per node (lower / upper face)
        std::vector<unsigned int> normal_direction;
        std::vector<bool>         components;
      };

      struct Probe
      {
        dealii::Point<dim>            point;
        dealii::types::particle_index id = 0;
        dealii::Point<dim>            initial_position;
        int                           local = -1; ///< index in the store, -1 if not on this rank
      };

      // Parameters.
      dealii::Point<dim>            lower, upper;
      double                        cell_size = 0;
      std::array<unsigned int, dim> n_cells;
      std::string                   basis_name;
      double                        flip_fraction = 1.0;
      bool                          jaumann       = false;
      /// x is the radius (Material/Stress state = axisymmetric): ring volumes, hoop terms.
      bool                          axisymmetric  = false;
      double                        maximum_cfl   = 1.0;
      /// The critical step and the step of the step being taken (for failure messages).
      double                        step_critical = 0, step_dt = 0;
      double                        probe_interval = 0.0;
      bool                          particle_table = false;
      std::vector<Geometry::Region<dim>> average_regions;
      double                        small_mass = 0; ///< nodes lighter than this have no velocity
      /// The work of a grid cell, in material points, when p4est balances the ranks.
      double                        cell_weight = 0.01;

      // The moving grid (`MPM/Grid/Motion`, grid_motion.cc). The lattice is moved
      // after every step; the kernels see only the lattice of their step.
      enum class GridMotion
      {
        fixed,     ///< the grid stays where it is
        follow,    ///< the grid follows the affine part of the motion of some bodies
        prescribed ///< the lower corner moves and the cells stretch as functions of t
      };
      GridMotion                                   grid_motion = GridMotion::fixed;
      /// Whether the grid moves (any Type but fixed): a fixed grid pays nothing.
      bool                                         grid_moves = false;
      /// follow: per body, whether its points are followed; whether the cells stretch.
      std::vector<bool>                            motion_follows_body;
      bool                                         motion_stretches = true;
      /// prescribed: the lower corner's velocity [m/s] and the stretch rates d ln h_d / dt [1/s].
      std::shared_ptr<dealii::FunctionParser<1>>   motion_velocity, motion_stretch_rate;
      /// follow: per face 2 d + side, the boundary condition that holds the face in
      /// its normal direction (its index), or -1: a held face moves only as the
      /// condition moves the material there.
      std::array<int, 2 * dim>                     held_face;
      /// The grid's lower corner and cell sizes at the rows of grid.csv (rank 0).
      std::unique_ptr<Output::TimeTable>           grid_table;
      double                                       grid_table_time = -1;
      /// The lattice moved_lattice() computed last (for the failure message).
      Lattice<dim>                                 last_moved_lattice;
      static void
      declare_grid_motion_parameters(dealii::ParameterHandler &prm);
      void
      parse_grid_motion(dealii::ParameterHandler &prm);
      /// After setup_boundaries(): which faces of the grid the conditions hold.
      void
      setup_grid_motion();
      /**
       * The lattice after the step from @p t to @p t + @p dt (points at
       * particles.next), collective. Sets failed_point if a point lies outside
       * it; returns a message (the same on every rank) if the grid cannot move so.
       */
      std::string
      moved_lattice(const double t, const double dt, Lattice<dim> &moved);
      /// Move the grid to @p moved and find the points' cells in it (after commit()).
      void
      move_grid(const Lattice<dim> &moved);
      void
      write_grid_row(const double t);

      // Set-up and the pieces of run().
      void
      setup_grid();
      /// The groups of points (a material or a rigid body each) and the ParticleHandler.
      void
      setup_groups();
      void
      generate_particles();
      void
      setup_boundaries();
      /// Refuse two conditions that prescribe one component of a grid node differently.
      void
      refuse_conflicting_boundaries() const;
      /// --resume: the grid and this rank's points (in resumed_points) from the checkpoint.
      void
      setup_from_checkpoint();
      /// --resume: the arrays and the handler from resumed_points; with @p same_order
      /// (as many ranks as the checkpoint's) in the arrays' order at the checkpoint.
      void
      restore_points(const bool same_order);
      /// The global part (what is the same on every rank) and a rank's part of the
      /// state, for save() and load() alike.
      template <class Archive>
      void
      serialize_global(Archive &ar);
      template <class Archive>
      void
      serialize_rank(Archive &ar);
      /// "[x0, x1] x [y0, y1]": the extent of @p lattice (the background grid), for messages.
      std::string
      grid_extent(const Lattice<dim> &lattice) const;
      /// A warning for every boundary condition that constrained no node with mass.
      void
      warn_about_idle_boundaries() const;
      void
      from_handler();
      /// Copy the arrays into the handler; the locations in the set-up's frame of a
      /// moving grid (for sorting), or with @p physical_locations where they are (output).
      void
      to_handler(const bool physical_locations = false);
      /// Put a new point at @p x (in the current lattice, a cell of this rank) into the handler.
      void
      insert_into_handler(const dealii::Point<dim>               &x,
                          const dealii::types::particle_index     id,
                          const dealii::ArrayView<const double>  &properties);
      void
      locate_probes();
      /// h / max_p(c_p + |v_p|), reduced for stiffness-proportional damping (damping.cc).
      double
      critical_time_step() const;
      void
      check_step(const double dt, const double t) const;
      void
      open_tables();
      /// Column names and values of one point (probes, particle table).
      std::vector<std::string>
      point_columns() const;
      void
      point_values(const unsigned int s, double *values) const;
      void
      write_particle_table() const;
      void
      write_table_rows(const double t);
      /// The failure of the last step, described on every rank (from the rank that saw it).
      std::string
      describe_failure(const double t) const;
      /// The divergence message if the step from @p t diverged (energy), else "".
      std::string
      check_energy(const double t, const double dt, const double critical) const;
      void
      apply_boundary_conditions(const double t, const double dt, const bool record_reactions);
      bool
      needs_migration() const;

      // The phases of a step (StepPhases documents what each computes).
      template <int, typename, bool>
      friend class PhaseKernels;
      /// Reset the nodes touched in the last step, the reactions and the loads at @p t.
      void
      begin_step(const double t);
      template <typename Basis, bool with_forces, bool with_contact>
      void
      particles_to_grid();
      /// With @p viscous also the viscous stress a1 C0 : sym(L_p), L_p from the velocities
      /// the nodes hold (damping.cc), and its work.
      template <typename Basis, bool with_contact, bool viscous>
      void
      forces_to_grid(const bool updated_stresses);
      void
      nodal_velocities();
      void
      update_nodal_velocities(const double dt);
      /// update_nodal_velocities() with the nodal damping and the dashpots of absorbing
      /// boundaries, and their work (damping.cc).
      void
      update_damped_nodal_velocities(const double dt);

      // Absorbing boundaries (`Boundary/Type = absorbing`, absorbing.cc; doc/mpm.md
      // "Absorbing boundaries"): Lysmer-Kuhlemeyer dashpots on the grid nodes of faces.
      struct Dashpot
      {
        unsigned int           node     = 0; ///< local grid node
        unsigned int           boundary = 0; ///< index of the condition (its reaction)
        dealii::Tensor<1, dim> c;            ///< per component: rho c_p A (normal), rho c_s A [kg/s]
      };
      /// Sorted by node; a node on several absorbing faces has one per face.
      std::vector<Dashpot>    dashpots;
      /// Per local node: 1 + the index of its first dashpot, 0: none.
      ZeroPages<unsigned int> dashpot_first;
      /// After setup_boundaries(): the dashpots of every absorbing condition.
      void
      setup_absorbing();
      /// The deformable body whose material lies behind the absorbing condition @p b
      /// (points in the grid cells next to its faces); refused if none or several materials.
      unsigned int
      absorbing_body(const unsigned int b) const;
      /// The forces of the dashpots from @p first (of node n) on component @p d at the
      /// mid-step velocity @p v_mid: their reactions and work (boundary_work).
      void
      record_dashpots(const unsigned int first, const unsigned int d, const double v_mid, const double dt);

      // Damping (`MPM/Damping`, damping.cc; doc/mpm.md, "Damping").
      NodalDamping nodal_damping;
      /// Rayleigh stiffness coefficient a1 [s]: the viscous stress a1 C0 : d in the forces.
      double       stiffness_damping = 0;
      /// The work of the damping forces (this rank: its points' viscous stresses and its
      /// owned nodes' forces), the damping_work column of energy.csv.
      double       damping_work = 0;
      bool
      damped() const
      {
        return nodal_damping.active() || stiffness_damping > 0;
      }
      static void
      declare_damping_parameters(dealii::ParameterHandler &prm);
      void
      parse_damping(dealii::ParameterHandler &prm);
      template <typename Basis, bool with_contact>
      bool
      grid_to_particles(const double t, const double dt);
      template <typename Basis, bool with_contact>
      void
      remap_momenta();
      /// Strains, deformation gradients, volumes and stresses from the nodal
      /// velocities (with @p midpoint from v_i - Delta v_i / 2), with or without
      /// adding their work to internal_work.
      template <typename Basis, bool midpoint, bool with_contact>
      bool
      update_stresses(const double dt, const bool record_work);

      // Contact (`MPM/Contact`, contact.cc): every body has its own nodal mass,
      // momentum, force and mass gradient in the grid's layer (block b of a node
      // is body b: contact_block doubles, m, p or v, f or Delta v as in the common
      // field, then the mass gradient and the velocity projected from the points);
      // where two or more bodies have mass at a node their velocities are corrected
      // so that they do not interpenetrate.
      static constexpr unsigned int contact_block = 1 + 4 * dim;
      bool                          contact       = false;
      /// With contact: the blocks per node of the layer (one per body).
      unsigned int                  n_contact_blocks = 0;
      /// Coulomb friction coefficient of each pair of bodies (n_bodies x n_bodies).
      std::vector<double>           friction;
      /// Whether the layer holds momenta (after a transfer) or velocities.
      bool                          layer_holds_momenta = true;
      /// Whether the layer holds the momenta of particles_to_grid() (not yet converted).
      bool                          layer_from_points = true;
      /// Per local node (with contact or damping): bit c set if a boundary condition sets
      /// velocity component c there (0: no condition).
      ZeroPages<unsigned char>      boundary_node;
      /// Mark the nodes of the boundary conditions in boundary_node.
      void
      mark_boundary_nodes();
      /// Scratch of apply_contact(): per body, the trial and the rigid velocities.
      std::vector<dealii::Tensor<1, dim>> contact_velocity, contact_rigid_velocity;
      /// Allocate the layer and the scratch of contact (after setup_boundaries()).
      void
      setup_contact();
      void
      parse_contact(dealii::ParameterHandler &prm);
      /// The per-body velocities at the active nodes from the common field (one body
      /// at the node) or with the contact correction (two or more); with @p record
      /// also Delta v per body and the reactions of rigid bodies.
      void
      apply_contact(const double t, const double dt, const bool record);

      /// Record the cell of point p at its new position @p x (or the failure).
      void
      track_cell(const unsigned int p, const dealii::Point<dim> &x)
      {
        const Lattice<dim> &lattice = grid->lattice();
        bool                finite  = true;
        for (unsigned int d = 0; d < dim; ++d)
          finite = finite && std::isfinite(x[d]);
        // A moving grid checks the points against the lattice of the next step
        // (moved_lattice()); here it only finds their cells in this one.
        if (!finite || (!grid_moves && !lattice.contains(x)))
          {
            if (failed_point < 0)
              {
                failed_point = p;
                failure      = finite ? "a material point left the grid" :
                                        "a non-finite position";
              }
            return;
          }
        const auto         cell = lattice.cell_of(x);
        const unsigned int id   = grid->cell_id(cell);
        if (id != particles.cell[p])
          {
            particles.cell[p] = id;
            ++n_changed_cells;
            if (!grid->owns_cell(cell))
              left_subdomain = true;
          }
      }

      std::unique_ptr<BackgroundGrid<dim>>               grid;
      dealii::MappingCartesian<dim>                      mapping;
      std::unique_ptr<dealii::Particles::ParticleHandler<dim>> handler;
      ParticleStore<dim>                                 particles;
      std::vector<BoundaryNodes>                         boundaries;
      std::vector<bool> boundary_acted; ///< per boundary: has it constrained a node with mass
      std::vector<Probe>                                 probes;
      std::vector<dealii::Tensor<1, dim>>                load_per_point; ///< per load, at t
      /// The body force per unit mass at the step's start t, g - a_g(t) d (begin_step()).
      dealii::Tensor<1, dim>                             body_acceleration;
      /// With a ground motion: per probe, the relative acceleration (v_p' - v_p) / dt of
      /// its point in the last step on the rank that took the step for it, zero on the
      /// others (partial sums, as the tables take them); empty without a ground motion.
      std::vector<dealii::Tensor<1, dim>>                probe_acceleration;
      void
      record_probe_accelerations(const double dt);
      std::vector<double>                                load_scale;     ///< 1 / count or area
      std::vector<std::vector<double>>                   particle_load_area;

      // Nodes touched this step (their stamp is the step number).
      std::vector<unsigned int> active_nodes;
      ZeroPages<unsigned int>   node_stamp;
      ZeroPages<unsigned int>   rigid_node_body; ///< 1 + rigid body index at a node, 0 none
      std::vector<unsigned int> rigid_nodes;
      unsigned int              stamp = 0;

      // Per step scratch: the strain increments of one chunk of points.
      static constexpr unsigned int                stress_chunk = 256;
      std::vector<dealii::SymmetricTensor<2, dim>> strain_increment =
        std::vector<dealii::SymmetricTensor<2, dim>>(stress_chunk);
      std::vector<double> hoop_increment = std::vector<double>(stress_chunk); ///< axisymmetric
      /// Jaumann: the rotation of each point's tensor state over the step (of one chunk).
      std::vector<dealii::Tensor<2, dim>> state_rotation = std::vector<dealii::Tensor<2, dim>>(stress_chunk);

      /// Axisymmetric: the hoop stress sigma_tt of point p (of a deformable group) in @p state.
      double
      hoop_stress(const typename ParticleStore<dim>::Group &group,
                  const unsigned int                        p,
                  const typename ParticleStore<dim>::State &state) const
      {
        double eps_zz = 0, sigma_tt = 0;
        group.material->out_of_plane(
          state.strain[p],
          state.stress[p],
          dealii::ArrayView<const double>(state.material_state.data() + group.state_offset +
                                            std::size_t(p - group.begin) * group.n_state,
                                          group.n_state),
          eps_zz,
          sigma_tt);
        return sigma_tt;
      }

      /// Axisymmetric: V_p sigma_tt / r_p, the hoop part of the internal force of
      /// point p (acting on its nodes with N_ip along -e_r); r_p at the step's start.
      double
      hoop_force(const typename ParticleStore<dim>::Group &group,
                 const unsigned int                        p,
                 const typename ParticleStore<dim>::State &state) const
      {
        return state.volume[p] * hoop_stress(group, p, state) / particles.current.x[p][0];
      }

      // Diagnostics of the last step.
      double       max_speed            = 0; ///< max_p (c_p + |v_p|)
      double       internal_work        = 0; ///< sum V sigma : d eps (this rank)
      double       external_work        = 0; ///< gravity and loads (this rank)
      double       boundary_work        = 0; ///< reactions times prescribed velocities (owned nodes)
      double       kinetic_energy       = 0; ///< of the deformable points after the step (this rank)
      double       initial_kinetic_energy = 0; ///< of the deformable points at t = 0 (all ranks)
      std::vector<dealii::Tensor<1, dim>> reactions; ///< per boundary, then per rigid body
      std::vector<dealii::Tensor<1, dim>> reactions_at_t; ///< of the state t during a step
      long         failed_point         = -1;
      std::string  failure;
      unsigned int n_changed_cells      = 0;
      bool         left_subdomain       = false;

      // Bookkeeping.
      /// The update scheme (`MPM/Scheme`) and the phases of the chosen basis it calls.
      std::unique_ptr<UpdateScheme<dim>> update_scheme;
      std::unique_ptr<StepPhases<dim>>   phases;
      /// Whether the nodes hold momenta p_i (after a transfer) or velocities v_i.
      bool nodes_hold_momenta = true;
      unsigned int                                  n_rebuilds = 0;
      PointData::Tables<dim>                        tables;
      std::vector<std::string>                      state_names;
      std::vector<unsigned int>                     group_of_body;
      std::vector<std::vector<dealii::Point<dim>>>  body_points; ///< set-up only
      /// --resume: this rank's points as the checkpoint holds them, by block (set-up to load()).
      std::map<std::array<unsigned int, dim>, std::vector<char>> resumed_points;
      std::vector<typename ParticleStore<dim>::Group> group_templates;
      unsigned int                                  current_group_key = 0;
      unsigned int                                  n_properties      = 0;
      std::vector<unsigned long>                    load_count; ///< points per load (index 0: none)
      std::vector<double>                           load_volume; ///< their volume (a force's share)
      dealii::types::particle_index                 n_global_particles = 0;
    };



    /// The phases of the step with the basis @p Basis, with or without contact
    /// (instantiated in step_linear.cc, step_cubic.cc and their *_contact.cc).
    template <int dim, typename Basis, bool with_contact>
    std::unique_ptr<StepPhases<dim>>
    make_step_phases(Solver<dim> &solver);
  } // namespace MPM
} // namespace hysteron

#endif
