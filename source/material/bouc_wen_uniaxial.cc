#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include <sstream>

namespace hysteron
{
  namespace Material
  {
    BoucWenUniaxial::BoucWenUniaxial(const BoucWenParameters &parameters, const double stiffness)
    {
      reinit(parameters, stiffness, parameters.yield_stress);
    }



    BoucWenUniaxial::BoucWenUniaxial(const BoucWenParameters &parameters,
                                     const double             stiffness,
                                     const double             yield_value)
    {
      reinit(parameters, stiffness, yield_value);
    }



    void
    BoucWenUniaxial::reinit(const BoucWenParameters &parameters,
                            const double             stiffness,
                            const double             yield_value)
    {
      if (!(stiffness > 0) || !(yield_value > 0) || !std::isfinite(stiffness) ||
          !std::isfinite(yield_value))
        throw std::invalid_argument("BoucWenUniaxial: the stiffness and the yield value must be "
                                    "positive and finite");
      prm          = parameters;
      degrading    = parameters.degradation();
      k            = stiffness;
      y            = yield_value;
      z_y          = y / k;
      inv_z_y      = 1 / z_y;
      a            = parameters.post_yield_ratio;
      k_h          = (1 - a) * k;
      n            = parameters.smoothness;
      n_integer    = (n >= 1 && n <= 64 && n == std::floor(n)) ? static_cast<unsigned int>(n) : 0;
      beta         = parameters.beta;
      gamma        = parameters.gamma;
      c_eta        = parameters.stiffness_degradation_c_eta;
      m_u          = parameters.stiffness_degradation_m_u;
      c_nu_scaled  = parameters.strength_deterioration_c_nu / (y * z_y);
      tolerance    = parameters.tolerance;
      energy_scale = y * z_y;
      z_saturation = z_y * std::pow(beta + gamma, -1 / n);
    }



    std::vector<std::string>
    BoucWenUniaxial::state_variable_names() const
    {
      if (degrading)
        return {"z", "eta", "e_h"};
      return {"z"};
    }



    unsigned long
    BoucWenUniaxial::update(const unsigned int n,
                            const double      *deps,
                            double            *stresses,
                            double            *states,
                            double            *tangents) const
    {
      // One dispatch, then the inlined kernel of the variant in the loop.
      return dispatch([&](auto degrading_, auto integrator_) {
        constexpr unsigned int n_state = degrading_ ? 3 : 1;
        unsigned long          work    = 0;
        for (unsigned int i = 0; i < n; ++i)
          work += update_point<degrading_, integrator_>(deps[i],
                                                        stresses[i],
                                                        states + i * n_state,
                                                        tangents ? tangents + i : nullptr);
        return work;
      });
    }



    void
    BoucWenUniaxial::throw_not_finite(const double deps, const double z) const
    {
      std::ostringstream m;
      m << "Bouc-Wen (uniaxial): the increment " << deps << " is not finite (z/z_y = " << z / z_y
        << ")";
      throw RuntimeError(m.str());
    }



    void
    BoucWenUniaxial::throw_unstable(const double deps, const double z0, const double z) const
    {
      std::ostringstream m;
      m << "Bouc-Wen (uniaxial): forward Euler is unstable at the increment " << deps
        << " (z/z_y = " << z0 / z_y << " -> " << z / z_y
        << ", beyond the saturation value by more than one increment; n = " << n
        << ", stable for increments up to about 2 z_y/n = " << 2 * z_y / n
        << "): reduce the increments or use the adaptive or backward euler integrator";
      throw RuntimeError(m.str());
    }



    void
    BoucWenUniaxial::throw_too_many_substeps(const double deps, const double z) const
    {
      std::ostringstream m;
      m << "Bouc-Wen (uniaxial): the adaptive integrator needed more than " << max_substeps
        << " sub-steps for the increment " << deps << " (z/z_y = " << z / z_y
        << " when it gave up; n = " << n << ", tolerance = " << tolerance
        << "): reduce the increments or raise the Tolerance";
      throw RuntimeError(m.str());
    }



    void
    BoucWenUniaxial::throw_no_convergence(const double       deps,
                                          const double       z,
                                          const double       residual,
                                          const std::string &why) const
    {
      std::ostringstream m;
      m << "Bouc-Wen (uniaxial): the backward Euler iteration did not converge for the "
           "increment "
        << deps << " (" << why << "; z/z_y = " << z / z_y << ", residual/z_y = " << residual / z_y
        << "): reduce the increments";
      throw RuntimeError(m.str());
    }
  } // namespace Material
} // namespace hysteron
