// The Bouc-Wen material's uniaxial spring law: a BoucWenUniaxial per spring.
#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include "material/update_each_spring.h"

#include <vector>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      /**
       * Uniaxial Bouc-Wen springs (eq. 3.32-3.36): spring i follows BoucWenUniaxial with
       * its k and F_y and the material's parameters, F = a k delta + (1 - a) k z. Its
       * state is BoucWenUniaxial::max_n_state_variables doubles (z, and eta and e_h with
       * degradation), whether it degrades or not.
       */
      class BoucWenSprings : public UniaxialSpringLaw
      {
      public:
        explicit BoucWenSprings(const BoucWenParameters &parameters)
          : parameters(parameters)
        {}

        double
        yield_stress() const override
        {
          return parameters.yield_stress;
        }

        unsigned int
        n_state_variables() const override
        {
          return BoucWenUniaxial::max_n_state_variables;
        }

        unsigned int
        add_spring(const double k, const double yield_value, double *state) override
        {
          springs.emplace_back(parameters, k, yield_value);
          springs.back().initialize_state(state);
          return springs.size() - 1;
        }

        unsigned int
        update(const unsigned int first,
               const unsigned int n,
               const double      *increment,
               double            *force,
               double            *state,
               double            *tangent,
               const unsigned int tangent_stride,
               std::string       &failure) const override
        {
          constexpr unsigned int stride = BoucWenUniaxial::max_n_state_variables;
          return update_each_spring(n, failure, [&](const unsigned int i) {
            springs[first + i].update(increment[i], force[i], state + stride * i,
                                      tangent ? tangent + tangent_stride * i : nullptr);
          });
        }

        double
        h1(const unsigned int spring, const double *state) const override
        {
          return springs[spring].h1(state);
        }

        double
        hysteretic_variable(const unsigned int, const double *state) const override
        {
          return state[BoucWenUniaxial::z_index];
        }

        double
        strain_energy(const unsigned int spring, const double delta, const double *state) const override
        {
          const BoucWenUniaxial &law = springs[spring];
          return bouc_wen_strain_energy(parameters.post_yield_ratio, law.stiffness(), delta,
                                        state[BoucWenUniaxial::z_index]);
        }

        const BoucWenParameters *
        bouc_wen_parameters() const override
        {
          return &parameters;
        }

        const BoucWenUniaxial *
        bouc_wen(const unsigned int spring) const override
        {
          return &springs[spring];
        }

      private:
        const BoucWenParameters      parameters;
        std::vector<BoucWenUniaxial> springs;
      };
    } // namespace



    template <int dim>
    std::unique_ptr<UniaxialSpringLaw>
    BoucWen<dim>::uniaxial_spring_law() const
    {
      if (family.variant != UniaxialVariant::smooth)
        return create_bouc_wen_variant(family, parameters.yield_stress);
      return std::make_unique<BoucWenSprings>(parameters);
    }

    template <int dim>
    std::string
    BoucWen<dim>::continuum_unsupported() const
    {
      if (family.variant == UniaxialVariant::smooth)
        return "";
      return "Bouc-Wen/Uniaxial law = " + family.name() +
             " is a law for springs and uniaxial points (the rbsn, oscillator, spectrum and uniaxial "
             "methods); a continuum takes the smooth triaxial law: set Uniaxial law = smooth";
    }

    template std::unique_ptr<UniaxialSpringLaw>
    BoucWen<2>::uniaxial_spring_law() const;
    template std::unique_ptr<UniaxialSpringLaw>
    BoucWen<3>::uniaxial_spring_law() const;
    template std::string
    BoucWen<2>::continuum_unsupported() const;
    template std::string
    BoucWen<3>::continuum_unsupported() const;
  } // namespace Material
} // namespace hysteron
