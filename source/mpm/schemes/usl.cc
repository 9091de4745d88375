// USL, update stress last: the stresses of the step come from the nodal velocities
// at the step's end.
#include <hysteron/mpm/update_scheme.h>

namespace hysteron
{
  namespace MPM
  {
    /**
     * Update stress last (Sulsky, Chen and Schreyer 1994): forces from the
     * stresses of the step's start, the momentum balance on the nodes, the
     * points moved, and then the strain increment d eps = sym(sum_i v_i'
     * (x) grad N_ip) dt with the updated nodal velocities v_i'. Dissipates
     * energy slowly (the stress lags the velocity it works on).
     */
    template <int dim>
    class USL : public UpdateScheme<dim>
    {
    public:
      void
      step(StepPhases<dim> &phases, const double t, const double dt) const override
      {
        phases.particles_to_grid(true);
        phases.update_nodal_velocities(dt);
        phases.boundary_conditions(t + dt, dt, true);
        if (phases.grid_to_particles(t, dt))
          phases.update_stresses(dt, StepPhases<dim>::Velocity::current);
      }
    };
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_MPM_SCHEME(hysteron::MPM::USL,
                             "USL",
                             "update stress last, from the updated nodal velocities")
