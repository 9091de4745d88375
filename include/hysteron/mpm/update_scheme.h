#ifndef hysteron_mpm_update_scheme_h
#define hysteron_mpm_update_scheme_h

#include <hysteron/base/registry.h>

namespace hysteron
{
  namespace MPM
  {
    /**
     * The phases of one explicit MPM step, provided by the solver. A phase is
     * one pass over the material points or the active grid nodes; the solver
     * implements each one as a kernel of the grid's basis (chosen once, at
     * set-up), so a call here is one virtual call per phase and step and the
     * loops inside are as fast as a hand-written step.
     *
     * Notation: point p with mass m_p, volume V_p, velocity v_p, stress
     * sigma_p; grid node i with shape function N_i and N_ip = N_i(x_p) at the
     * point positions of the step's start; every node stores its mass m_i, a
     * vector q_i (the momentum p_i after a transfer to the grid, the velocity
     * v_i after nodal_velocities() or update_nodal_velocities()) and a vector
     * f_i (the force, then the velocity change over the step).
     */
    template <int dim>
    class StepPhases
    {
    public:
      virtual ~StepPhases() = default;

      /// Whose stress the internal forces of forces_to_grid() come from.
      enum class Stress
      {
        current, ///< sigma_p, V_p of the step's start
        updated  ///< the stresses and volumes of update_stresses() in this step
      };

      /// Which nodal velocities update_stresses() takes for L_p = sum_i v_i (x) grad N_ip.
      enum class Velocity
      {
        current, ///< the nodal velocities the nodes hold now
        midpoint ///< v_i - Delta v_i / 2: the mean of the velocities before and after update_nodal_velocities()
      };

      /**
       * P2G, the first phase of every step: m_i = sum_p N_ip m_p and
       * p_i = sum_p N_ip m_p v_p; with @p forces also, in the same pass, the
       * force f_i = sum_p N_ip (m_p g + f_p) - sum_p V_p sigma_p grad N_ip of the
       * stresses of the step's start. The nodes then hold momenta.
       */
      virtual void
      particles_to_grid(const bool forces) = 0;

      /// P2G of the forces alone (f_i as above) from the stresses @p stress.
      virtual void
      forces_to_grid(const Stress stress) = 0;

      /// Momenta to velocities: v_i = p_i / m_i (0 at nodes without mass).
      virtual void
      nodal_velocities() = 0;

      /**
       * The momentum balance: Delta v_i = dt f_i / m_i, v_i' = v_i + Delta v_i
       * (from p_i / m_i if the nodes still hold momenta). The nodes keep
       * Delta v_i for the FLIP update of the points.
       */
      virtual void
      update_nodal_velocities(const double dt) = 0;

      /**
       * The boundary conditions and rigid bodies at time @p t on the nodal
       * velocities; with @p record the imposed change joins Delta v_i and the
       * reactions and the boundary work are recorded (once per step).
       */
      virtual void
      boundary_conditions(const double t, const double dt, const bool record) = 0;

      /**
       * G2P: v_p' = alpha (v_p + sum_i N_ip Delta v_i) + (1 - alpha) sum_i N_ip v_i',
       * x_p' = x_p + dt sum_i N_ip v_i', the kinetic energy, the external work
       * and the critical speed. Returns false if the step failed (a point left
       * the grid, a non-finite velocity); the scheme must then return.
       */
      virtual bool
      grid_to_particles(const double t, const double dt) = 0;

      /// MUSL: the momenta again, p_i = sum_p N_ip m_p v_p', from the updated point velocities.
      virtual void
      remap_momenta() = 0;

      /**
       * L_p = sum_i v_i (x) grad N_ip with the nodal velocities @p velocity,
       * d eps = sym(L_p) dt, F' = (I + dt L_p) F, V' = det F' V_0, and the
       * material's stress and state update (with the Jaumann rotation if chosen).
       * Returns false if a stress is not finite; the scheme must then return.
       */
      virtual bool
      update_stresses(const double dt, const Velocity velocity) = 0;

      /**
       * The stresses and volumes after @p dt from the current nodal velocities
       * (as update_stresses(dt, Velocity::current)), for the forces of
       * forces_to_grid(Stress::updated) only: the internal work is not
       * recorded, and the step's update_stresses() replaces them (it starts
       * from the step's start again). Returns false if a stress is not finite.
       */
      virtual bool
      predict_stresses(const double dt) = 0;
    };



    /**
     * An MPM update scheme (`MPM/Scheme`): the order of the phases of one step,
     * chosen once at set-up. Adding one takes one class and one registration
     * line (see doc/mpm.md):
     *
     *   template <int dim>
     *   class USL : public MPM::UpdateScheme<dim>
     *   {
     *   public:
     *     void step(MPM::StepPhases<dim> &phases, double t, double dt) const override
     *     {
     *       phases.particles_to_grid(true);
     *       phases.update_nodal_velocities(dt);
     *       phases.boundary_conditions(t + dt, dt, true);
     *       if (phases.grid_to_particles(t, dt))
     *         phases.update_stresses(dt, MPM::StepPhases<dim>::Velocity::current);
     *     }
     *   };
     *   HYSTERON_REGISTER_MPM_SCHEME(USL, "USL", "update stress last")
     *
     * A step must begin with particles_to_grid(), apply the boundary conditions
     * at t + dt with record = true exactly once, call grid_to_particles() once
     * and update the stresses once.
     */
    template <int dim>
    class UpdateScheme
    {
    public:
      virtual ~UpdateScheme() = default;

      /// Parameters of the scheme, in `subsection MPM` (optional; names must not clash).
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /// One step from @p t to @p t + @p dt.
      virtual void
      step(StepPhases<dim> &phases, const double t, const double dt) const = 0;
    };

    template <int dim>
    using SchemeRegistry = Plugins::Registry<UpdateScheme<dim>>;
  } // namespace MPM
} // namespace hysteron

/// Register the MPM update scheme class template @p classname (dim = 2, 3) under @p name.
#define HYSTERON_REGISTER_MPM_SCHEME(classname, name, description) \
  HYSTERON_REGISTER_DIM_PLUGIN(::hysteron::MPM::UpdateScheme, classname, name, description)

#endif
