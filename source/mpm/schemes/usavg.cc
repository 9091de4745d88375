// USAVG, update stress average: the strain increment of a step is the mean of the
// USF and the USL increments.
#include <hysteron/mpm/update_scheme.h>

namespace hysteron
{
  namespace MPM
  {
    /**
     * Update stress average (after Wallstedt and Guilkey 2008): the strain
     * increment of the step is taken with the mean nodal velocity
     * (v_i(t) + v_i(t + dt)) / 2 = v_i' - Delta v_i / 2, the average of the USF
     * and the USL increments (a trapezoidal rule for d eps / dt over the step).
     * The forces come from the stresses at the middle of the step, predicted
     * with the USF velocities over dt / 2, so that for linear elasticity the
     * step is the Stoermer-Verlet (leapfrog) scheme with the stress as the
     * position: it conserves a modified energy instead of gaining or losing
     * energy in proportion to dt. Derivation in doc/mpm.md.
     */
    template <int dim>
    class USAVG : public UpdateScheme<dim>
    {
    public:
      void
      step(StepPhases<dim> &phases, const double t, const double dt) const override
      {
        phases.particles_to_grid(false);
        phases.nodal_velocities();
        phases.boundary_conditions(t, dt, false);
        if (!phases.predict_stresses(0.5 * dt))
          return;
        phases.forces_to_grid(StepPhases<dim>::Stress::updated);
        phases.update_nodal_velocities(dt);
        phases.boundary_conditions(t + dt, dt, true);
        if (phases.grid_to_particles(t, dt))
          phases.update_stresses(dt, StepPhases<dim>::Velocity::midpoint);
      }
    };
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_MPM_SCHEME(hysteron::MPM::USAVG,
                             "USAVG",
                             "update stress average: the mean of the USF and the USL strain "
                             "increments, forces from the stresses at mid-step (after Wallstedt and "
                             "Guilkey 2008)")
