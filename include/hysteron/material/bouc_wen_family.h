#ifndef hysteron_material_bouc_wen_family_h
#define hysteron_material_bouc_wen_family_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/uniaxial_spring_law.h>

#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    /// The uniaxial laws a Bouc-Wen material offers its springs (`Bouc-Wen/Uniaxial law`).
    enum class UniaxialVariant
    {
      smooth,                    ///< the project's law (BoucWenUniaxial), the default
      pinching,                  ///< Baber-Noori pinching with Foliente's parameters (BWBN)
      asymmetric,                ///< the smooth law with a yield value of its own in compression
      opensees_bouc_wen,         ///< OpenSees' `BoucWen` (Haukaas), its parameters and update
      opensees_bouc_wen_original ///< OpenSees' `BoucWenOriginal` (Schellenberg)
    };

    /**
     * The wider Bouc-Wen family as uniaxial laws (doc/theory.md, "The Bouc-Wen family"):
     * the parameters of `subsection Material / subsection Bouc-Wen / set Uniaxial law`
     * and its subsections. Each variant is a law F(delta) of a spring with stiffness k and
     * yield value y from its host (the uniaxial bench: k = E, y = sigma_y; the oscillator:
     * a storey's stiffness and yield force; the RBSN: a facet spring's), integrated like
     * OpenSees integrates them: one implicit (backward Euler) step per increment,
     *
     *   z_1 = z_0 + Delta g(z_1, e_1),   e_1 = e_0 + c Delta z_1,
     *
     * with g = dz/d delta of the variant and e its energy measure, solved to round-off
     * by a safeguarded Newton iteration; the tangent is the derivative of this update.
     */
    struct BoucWenFamilyParameters
    {
      UniaxialVariant variant = UniaxialVariant::smooth;

      /// Shared by the pinching, asymmetric and OpenSees BoucWen laws: the post-yield
      /// ratio alpha, the exponent n and the two shape factors. The pinching and OpenSees
      /// laws follow Foliente's and OpenSees' naming: beta multiplies sgn(z ddelta),
      /// gamma is the constant term (the other way round from the smooth law's).
      double alpha = 0, n = 1, beta = 0.5, gamma = 0.5;
      /// Degradation of A, nu, eta with the energy e (pinching, OpenSees BoucWen).
      double A0 = 1, delta_A = 0, delta_nu = 0, delta_eta = 0;
      /// Pinching: zeta_s, p, q, psi_0, delta_psi, lambda.
      double zeta_s = 0, p = 0, q = 0, psi0 = 0.1, delta_psi = 0, lambda = 0.5;
      /// Asymmetric: the yield value in compression over that in tension.
      double compression_ratio = 1;
      /// OpenSees BoucWenOriginal: alphaL, alphaNL, mu (eta is n, beta and gamma shared).
      double alpha_L = 0, alpha_NL = 0, mu = 2;

      /// Declare `Uniaxial law` and the subsections (inside `subsection Bouc-Wen`).
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      /// Read from @p bouc_wen (the `Bouc-Wen` section); the asymmetric law takes a, n,
      /// beta and gamma of the smooth law @p smooth.
      void
      parse_parameters(const Section &bouc_wen, const BoucWenParameters &smooth);

      /// The variant's name as in the parameter file.
      std::string
      name() const;
    };

    /// A new uniaxial spring law of the variant in @p parameters (not the smooth one),
    /// with sigma_y = @p yield_stress for the network's yield values.
    std::unique_ptr<UniaxialSpringLaw>
    create_bouc_wen_variant(const BoucWenFamilyParameters &parameters, double yield_stress);
  } // namespace Material
} // namespace hysteron

#endif
