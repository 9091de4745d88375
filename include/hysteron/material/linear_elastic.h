#ifndef hysteron_material_linear_elastic_h
#define hysteron_material_linear_elastic_h

#include <hysteron/material/interface.h>

namespace hysteron
{
  namespace Material
  {
    /**
     * Hooke's law sigma = C : eps for the stress state of the scene
     * (plane stress, plane strain, axisymmetric, 3D). No state, except the hoop
     * stress sigma_tt of an axisymmetric model (named sigma_zz like the plane-strain
     * out-of-plane stress), which is not a function of the in-plane stress there.
     */
    template <int dim>
    class LinearElastic : public Interface<dim>
    {
    public:
      unsigned int
      n_state_variables() const override
      {
        return axisymmetric() ? 1 : 0;
      }

      std::vector<std::string>
      state_variable_names() const override
      {
        return axisymmetric() ? std::vector<std::string>{"sigma_zz"} : std::vector<std::string>();
      }

      bool
      has_symmetric_tangent() const override
      {
        return true;
      }

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

      /// Axisymmetric: the hoop stress from the state; otherwise the elastic relation.
      void
      out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                   const dealii::SymmetricTensor<2, dim> &stress,
                   const dealii::ArrayView<const double> &state,
                   double                                &eps_zz,
                   double                                &sigma_zz) const override;

      void
      update(const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
             const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
             const dealii::ArrayView<double>                                &states,
             const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents) const override;

      /// Linear springs, F = k delta.
      std::unique_ptr<UniaxialSpringLaw>
      uniaxial_spring_law() const override;

    protected:
      void
      parse_parameters(const Section &section) override;

    private:
      bool
      axisymmetric() const
      {
        return this->elasticity().stress_state == StressState::axisymmetric;
      }

      dealii::SymmetricTensor<4, dim> stiffness;
    };
  } // namespace Material
} // namespace hysteron

#endif
