// MUSL, modified update stress last: the stresses come from nodal velocities
// mapped back from the updated points.
#include <hysteron/mpm/update_scheme.h>

namespace hysteron
{
  namespace MPM
  {
    /**
     * Modified update stress last (Sulsky, Zhou and Schreyer 1995): as USL, but after the points are updated the nodal
     * velocities are computed again from the new point momenta,
     * v_i = sum_p N_ip m_p v_p' / m_i (with the boundary conditions), and the
     * strain increment uses these. The remap filters the velocity modes the
     * grid cannot carry, so nodes with little mass do not produce spurious
     * strains.
     */
    template <int dim>
    class MUSL : public UpdateScheme<dim>
    {
    public:
      void
      step(StepPhases<dim> &phases, const double t, const double dt) const override
      {
        phases.particles_to_grid(true);
        phases.update_nodal_velocities(dt);
        phases.boundary_conditions(t + dt, dt, true);
        if (!phases.grid_to_particles(t, dt))
          return;
        phases.remap_momenta();
        phases.nodal_velocities();
        phases.boundary_conditions(t + dt, dt, false);
        phases.update_stresses(dt, StepPhases<dim>::Velocity::current);
      }
    };
  } // namespace MPM
} // namespace hysteron

HYSTERON_REGISTER_MPM_SCHEME(hysteron::MPM::MUSL,
                             "MUSL",
                             "modified update stress last: after the points, from nodal velocities "
                             "remapped from them")
