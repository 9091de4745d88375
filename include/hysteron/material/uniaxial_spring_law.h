#ifndef hysteron_material_uniaxial_spring_law_h
#define hysteron_material_uniaxial_spring_law_h

#include <string>

namespace hysteron
{
  namespace Material
  {
    struct BoucWenParameters;
    class BoucWenUniaxial;

    /**
     * A uniaxial law F(delta) with a per-spring state, which a material offers for the
     * springs of a spring network between its cells (Interface::uniaxial_spring_law();
     * the RBSN's `uncoupled` spring law drives every spring of a facet with it). A spring
     * has its elastic stiffness k (dF / d delta = k while elastic) and yield value F_y;
     * the network derives F_y from yield_stress() and the facet's section (2D
     * sigma_y t l for the normal spring, see RBSN::FacetSprings::yield_values), so the
     * law itself is written in (k, F_y) only: a law for stresses (E, sigma_y) is the same
     * law with k = E, F_y = sigma_y.
     *
     * One object holds the constants of the springs it has been given (add_spring(),
     * numbered 0, 1, ... in that order); the caller stores their states
     * (n_state_variables() doubles each) and commits or discards trial states.
     */
    class UniaxialSpringLaw
    {
    public:
      virtual ~UniaxialSpringLaw() = default;

      /// The yield stress sigma_y [Pa] that the network scales to the springs' yield values.
      virtual double
      yield_stress() const = 0;

      /// Whether the springs are linear, F = k delta with no state (the network then
      /// integrates them itself and never calls update()).
      virtual bool
      linear() const
      {
        return false;
      }

      /// The doubles of state per spring.
      virtual unsigned int
      n_state_variables() const = 0;

      /// A new spring of stiffness @p k and yield value @p yield_value; its virgin state
      /// into @p state. Returns its number.
      virtual unsigned int
      add_spring(double k, double yield_value, double *state) = 0;

      /**
       * Advance the springs first, ..., first + n - 1 (one call per facet) by
       * increment[i]: force[i] holds the converged force on entry, the trial force on
       * exit; spring first + i has its state at state + i n_state_variables(); @p tangent
       * is null or receives dF_i / d delta_i, the derivative of this update, at
       * tangent[i tangent_stride]. Every spring is advanced even if one fails; returns n,
       * or the index i of the last spring that failed with its cause in @p failure.
       */
      virtual unsigned int
      update(unsigned int first,
             unsigned int n,
             const double *increment,
             double       *force,
             double       *state,
             double       *tangent,
             unsigned int  tangent_stride,
             std::string  &failure) const = 0;

      /// The yield indicator of spring @p spring (0 elastic ... 1 yielding; the H1 output).
      virtual double
      h1(unsigned int spring, const double *state) const = 0;

      /// The recoverable energy of spring @p spring at deformation @p delta and @p state.
      virtual double
      strain_energy(unsigned int spring, double delta, const double *state) const = 0;

      /// Whether the law uses the springs' yield values (OpenSees' BoucWen does not: its
      /// yield deformation follows from its own parameters), so that a host which scales
      /// them (the RBSN's facets, an inelastic spectrum's strength) may use it.
      virtual bool
      scales_with_yield_value() const
      {
        return true;
      }

      /// The hysteretic variable z of spring @p spring (in the units of its deformation),
      /// for output; 0 for a law without one.
      virtual double
      hysteretic_variable(unsigned int spring, const double *state) const
      {
        (void)spring;
        (void)state;
        return 0;
      }

      /// A Bouc-Wen law's parameters (spring laws that are Bouc-Wen by nature, the
      /// coupled interaction surface, ask for them), else null.
      virtual const BoucWenParameters *
      bouc_wen_parameters() const
      {
        return nullptr;
      }

      /// A Bouc-Wen law's uniaxial kernel of spring @p spring (the RBSN's variable-order
      /// analysis integrates its rates), else null.
      virtual const BoucWenUniaxial *
      bouc_wen(unsigned int spring) const
      {
        (void)spring;
        return nullptr;
      }
    };
  } // namespace Material
} // namespace hysteron

#endif
