#ifndef hysteron_material_linear_elastic_h
#define hysteron_material_linear_elastic_h

#include <hysteron/material/interface.h>

namespace hysteron
{
  namespace Material
  {
    /**
     * Hooke's law sigma = C : eps for the stress state of the scene
     * (plane stress, plane strain, 3D). No state.
     */
    template <int dim>
    class LinearElastic : public Interface<dim>
    {
    public:
      void
      update(const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
             const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
             const dealii::ArrayView<double>                                &states,
             const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents) const override;

      /// Linear springs.
      SpringBehaviour
      spring_behaviour() const override
      {
        return {SpringBehaviour::Type::linear_elastic, nullptr};
      }

    protected:
      void
      parse_parameters(const Section &section) override;

    private:
      dealii::SymmetricTensor<4, dim> stiffness;
    };
  } // namespace Material
} // namespace hysteron

#endif
