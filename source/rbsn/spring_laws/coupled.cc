#include <hysteron/material/bouc_wen_interaction.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include <hysteron/rbsn/spring_law.h>

#include <memory>
#include <string>
#include <type_traits>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /**
       * One Bouc-Wen law for all springs of a facet (eq. 3.38-3.42,
       * doc/rbsn_coupled_springs.md), Material::BoucWenInteraction<n> with n = 3 in 2D
       * and 6 in 3D: the yield criterion Phi^2 = sum_i (F^h_i / F^h_y,i)^2 <= 1 in the
       * hysteretic forces F^h_i = (1 - a) k_i z_i (2D: F_n, F_t, M; 3D: N, V_1, V_2, M_1,
       * M_2, T) with associated flow, and a full n x n tangent D_t. The yield values
       * F_y,i are FacetSprings::yield_values of the smaller yield stress of the two cells
       * (those of the uncoupled law), the Bouc-Wen parameters cell a's. The state is
       * z = (z_1, ..., z_n), one double per spring.
       */
      template <int dim>
      class Coupled : public SpringLaw<dim>
      {
      public:
        using typename SpringLaw<dim>::Vector;
        using typename SpringLaw<dim>::Matrix;
        static constexpr unsigned int n = SpringLaw<dim>::n;

        unsigned int
        n_state_variables() const override
        {
          return n;
        }

        /// One interaction surface of Bouc-Wen forces: the material's springs must be
        /// Bouc-Wen (or linear).
        std::string
        unsupported(const Material::Interface<dim> &material) const override
        {
          const std::unique_ptr<Material::UniaxialSpringLaw> law = material.uniaxial_spring_law();
          if (law == nullptr || law->linear())
            return law ? std::string() : "the material offers no uniaxial spring law";
          const Material::BoucWenParameters *prm = law->bouc_wen_parameters();
          return prm ? Law::unsupported(*prm) :
                       "the coupled law is one Bouc-Wen interaction surface of the facet's "
                       "springs; the material's springs are not Bouc-Wen: use the uncoupled law";
        }

        bool
        setup_facet(const unsigned int            e,
                    const FacetSprings<dim>      &springs,
                    const Material::Interface<dim> &a,
                    const Material::Interface<dim> &b,
                    double                       *state) override
        {
          double                             sigma_y = 0;
          const Material::UniaxialSpringLaw *springs_of = material_laws.facet(a, b, sigma_y);
          if (springs_of == nullptr)
            return false;
          const Material::BoucWenParameters *prm = springs_of->bouc_wen_parameters();
          AssertThrow(prm != nullptr, dealii::ExcMessage("rbsn: coupled springs of a material unsupported()"));
          Facet &facet = facets(e);
          facet.law.reinit(*prm, springs.k, springs.yield_values(sigma_y));
          facet.law.initialize_state(state);
          facet.k = springs.k;
          facet.a = prm->post_yield_ratio;
          return true;
        }

        void
        update(const unsigned int e,
               const Vector      &increment,
               Vector            &force,
               double            *state,
               Matrix            *tangent) const override
        {
          try
            {
              facets[e].law.update(increment, force, state, tangent);
            }
          catch (const RuntimeError &error)
            {
              throw SpringFailure(error.what(), "the coupled springs");
            }
        }

        /// Phi^n of the facet, the same value for all its springs.
        double
        h1(const unsigned int e, const unsigned int, const double *state) const override
        {
          return facets[e].law.h1(state);
        }

        double
        strain_energy(const unsigned int e,
                      const unsigned int i,
                      const double       delta,
                      const double      *state) const override
        {
          return Material::bouc_wen_strain_energy(facets[e].a, facets[e].k[i], delta, state[i]);
        }

        /// Its springs yield together, they are not uniaxial laws (uniaxial_spring() gives
        /// none).
        std::string
        variable_order_unsupported() const override
        {
          return "the variable-order analysis integrates the uncoupled springs' rates; use "
                 "Analysis = implicit dynamics with the coupled law";
        }

      private:
        using Law = Material::BoucWenInteraction<n>;
        static_assert(std::is_same_v<typename Law::Vector, Vector> &&
                        std::is_same_v<typename Law::Matrix, Matrix>,
                      "the law works on the facet's vectors and matrices");

        struct Facet
        {
          Law    law;
          Vector k{};
          double a = 0; ///< post-yield ratio
        };
        PerFacet<Facet>                 facets;
        MaterialSpringLaws<dim> material_laws;
      };
    } // namespace
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_SPRING_LAW(hysteron::RBSN::Coupled,
                             "coupled",
                             "one Bouc-Wen law for all springs of a facet (2D: F_n, F_t, M; 3D: "
                             "N, V_1, V_2, M_1, M_2, T) with the yield criterion sum_i "
                             "(F^h_i / F^h_y,i)^2 <= 1 in the hysteretic forces F^h = (1 - a) k z "
                             "and associated flow (eq. 3.38-3.42; F^h_y = (1 - a) F_y, F_y the "
                             "uncoupled law's yield values), a full facet tangent (3 x 3 in 2D, "
                             "6 x 6 in 3D); it reduces to the uncoupled law when one spring is "
                             "loaded alone. No degradation; not for Analysis = variable order. See "
                             "doc/rbsn_coupled_springs.md")
