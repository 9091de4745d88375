#ifndef hysteron_material_bouc_wen_parameters_h
#define hysteron_material_bouc_wen_parameters_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    /// How the Bouc-Wen rate equations are integrated over one strain increment.
    enum class BoucWenIntegrator
    {
      forward_euler,  ///< one evaluation per step (the dissertation's scheme)
      adaptive,       ///< embedded explicit Runge-Kutta sub-stepping with error control
      backward_euler  ///< implicit, local Newton, consistent algorithmic tangent
    };

    /**
     * Parameters of the smooth Bouc-Wen law, shared by the uniaxial law
     * (springs, 1D) and the triaxial von Mises law. Convention (doc/theory.md):
     *   z' = eps' / eta [1 - nu_s |z/z_y|^n (beta + gamma sgn(z eps'))],
     * gamma multiplies the sign term; admissible: -beta <= gamma <= beta, beta + gamma > 0
     * (beta + gamma = 1 for z_y to be the saturation value).
     * (OpenSees' BoucWenMaterial names these the other way round.)
     *
     * Declared in `subsection Material / subsection Bouc-Wen`
     * (and `subsection Degradation` inside it).
     */
    struct BoucWenParameters
    {
      double yield_stress          = 235e6; ///< sigma_y [Pa] (F_y [N] for springs)
      double post_yield_ratio      = 0.0;   ///< a in [0, 1)
      double smoothness            = 8.0;   ///< n > 0
      double beta                  = 0.5;
      double gamma                 = 0.5;
      double isotropic_fraction    = 1.0;   ///< m in [0, 1]: 1 isotropic, 0 kinematic
      BoucWenIntegrator integrator = BoucWenIntegrator::adaptive;
      double tolerance             = 1e-6;  ///< adaptive: local error; backward Euler: Newton
      double stiffness_degradation_c_eta = 0.0; ///< c_eta >= 0
      double stiffness_degradation_m_u   = 1.0; ///< m_u >= 0
      double strength_deterioration_c_nu = 0.0; ///< c_nu >= 0

      bool
      degradation() const
      {
        return stiffness_degradation_c_eta > 0 || strength_deterioration_c_nu > 0;
      }

      /// Declare the entries (inside `subsection Material`).
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      /// Read and validate from @p material (the `Material` section); returns warnings (a
      /// yield strain sigma_y / E below 1e-7 or above 5 %: units?, beta + gamma != 1,
      /// n < 1) for the caller to print.
      std::vector<std::string>
      parse_parameters(const Section &material);
    };
  } // namespace Material
} // namespace hysteron

#endif
