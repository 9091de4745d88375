// USF, update stress first: the stresses come from the nodal velocities of the
// step's start, and the forces from the updated stresses.
#include <hysteron/mpm/update_scheme.h>

namespace hysteron
{
  namespace MPM
  {
    /**
     * Update stress first (Bardenhagen 2002): mass and momentum to the grid,
     * v_i = p_i / m_i with the boundary conditions at t, the strain increment
     * and the stresses from these velocities, then the forces from the updated
     * stresses, the momentum balance and the points. Gains energy slowly (the
     * stress leads the velocity it works on).
     */
    template <int dim>
    class USF : public UpdateScheme<dim>
    {
    public:
      void
      step(StepPhases<dim> &phases, const double t, const double dt) const override
      {
        phases.particles_to_grid(false);
        phases.nodal_velocities();
        phases.boundary_conditions(t, dt, false);
        if (!phases.update_stresses(dt, StepPhases<dim>::Velocity::current))
          return;
        phases.forces_to_grid(StepPhases<dim>::Stress::updated);
        phases.update_nodal_velocities(dt);
        phases.boundary_conditions(t + dt, dt, true);
        phases.grid_to_particles(t, dt);
      }
    };
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_MPM_SCHEME(hysteron::MPM::USF,
                             "USF",
                             "update stress first, from the nodal velocities of the step's start")
