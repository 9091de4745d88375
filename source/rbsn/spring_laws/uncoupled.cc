#include <hysteron/material/uniaxial_spring_law.h>
#include <hysteron/rbsn/spring_law.h>

#include <string>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /**
       * One independent uniaxial law per spring (eq. 3.36 for Bouc-Wen materials): three
       * in 2D (normal, tangential, rotational), six in 3D (normal, two shear, two
       * bending, torsion), each with its own stiffness k_i and yield value F_y,i
       * (FacetSprings::yield_values of the smaller yield stress of the two cells). The
       * springs follow the uniaxial spring law of cell a's material
       * (Material::Interface::uniaxial_spring_law()), so any material that offers one
       * drives the springs; facets with a linear material are F = k delta. The state of
       * spring i lies at state[stride i], stride the largest n_state_variables() of the
       * bodies' laws; the tangent is diagonal. Springs of Bouc-Wen materials are the
       * uniaxial laws that `Analysis = variable order` integrates (uniaxial_spring()).
       */
      template <int dim>
      class Uncoupled : public SpringLaw<dim>
      {
      public:
        using typename SpringLaw<dim>::Vector;
        using typename SpringLaw<dim>::Matrix;
        static constexpr unsigned int n = SpringLaw<dim>::n;

        std::string
        unsupported(const Material::Interface<dim> &material) const override
        {
          if (material.uniaxial_spring_law() == nullptr)
            return "the material offers no uniaxial spring law "
                   "(Material::Interface::uniaxial_spring_law())";
          return "";
        }

        /// The bodies' laws fix the stride: the largest state of a spring.
        void
        initialize(const std::vector<const Material::Interface<dim> *> &materials) override
        {
          for (const auto *material : materials)
            material_laws(*material);
          stride = material_laws.max_n_state_variables();
        }

        unsigned int
        n_state_variables() const override
        {
          return n * stride;
        }

        bool
        setup_facet(const unsigned int              e,
                    const FacetSprings<dim>        &springs,
                    const Material::Interface<dim> &a,
                    const Material::Interface<dim> &b,
                    double                         *state) override
        {
          double                       sigma_y = 0;
          Material::UniaxialSpringLaw *law     = material_laws.facet(a, b, sigma_y);
          if (law == nullptr)
            return false;
          AssertThrow(law->n_state_variables() <= stride,
                      dealii::ExcMessage("rbsn: a material not given to initialize()"));
          const auto yield = springs.yield_values(sigma_y);
          Facet     &facet = facets(e);
          facet.law        = law;
          for (unsigned int i = 0; i < n; ++i)
            {
              const unsigned int s = law->add_spring(springs.k[i], yield[i], state + stride * i);
              if (i == 0)
                facet.first = s;
            }
          return true;
        }

        bool
        diagonal_tangent() const override
        {
          return true;
        }

        /// One call of the material's law for the facet's springs (D[i][i] at stride n + 1
        /// in the n x n tensor's contiguous components).
        void
        update(const unsigned int e,
               const Vector      &increment,
               Vector            &force,
               double            *state,
               Matrix            *tangent) const override
        {
          const Facet &facet = facets[e];
          std::string  cause;
          const unsigned int failed = facet.law->update(facet.first, n, increment.data(), force.data(), state,
                                                        tangent ? &(*tangent)[0][0] : nullptr, n + 1, cause);
          if (failed < n)
            throw SpringFailure(cause, std::string("the ") + spring_name<dim>(failed) + " spring");
        }

        double
        h1(const unsigned int e, const unsigned int i, const double *state) const override
        {
          return facets[e].law->h1(facets[e].first + i, state + stride * i);
        }

        double
        strain_energy(const unsigned int e,
                      const unsigned int i,
                      const double       delta,
                      const double      *state) const override
        {
          return facets[e].law->strain_energy(facets[e].first + i, delta, state + stride * i);
        }

        std::string
        variable_order_unsupported() const override
        {
          return "";
        }

        typename SpringLaw<dim>::UniaxialSpring
        uniaxial_spring(const unsigned int e, const unsigned int i) const override
        {
          return {facets[e].law->bouc_wen(facets[e].first + i), stride * i};
        }

      private:
        /// A hysteretic facet: its material's law and the number of its first spring there.
        struct Facet
        {
          const Material::UniaxialSpringLaw *law   = nullptr;
          unsigned int                       first = 0;
        };
        PerFacet<Facet> facets;
        MaterialSpringLaws<dim> material_laws;
        unsigned int            stride = 0;
      };
    } // namespace
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_SPRING_LAW(hysteron::RBSN::Uncoupled,
                             "uncoupled",
                             "one uniaxial law per spring, the cells' material's (Bouc-Wen: eq. "
                             "3.36), each yielding at its "
                             "own F_y: 2D sigma_y t l (normal), sigma_y t l / sqrt(3) (tangential), "
                             "factor sigma_y t l^2 (rotational); 3D sigma_y A (normal), "
                             "sigma_y A / sqrt(3) (shear), factor sigma_y A sqrt(12 I / A) "
                             "(bending), factor sigma_y / sqrt(3) A sqrt(12 J / A) (torsion); "
                             "sigma_y and the law from the cells' material")
