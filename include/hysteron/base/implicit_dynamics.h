#ifndef hysteron_base_implicit_dynamics_h
#define hysteron_base_implicit_dynamics_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>

namespace hysteron
{
  /**
   * `subsection Dynamics` of an implicit method (FEM, RBSN): HHT-alpha time
   * integration (Newmark average acceleration for alpha = 0) and Rayleigh
   * damping C = a0 M + a1 K0.
   */
  struct ImplicitDynamicsParameters
  {
    double hht_alpha          = 0; ///< in [-1/3, 0]
    double rayleigh_mass      = 0; ///< a0 [1/s]
    double rayleigh_stiffness = 0; ///< a1 [s]

    /// Newmark's beta = (1 - alpha)^2 / 4 and gamma = 1/2 - alpha of the HHT scheme.
    double
    beta() const
    {
      return (1 - hht_alpha) * (1 - hht_alpha) / 4;
    }
    double
    gamma() const
    {
      return 0.5 - hht_alpha;
    }

    /**
     * The Newmark update of velocities and accelerations at the end of a step
     * with the displacement increment @p du:
     *   a1 = (du - dt v0) / (beta dt^2) - (1 - 2 beta) / (2 beta) a0,
     *   v1 = v0 + dt ((1 - gamma) a0 + gamma a1).
     */
    template <typename VectorType>
    void
    update(const VectorType &du, const double dt, VectorType &v, VectorType &a) const
    {
      const double b = beta(), g = gamma();
      VectorType   a_new = du;
      a_new.add(-dt, v);
      a_new *= 1 / (b * dt * dt);
      a_new.add(-(1 - 2 * b) / (2 * b), a);
      v.add(dt * (1 - g), a, dt * g, a_new);
      a = a_new;
    }

    /// Declare the entries in the current subsection.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(const Section &section);
  };
} // namespace hysteron

#endif
