#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include "material/bouc_wen_uniaxial_kernels.h"

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



    void
    BoucWenUniaxial::state_rate(const double *state, const double deformation_rate, double *rate) const
    {
      if (degrading)
        {
          const Vector<true> f = rates<true>({{state[0], state[1], state[2]}}, deformation_rate);
          std::copy(f.begin(), f.end(), rate);
        }
      else
        rate[0] = rates<false>({{state[0]}}, deformation_rate)[0];
    }



    void
    BoucWenUniaxial::state_rate_derivatives(const double *state,
                                            const double  deformation_rate,
                                            double       *d_state,
                                            double       *d_deformation_rate) const
    {
      // With P = H1 H2 eps' and dH1/dz = n H1 / z: dP/dz = n H1 H2 eps' / z and,
      // H2 held constant, dP/d eps' = H1 H2. The z' row in eps' is rate_tangent().
      const double z      = state[z_index];
      const double h1     = abs_pow(z * inv_z_y);
      const double h2     = beta_plus_gamma_sign(z * deformation_rate);
      const double dP_dz  = (z != 0 ? n * h1 / z : 0.0) * h2 * deformation_rate;
      const double dP_der = h1 * h2;
      if (!degrading)
        {
          d_state[0]            = -dP_dz;
          d_deformation_rate[0] = rate_tangent<false>({{z}}, deformation_rate);
          return;
        }
      // g = nu_s P (nu_s = 1 + c e_h), z' = (eps' - g) / eta, eta' = c_eta eta^(-m_u) |g|,
      // e_h' = (1 - a) k z g; state order (z, eta, e_h).
      const double eta = state[eta_index], e = state[energy_index];
      const double nu = 1 + c_nu_scaled * e, P = h1 * h2 * deformation_rate, g = nu * P;
      const double dg_dz = nu * dP_dz, dg_de = c_nu_scaled * P, dg_der = nu * dP_der;
      const double p = c_eta * eta_power(eta), sg = (g > 0 ? 1.0 : (g < 0 ? -1.0 : 0.0));
      double      *J = d_state;
      J[0] = -dg_dz / eta;
      J[1] = -(deformation_rate - g) / (eta * eta);
      J[2] = -dg_de / eta;
      J[3] = p * sg * dg_dz;
      J[4] = -m_u * p / eta * std::abs(g);
      J[5] = p * sg * dg_de;
      J[6] = k_h * (g + z * dg_dz);
      J[7] = 0;
      J[8] = k_h * z * dg_de;
      d_deformation_rate[0] = rate_tangent<true>({{z, eta, e}}, deformation_rate);
      d_deformation_rate[1] = p * sg * dg_der;
      d_deformation_rate[2] = k_h * z * dg_der;
    }



    unsigned int
    BoucWenUniaxial::update(const double deps, double &stress, double *state, double *tangent) const
    {
      return dispatch([&](auto degrading_, auto integrator_) {
        return update_point<degrading_, integrator_>(deps, stress, state, tangent);
      });
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


    // The kernel of each variant, for callers outside the library (the batch update()
    // above inlines its own copies).
    template unsigned int
    BoucWenUniaxial::update_point<false, BoucWenIntegrator::forward_euler>(double, double &, double *, double *) const;
    template unsigned int
    BoucWenUniaxial::update_point<false, BoucWenIntegrator::adaptive>(double, double &, double *, double *) const;
    template unsigned int
    BoucWenUniaxial::update_point<false, BoucWenIntegrator::backward_euler>(double, double &, double *, double *) const;
    template unsigned int
    BoucWenUniaxial::update_point<true, BoucWenIntegrator::forward_euler>(double, double &, double *, double *) const;
    template unsigned int
    BoucWenUniaxial::update_point<true, BoucWenIntegrator::adaptive>(double, double &, double *, double *) const;
    template unsigned int
    BoucWenUniaxial::update_point<true, BoucWenIntegrator::backward_euler>(double, double &, double *, double *) const;
  } // namespace Material
} // namespace hysteron
