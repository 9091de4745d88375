#include <hysteron/material/linear_elastic.h>

#include <limits>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      /// Linear springs F = k delta, without state and never yielding (sigma_y = inf).
      class LinearSprings : public UniaxialSpringLaw
      {
      public:
        double
        yield_stress() const override
        {
          return std::numeric_limits<double>::infinity();
        }

        bool
        linear() const override
        {
          return true;
        }

        unsigned int
        n_state_variables() const override
        {
          return 0;
        }

        unsigned int
        add_spring(const double k, const double, double *) override
        {
          stiffness.push_back(k);
          return stiffness.size() - 1;
        }

        unsigned int
        update(const unsigned int first,
               const unsigned int n,
               const double      *increment,
               double            *force,
               double            *,
               double            *tangent,
               const unsigned int tangent_stride,
               std::string &) const override
        {
          for (unsigned int i = 0; i < n; ++i)
            {
              force[i] += stiffness[first + i] * increment[i];
              if (tangent)
                tangent[i * tangent_stride] = stiffness[first + i];
            }
          return n;
        }

        double
        h1(const unsigned int, const double *) const override
        {
          return 0;
        }

        /// 1/2 k delta^2.
        double
        strain_energy(const unsigned int spring, const double delta, const double *) const override
        {
          return 0.5 * stiffness[spring] * delta * delta;
        }

      private:
        std::vector<double> stiffness;
      };
    } // namespace



    template <int dim>
    std::unique_ptr<UniaxialSpringLaw>
    LinearElastic<dim>::uniaxial_spring_law() const
    {
      return std::make_unique<LinearSprings>();
    }



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

    template <int dim>
    void
    LinearElastic<dim>::update_axisymmetric(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<const double>                          &hoop_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
      const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const
    {
      // With the hoop strain as the third normal component, sigma = lambda tr(eps) 1 +
      // 2 mu eps (3D): d sigma_ij += lambda d eps_tt delta_ij in plane, and
      // d sigma_tt = lambda (tr_2D d eps) + (lambda + 2 mu) d eps_tt.
      const double lambda = this->elasticity().lame_lambda();
      const double mu     = this->elasticity().shear_modulus();
      const auto   I      = dealii::unit_symmetric_tensor<dim>();
      AssertDimension(states.size(), strain_increments.size());
      for (std::size_t p = 0; p < strain_increments.size(); ++p)
        {
          stresses[p] += stiffness * strain_increments[p] + lambda * hoop_increments[p] * I;
          states[p] += lambda * dealii::trace(strain_increments[p]) +
                       (lambda + 2.0 * mu) * hoop_increments[p];
        }
      for (auto &t : tangents)
        t = stiffness;
      for (auto &h : hoop_tangents)
        {
          h.stress_by_hoop = lambda * I;
          h.hoop_by_strain = lambda * I;
          h.hoop_by_hoop   = lambda + 2.0 * mu;
        }
    }

    template <int dim>
    void
    LinearElastic<dim>::out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                                     const dealii::SymmetricTensor<2, dim> &stress,
                                     const dealii::ArrayView<const double> &state,
                                     double                                &eps_zz,
                                     double                                &sigma_zz) const
    {
      if (axisymmetric())
        {
          eps_zz   = 0;
          sigma_zz = state[0];
        }
      else
        Interface<dim>::out_of_plane(strain, stress, state, eps_zz, sigma_zz);
    }

    template class LinearElastic<2>;
    template class LinearElastic<3>;
  } // namespace Material
} // namespace hysteron

HYSTERON_REGISTER_MATERIAL(hysteron::Material::LinearElastic,
                           "linear elastic",
                           "Hooke's law sigma = C : eps (isotropic; plane stress, plane strain "
                           "or 3D). No internal variables.")
