#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include <hysteron/rbsn/spring_law.h>

#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /**
       * One independent uniaxial Bouc-Wen law per spring (eq. 3.32-3.36): three in 2D
       * (normal, tangential, rotational), six in 3D (normal, two shear, two bending,
       * torsion), each with its own stiffness k_i and yield value F_y,i
       * (FacetSprings::yield_values of the smaller yield stress of the two cells) and the
       * Bouc-Wen parameters of cell a's material. The state of spring i lies at
       * state[3 i] (BoucWenUniaxial::max_n_state_variables each: z, and eta and e_h with
       * degradation); the tangent is diagonal. The springs are the uniaxial laws that
       * `Analysis = variable order` integrates (uniaxial_spring()).
       */
      template <int dim>
      class Uncoupled : public SpringLaw<dim>
      {
      public:
        using typename SpringLaw<dim>::Vector;
        using typename SpringLaw<dim>::Matrix;
        static constexpr unsigned int n = SpringLaw<dim>::n;

        static constexpr unsigned int stride = Material::BoucWenUniaxial::max_n_state_variables;

        unsigned int
        n_state_variables() const override
        {
          return n * stride;
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
          auto      &facet = laws(e);
          const auto yield = springs.yield_values(facet_yield_stress<dim>(a, b));
          for (unsigned int i = 0; i < n; ++i)
            {
              facet[i].reinit(*prm, springs.k[i], yield[i]);
              facet[i].initialize_state(state + stride * i);
            }
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
          // Every spring is advanced even if one fails, so that the trial state is the
          // same as spring-by-spring; the last failure is reported.
          std::string cause, spring;
          for (unsigned int i = 0; i < n; ++i)
            try
              {
                laws[e][i].update(increment[i], force[i], state + stride * i,
                                  tangent ? &(*tangent)[i][i] : nullptr);
              }
            catch (const RuntimeError &error)
              {
                cause  = error.what();
                spring = std::string("the ") + spring_name<dim>(i) + " spring";
              }
          if (!cause.empty())
            throw SpringFailure(cause, spring);
        }

        double
        h1(const unsigned int e, const unsigned int i, const double *state) const override
        {
          return laws[e][i].h1(state + stride * i);
        }

        double
        strain_energy(const unsigned int e,
                      const unsigned int i,
                      const double       delta,
                      const double      *state) const override
        {
          const auto &law = laws[e][i];
          return bouc_wen_strain_energy(law.parameters().post_yield_ratio, law.stiffness(), delta,
                                        state[stride * i]);
        }

        std::string
        variable_order_unsupported() const override
        {
          return "";
        }

        typename SpringLaw<dim>::UniaxialSpring
        uniaxial_spring(const unsigned int e, const unsigned int i) const override
        {
          return {&laws[e][i], stride * i};
        }

      private:
        PerFacet<std::array<Material::BoucWenUniaxial, n>> laws;
      };
    } // namespace
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_SPRING_LAW(hysteron::RBSN::Uncoupled,
                             "uncoupled",
                             "one uniaxial Bouc-Wen law per spring (eq. 3.36), each yielding at its "
                             "own F_y: 2D sigma_y t l (normal), sigma_y t l / sqrt(3) (tangential), "
                             "factor sigma_y t l^2 (rotational); 3D sigma_y A (normal), "
                             "sigma_y A / sqrt(3) (shear), factor sigma_y A sqrt(12 I / A) "
                             "(bending), factor sigma_y / sqrt(3) A sqrt(12 J / A) (torsion); "
                             "sigma_y and the Bouc-Wen parameters from the cells' material")
