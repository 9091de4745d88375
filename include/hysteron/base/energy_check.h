#ifndef hysteron_base_energy_check_h
#define hysteron_base_energy_check_h

namespace hysteron
{
  /**
   * The divergence test of the explicit schemes (FEM central differences, MPM): in a
   * physical motion the kinetic energy plus the internal work (strain energy +
   * dissipation) equals the energy put in (initial kinetic energy, work of loads,
   * boundaries and rigid bodies). An unstable step grows it without bound while the
   * values stay finite for many steps; stable runs stay within a few per cent of the
   * input, so twice the input is a clear sign of divergence.
   */
  inline bool
  energy_diverged(const double kinetic_plus_internal_work, const double energy_put_in)
  {
    return energy_put_in > 0 && kinetic_plus_internal_work > 2 * energy_put_in;
  }
} // namespace hysteron

#endif
