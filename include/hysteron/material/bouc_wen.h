#ifndef hysteron_material_bouc_wen_h
#define hysteron_material_bouc_wen_h

#include <hysteron/material/bouc_wen_constants.h>
#include <hysteron/material/bouc_wen_family.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/interface.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    /**
     * The triaxial smooth Bouc-Wen law (dissertation §2.5-2.6, eq. 2.8-2.47, §4.7):
     * von Mises plasticity with mixed hardening whose Kuhn-Tucker switches are
     * replaced by the smooth Bouc-Wen functions H1 = |q/sigma_y|^n and
     * H2 = beta + gamma sgn(n : D : eps'), with optional stiffness degradation
     * (eta) and strength deterioration (nu_s). Registered as "bouc-wen".
     *
     * Rate equations (tensor inner products, eps' the strain rate):
     *   q = sqrt(3/2 dev(sigma - alpha) : dev(sigma - alpha)),  n = 3/2 dev(sigma - alpha) / q,
     *   sigma_y = sigma_y0 + m H' eps_ps,  H' = a E / (1 - a),  C_p = 2/3 H',
     *   lambda1 = 1 / ((1 - m) 3/2 C_p + m H' + n : D : n) = 1 / (H' + n : D : n),
     *   lambda'  = nu_s H1 H2 lambda1 (n : D : eps') / eta,
     *   sigma'   = D : (eps' / eta - lambda' n),      eps_p' = lambda' n,
     *   alpha'   = (1 - m) C_p eps_p',   eps_ps' = |lambda'|,   e_h' = sigma : eps_p',
     *   eta' = c_eta eta^(-m_u) eps_ps',   nu_s = 1 + c_nu e_h / (sigma_y0 eps_y).
     * The stress rate is eq. 2.46: sigma' = (1/eta) D (I - nu_s H1 H2 R) eps'. See
     * source/material/bouc_wen_kernels.h for the derivations, the integrators and the state layout.
     *
     * Stress states: 3D (full tensors), plane strain (the 3D law with eps_zz' = 0;
     * sigma_zz is carried in the state), axisymmetric (the same with eps_zz' the hoop
     * strain rate u_r' / r) and plane stress (reduced xx, yy, xy forms
     * with the plane-stress stiffness; the zz components of the plastic strain and
     * back stress follow from plastic incompressibility).
     *
     * Integrators (`Integrator`): forward Euler (one rate evaluation per increment,
     * the dissertation's Fig. 4.18 with eq. 4.51), adaptive (Bogacki-Shampine 3(2)
     * with error control) and backward Euler (local Newton, consistent tangent).
     *
     * State (tensor components, in this order; F = xx, yy, zz, xy, yz, xz in 3D and
     * xx, yy, zz, xy in 2D):
     *   H1, H2, eps_ps, epsp_F,
     *   alpha_F     if m < 1 (alpha = (1 - m) C_p eps_p, written for output),
     *   sigma_zz    in plane strain,
     *   e_h, eta, nu_s   with degradation (eta and nu_s follow from eps_ps and e_h),
     *   epsilon_zz  in plane stress with degradation (eps_zz is then path dependent).
     * H1 and H2 are those of the end of the last increment (H2 of its direction).
     */
    template <int dim>
    class BoucWen : public Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      unsigned int
      n_state_variables() const override
      {
        return names.size();
      }

      std::vector<std::string>
      state_variable_names() const override
      {
        return names;
      }

      void
      initialize_state(const dealii::ArrayView<double> &state) const override;

      void
      update(const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
             const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
             const dealii::ArrayView<double>                                &states,
             const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents) const override;

      bool
      supports_axisymmetry() const override
      {
        return true;
      }

      void
      update_axisymmetric(
        const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
        const dealii::ArrayView<const double>                          &hoop_increments,
        const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
        const dealii::ArrayView<double>                                &states,
        const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
        const dealii::ArrayView<HoopTangent<dim>> &hoop_tangents) const override;

      /// Plane stress: eps_zz from the state; plane strain: sigma_zz from the state.
      void
      out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                   const dealii::SymmetricTensor<2, dim> &stress,
                   const dealii::ArrayView<const double> &state,
                   double                                &eps_zz,
                   double                                &sigma_zz) const override;

      /// Turns the plastic strain and the back stress (see Interface::rotate_state()).
      void
      rotate_state(const dealii::Tensor<2, dim> &R, const dealii::ArrayView<double> &state) const override;

      /// The backward Euler integrator returns the algorithmic tangent; the explicit ones E_t.
      bool
      has_consistent_tangent() const override
      {
        return parameters.integrator == BoucWenIntegrator::backward_euler;
      }

      const BoucWenParameters &
      get_parameters() const
      {
        return parameters;
      }

      /// The springs of `Uniaxial law`: BoucWenUniaxial with these parameters (smooth) or
      /// a law of the wider family (create_bouc_wen_variant()).
      std::unique_ptr<UniaxialSpringLaw>
      uniaxial_spring_law() const override;

      /// Refuses a continuum use of a `Uniaxial law` other than smooth.
      std::string
      continuum_unsupported() const override;

      const BoucWenFamilyParameters &
      get_family_parameters() const
      {
        return family;
      }

    protected:
      void
      parse_parameters(const Section &section) override;

    private:
      /// update() and update_axisymmetric(): @p hoop_increments null or n values.
      void
      update_batch(
        const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
        const double                                                   *hoop_increments,
        const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
        const dealii::ArrayView<double>                                &states,
        const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
        const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const;

      BoucWenParameters         parameters;
      BoucWenFamilyParameters   family;
      BoucWenKernels::Constants constants;
      StressState               stress_state = StressState::three_dimensional;
      bool                      kinematic    = false;
      bool                      degrading    = false;
      std::vector<std::string>  names;
      /// Slots read by out_of_plane() (numbers::invalid_unsigned_int if absent).
      unsigned int slot_sigma_zz = static_cast<unsigned int>(-1);
      unsigned int slot_eps_zz   = static_cast<unsigned int>(-1);
      unsigned int slot_epsp_zz  = static_cast<unsigned int>(-1);
      /// The first of the tensor components (xx, yy, zz, xy(, yz, xz)) of eps_p and of alpha.
      unsigned int slot_epsp     = static_cast<unsigned int>(-1);
      unsigned int slot_alpha    = static_cast<unsigned int>(-1);
      unsigned int slot_eta      = static_cast<unsigned int>(-1);
      unsigned int slot_nu_s     = static_cast<unsigned int>(-1);
    };
  } // namespace Material
} // namespace hysteron

#endif
