#ifndef hysteron_material_elasticity_h
#define hysteron_material_elasticity_h

#include <deal.II/base/symmetric_tensor.h>

#include <string>

namespace hysteron
{
  namespace Material
  {
    /**
     * How a two-dimensional model relates to the third direction.
     * plane stress: sigma_zz = sigma_xz = sigma_yz = 0, eps_zz follows from the law;
     * plane strain: eps_zz = eps_xz = eps_yz = 0, sigma_zz follows from the law;
     * axisymmetric: x is the radius r >= 0, y the axis and z the hoop direction t;
     * eps_tt = u_r / r is given by the kinematics (eps_rt = eps_zt = 0), sigma_tt
     * follows from the law; the in-plane stiffness is that of plane strain.
     * Three-dimensional models always use three_dimensional.
     */
    enum class StressState
    {
      plane_stress,
      plane_strain,
      three_dimensional,
      axisymmetric
    };

    std::string
    to_string(StressState state);

    /**
     * Isotropic linear elasticity: E, nu, density and the stress state.
     * In 2D the in-plane law is sigma = lambda_eff tr(eps) I + 2 mu eps with
     * lambda_eff = lambda (plane strain) or 2 lambda mu / (lambda + 2 mu) = E nu / (1 - nu^2)
     * (plane stress, from sigma_zz = 0 eliminating eps_zz).
     */
    struct Elasticity
    {
      double      youngs_modulus  = 1.0;
      double      poissons_ratio  = 0.0;
      double      density         = 1.0;
      StressState stress_state    = StressState::three_dimensional;

      /// mu = E / (2 (1 + nu)).
      double
      shear_modulus() const
      {
        return youngs_modulus / (2.0 * (1.0 + poissons_ratio));
      }

      /// The three-dimensional lambda = E nu / ((1 + nu)(1 - 2 nu)).
      double
      lame_lambda() const
      {
        return youngs_modulus * poissons_ratio /
               ((1.0 + poissons_ratio) * (1.0 - 2.0 * poissons_ratio));
      }

      /// lambda of the in-plane law (see the class documentation).
      double
      effective_lambda() const
      {
        if (stress_state == StressState::plane_stress)
          return youngs_modulus * poissons_ratio / (1.0 - poissons_ratio * poissons_ratio);
        return lame_lambda();
      }

      /// The P-wave (constrained) modulus lambda_eff + 2 mu; E / (1 - nu^2) in plane stress.
      double
      p_wave_modulus() const
      {
        return effective_lambda() + 2.0 * shear_modulus();
      }

      /// sqrt(M / rho): the speed that bounds explicit time steps (eq. 4.47).
      double
      p_wave_speed() const;

      /// The elasticity tensor lambda_eff I (x) I + 2 mu S of the stress state.
      template <int dim>
      dealii::SymmetricTensor<4, dim>
      stiffness() const
      {
        const double lambda = effective_lambda();
        const double mu     = shear_modulus();
        return lambda * dealii::outer_product(dealii::unit_symmetric_tensor<dim>(),
                                              dealii::unit_symmetric_tensor<dim>()) +
               2.0 * mu * dealii::identity_tensor<dim>();
      }
    };
  } // namespace Material
} // namespace hysteron

#endif
