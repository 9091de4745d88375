#include <hysteron/material/bouc_wen_interaction.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/rbsn/spring_law.h>


namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /**
       * One Bouc-Wen law for the three springs of a facet (eq. 3.38-3.42,
       * doc/rbsn_coupled_springs.md): the yield criterion
       * Phi^2 = (F^h_n / F^h_y,n)^2 + (F^h_t / F^h_y,t)^2 + (M^h / M^h_y)^2 <= 1 in the
       * hysteretic forces F^h_i = (1 - a) k_i z_i with associated flow, and a full
       * 3 x 3 tangent D_t. The state is z = (z_n, z_t, z_phi).
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
          return 3;
        }

        std::string
        unsupported(const Material::Interface<dim> &material) const override
        {
          const auto behaviour = material.spring_behaviour();
          return behaviour.bouc_wen ? Material::BoucWenInteraction::unsupported(*behaviour.bouc_wen) :
                                      std::string();
        }

        bool
        setup_facet(const unsigned int            e,
                    const FacetSprings<dim>      &springs,
                    const Material::Interface<dim> &a,
                    const Material::Interface<dim> &b,
                    double                       *state) override
        {
          const Material::BoucWenParameters *prm = bouc_wen_springs<dim>(a, b);
          if (prm == nullptr)
            return false;
          Facet &facet = facets(e);
          if constexpr (dim == 2)
            facet.law.reinit(*prm, springs.k, springs.yield_values(facet_yield_stress<dim>(a, b)));
          else
            throw InputError("RBSN/Spring law", "the coupled law is two-dimensional");
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
              if constexpr (dim == 2)
                facets[e].law.update(increment, force, state, tangent);
            }
          catch (const RuntimeError &error)
            {
              throw SpringFailure(error.what(), "the coupled springs");
            }
        }

        /// Phi^n of the facet, the same value for the three springs.
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
          return bouc_wen_strain_energy(facets[e].a, facets[e].k[i], delta, state[i]);
        }

        std::string
        variable_order_unsupported() const override
        {
          return "the variable-order analysis integrates the uncoupled springs' rates; use "
                 "Analysis = implicit dynamics with the coupled law";
        }

      private:
        struct Facet
        {
          Material::BoucWenInteraction law;
          Vector                       k{};
          double                       a = 0; ///< post-yield ratio
        };
        PerFacet<Facet> facets;
      };
    } // namespace
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_SPRING_LAW(hysteron::RBSN::Coupled,
                             "coupled",
                             "one Bouc-Wen law for the three springs with the yield criterion "
                             "(F^h_n / F^h_y,n)^2 + (F^h_t / F^h_y,t)^2 + (M^h / M^h_y)^2 <= 1 in the "
                             "hysteretic forces F^h = (1 - a) k z and associated flow (eq. "
                             "3.38-3.42; F^h_y = (1 - a) F_y), a full 3 x 3 facet tangent; it reduces "
                             "to the uncoupled law when one component is loaded alone. No "
                             "degradation. See doc/rbsn_coupled_springs.md")
