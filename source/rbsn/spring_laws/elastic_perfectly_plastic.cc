#include <hysteron/rbsn/spring_law.h>

#include <algorithm>
#include <cmath>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /**
       * Rate-independent elastic-perfectly-plastic springs: each spring of the facet
       * (three in 2D, six in 3D) is elastic, F_i = k_i (delta_i - delta^p_i), while
       * |F_i| < F_y,i and flows at |F_i| = F_y,i (FacetSprings::yield_values of the
       * smaller yield stress of the two cells' materials' uniaxial spring laws; the laws
       * themselves are not used). The update is the exact return map of the increment:
       * the trial force F + k d delta is cut back to +-F_y, the cut-off part
       * (|F_trial| - F_y) / k is plastic deformation; the tangent is k elastically and 0
       * at yield.
       *
       * State of spring i: state[2 i] = delta^p_i, state[2 i + 1] = |F_i| / F_y,i
       * (the H1 output: 1 at yield). No uniaxial Bouc-Wen springs, hence no
       * `Analysis = variable order` (the default variable_order_unsupported()).
       */
      template <int dim>
      class ElasticPerfectlyPlastic : public SpringLaw<dim>
      {
      public:
        using typename SpringLaw<dim>::Vector;
        using typename SpringLaw<dim>::Matrix;
        static constexpr unsigned int n = SpringLaw<dim>::n;

        unsigned int
        n_state_variables() const override
        {
          return 2 * n;
        }

        bool
        setup_facet(const unsigned int            e,
                    const FacetSprings<dim>      &springs,
                    const Material::Interface<dim> &a,
                    const Material::Interface<dim> &b,
                    double                       *state) override
        {
          double sigma_y = 0;
          if (material_laws.facet(a, b, sigma_y) == nullptr)
            return false;
          facets(e) = {springs.k, springs.yield_values(sigma_y)};
          std::fill(state, state + 2 * n, 0.0);
          return true;
        }

        /// The return map's tangent is exact, whatever the material's Bouc-Wen integrator.
        bool
        has_consistent_tangent(const Material::Interface<dim> &) const override
        {
          return true;
        }

        bool
        diagonal_tangent() const override
        {
          return true;
        }

        void
        update(const unsigned int e,
               const Vector      &increment,
               Vector            &force,
               double            *state,
               Matrix            *tangent) const override
        {
          const Facet &f = this->facets[e];
          for (unsigned int i = 0; i < n; ++i)
            {
              const double trial = force[i] + f.k[i] * increment[i];
              const bool   yields = std::abs(trial) > f.yield[i];
              force[i]            = yields ? std::copysign(f.yield[i], trial) : trial;
              state[2 * i] += (trial - force[i]) / f.k[i];
              state[2 * i + 1] = std::abs(force[i]) / f.yield[i];
              if (tangent)
                (*tangent)[i][i] = yields ? 0.0 : f.k[i];
            }
        }

        double
        h1(const unsigned int, const unsigned int i, const double *state) const override
        {
          return state[2 * i + 1];
        }

        /// 1/2 k (delta - delta^p)^2 = F^2 / 2k.
        double
        strain_energy(const unsigned int e,
                      const unsigned int i,
                      const double       delta,
                      const double      *state) const override
        {
          const double elastic = delta - state[2 * i];
          return 0.5 * facets[e].k[i] * elastic * elastic;
        }

      private:
        struct Facet
        {
          Vector k{}, yield{};
        };
        PerFacet<Facet>         facets;
        MaterialSpringLaws<dim> material_laws;
      };
    } // namespace
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_SPRING_LAW(hysteron::RBSN::ElasticPerfectlyPlastic,
                             "elastic-perfectly-plastic",
                             "independent rate-independent springs (three in 2D, six in 3D), "
                             "elastic (k) up to the yield value of the uncoupled law (from the "
                             "smaller yield stress of the cells' materials) and perfectly "
                             "plastic beyond; tangent k or 0; not for Analysis = variable order")
