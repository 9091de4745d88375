#include <hysteron/material/linear_elastic.h>

namespace hysteron
{
  namespace Material
  {
    template <int dim>
    void
    LinearElastic<dim>::parse_parameters(const Section &)
    {
      stiffness = this->elasticity().template stiffness<dim>();
    }

    template <int dim>
    void
    LinearElastic<dim>::update(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double> &,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents) const
    {
      for (std::size_t p = 0; p < strain_increments.size(); ++p)
        stresses[p] += stiffness * strain_increments[p];
      for (auto &t : tangents)
        t = stiffness;
    }

    template class LinearElastic<2>;
    template class LinearElastic<3>;
  } // namespace Material
} // namespace hysteron

HYSTERON_REGISTER_MATERIAL(hysteron::Material::LinearElastic,
                           "linear elastic",
                           "Hooke's law sigma = C : eps (isotropic; plane stress, plane strain "
                           "or 3D). No internal variables.")
