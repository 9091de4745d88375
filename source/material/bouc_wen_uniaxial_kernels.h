#ifndef hysteron_source_material_bouc_wen_uniaxial_kernels_h
#define hysteron_source_material_bouc_wen_uniaxial_kernels_h

// The point kernels of the uniaxial Bouc-Wen law (BoucWenUniaxial, whose header documents
// the equations): the rates, the implicit residual, the adaptive and backward Euler
// integrators and update_point(), inlined into the loops of bouc_wen_uniaxial.cc.

#include <hysteron/material/bogacki_shampine.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include "material/safeguarded_newton.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hysteron
{
  namespace Material
  {
    template <bool degrading_>
    inline BoucWenUniaxial::Vector<degrading_>
    BoucWenUniaxial::rates(const Vector<degrading_> &v, const double deps) const
    {
      const double       z  = v[0];
      const double       hh = abs_pow(z * inv_z_y) * beta_plus_gamma_sign(z * deps);
      Vector<degrading_> f;
      if constexpr (!degrading_)
        f[0] = deps * (1 - hh);
      else
        {
          const double eta = v[1];
          const double nu  = 1 + c_nu_scaled * v[2];
          const double g   = nu * hh * deps; // plastic strain increment eps' - eta z'
          f[0]             = (deps - g) / eta;
          f[1]             = c_eta * eta_power(eta) * std::abs(g);
          f[2]             = k_h * z * g;
        }
      return f;
    }



    template <bool degrading_>
    inline double
    BoucWenUniaxial::rate_tangent(const Vector<degrading_> &v, const double deps) const
    {
      const double hh = abs_pow(v[0] * inv_z_y) * beta_plus_gamma_sign(v[0] * deps);
      if constexpr (!degrading_)
        return 1 - hh;
      else
        return (1 - (1 + c_nu_scaled * v[2]) * hh) / v[1];
    }



    inline void
    BoucWenUniaxial::implicit_eta(const double eta_n,
                                  const double xi,
                                  double      &eta,
                                  double      &deta_dxi) const
    {
      if (m_u == 1)
        // eta^2 - eta_n eta - c_eta xi = 0
        eta = 0.5 * (eta_n + std::sqrt(eta_n * eta_n + 4 * c_eta * xi));
      else if (m_u == 0)
        eta = eta_n + c_eta * xi;
      else
        {
          eta = eta_n;
          for (unsigned int it = 0; it < 100; ++it)
            {
              const double p    = std::pow(eta, -m_u);
              const double phi  = eta - eta_n - c_eta * p * xi;
              const double step = phi / (1 + m_u * c_eta * p / eta * xi);
              eta -= step;
              if (std::abs(step) <= 1e-15 * eta)
                break;
            }
        }
      const double p = eta_power(eta);
      deta_dxi       = c_eta * p / (1 + m_u * c_eta * p / eta * xi);
    }



    template <bool degrading_>
    inline BoucWenUniaxial::Residual
    BoucWenUniaxial::implicit_residual(const double              z,
                                       const double              deps,
                                       const Vector<degrading_> &v0) const
    {
      // P = H1 H2 deps is the plastic increment per unit nu_s.
      const double h1       = abs_pow(z * inv_z_y);
      const double h2       = beta_plus_gamma_sign(z * deps);
      const double dh1_dz   = (z != 0 ? n * h1 / z : 0.0);
      const double P        = h1 * h2 * deps;
      const double dP_dz    = h2 * deps * dh1_dz;
      const double dP_ddeps = h1 * h2;

      Residual res;
      if constexpr (!degrading_)
        {
          // r = z - z_n - deps + H1 H2 deps
          res.r        = z - v0[0] - deps + P;
          res.dr_dz    = 1 + dP_dz;
          res.dr_ddeps = -1 + dP_ddeps;
          res.eta      = 1;
          res.energy   = 0;
        }
      else
        {
          // e_{n+1} = e_n + (1 - a) k z g with g = nu_{n+1} P and
          // nu_{n+1} = 1 + c e_{n+1} is linear in e_{n+1}: with B = (1 - a) k z P,
          // nu_{n+1} = nu_n / (1 - c B). Then eta_{n+1} from implicit_eta(|g|).
          const double eta_n    = v0[1];
          const double nu_n     = 1 + c_nu_scaled * v0[2];
          const double B        = k_h * z * P;
          const double dB_dz    = k_h * (P + z * dP_dz);
          const double dB_ddeps = k_h * z * dP_ddeps;
          const double denom    = 1 - c_nu_scaled * B;
          if (!(denom > 0))
            {
              // No finite nu_{n+1}: z is far beyond saturation in the direction
              // of deps, where the residual tends to +infinity * sgn(deps).
              res.r        = deps > 0 ? std::numeric_limits<double>::infinity() :
                                        -std::numeric_limits<double>::infinity();
              res.dr_dz    = std::numeric_limits<double>::quiet_NaN();
              res.dr_ddeps = std::numeric_limits<double>::quiet_NaN();
              res.eta      = eta_n;
              res.energy   = v0[2];
              return res;
            }
          const double nu        = nu_n / denom;
          const double dnu_dz    = nu * c_nu_scaled * dB_dz / denom;
          const double dnu_ddeps = nu * c_nu_scaled * dB_ddeps / denom;
          const double g         = nu * P;
          const double dg_dz     = dnu_dz * P + nu * dP_dz;
          const double dg_ddeps  = dnu_ddeps * P + nu * dP_ddeps;
          const double sg        = (g > 0 ? 1.0 : (g < 0 ? -1.0 : 0.0));

          double eta, deta_dxi;
          implicit_eta(eta_n, std::abs(g), eta, deta_dxi);
          const double deta_dz    = deta_dxi * sg * dg_dz;
          const double deta_ddeps = deta_dxi * sg * dg_ddeps;

          res.r        = eta * (z - v0[0]) - deps + g;
          res.dr_dz    = deta_dz * (z - v0[0]) + eta + dg_dz;
          res.dr_ddeps = deta_ddeps * (z - v0[0]) - 1 + dg_ddeps;
          res.eta      = eta;
          res.energy   = v0[2] + B * nu;
        }
      return res;
    }



    template <bool degrading_>
    inline unsigned int
    BoucWenUniaxial::integrate_adaptive(Vector<degrading_> &v, const double deps) const
    {
      using V = Vector<degrading_>;
      // Error scales: z by z_y, eta absolutely, e_h by y z_y.
      V inv_scale;
      inv_scale[0] = inv_z_y / tolerance;
      if constexpr (degrading_)
        {
          inv_scale[1] = 1 / tolerance;
          inv_scale[2] = 1 / (energy_scale * tolerance);
        }
      // The exact solution never leaves |z| <= z_s = z_y (beta + gamma)^(-1/n) while
      // nu_s >= 1 (there z' points inwards or vanishes), so projecting onto that set can
      // only reduce the error. It removes the overshoot of the saturation value for large
      // n, and a saturated point then has z' = 0 exactly and takes a whole increment in
      // one step.
      const auto project = [&](V &w) {
        if (!(std::abs(w[0]) > z_saturation))
          return false;
        if constexpr (degrading_)
          if (!(c_nu_scaled * w[2] >= 0))
            return false;
        w[0] = std::copysign(z_saturation, w[0]);
        return true;
      };
      return bogacki_shampine_32(
        v,
        inv_scale,
        max_substeps,
        [&](const V &w) { return rates<degrading_>(w, deps); },
        // lambda = n |plastic rate| / |z|: the plastic rate is deps / eta - z'.
        [&](const V &w, const V &f) {
          const double eta = degrading_ ? w[1] : 1.0;
          return w[0] != 0 ? n * std::abs(deps / eta - f[0]) / std::abs(w[0]) : 0.0;
        },
        project,
        [&]() { throw_too_many_substeps(deps, v[0]); });
    }



    template <bool degrading_>
    inline unsigned int
    BoucWenUniaxial::integrate_backward_euler(Vector<degrading_> &v,
                                              const double        deps,
                                              double             &dz_ddeps) const
    {
      const Vector<degrading_> v0   = v;
      const double             z0   = v0[0];
      const double             sign = (deps > 0 ? 1.0 : -1.0);
      const double             eta0 = degrading_ ? v0[1] : 1.0;

      // rho(z) = sgn(deps) r(z) (with d rho/dz), which increases in the
      // direction of deps in the loading branch.
      const auto rho = [&](const double z) {
        Residual r = implicit_residual<degrading_>(z, deps, v0);
        r.r *= sign;
        r.dr_dz *= sign;
        return r;
      };

      // The bracket [lo, hi] with rho(lo) < 0 <= rho(hi), and the residual at hi.
      double   lo = z0, hi = z0;
      Residual res = rho(z0);
      // An increment below the round-off of z (|r(z_n)| at that level: a Newton
      // correction of a converged state) leaves z_n, which is then the root.
      const double round_off = 8 * std::numeric_limits<double>::epsilon() * (std::abs(z0) + z_y);
      if (std::abs(res.r) <= round_off)
        res.r = 0;
      if (res.r < 0)
        {
          // z_n is inside the saturation value: the root lies in the direction
          // of deps, between z_n and the elastic predictor z_n + deps / eta_n,
          // which we clip at the saturation value z_s = z_y (beta + gamma)^(-1/n)
          // (there rho >= 0 as long as nu_s >= 1, and |z/z_y|^n cannot overflow).
          const double predictor = z0 + deps / eta0;
          hi                     = predictor;
          if (sign * predictor > z_saturation && sign * z0 < z_saturation)
            hi = sign * z_saturation;
          res = rho(hi);
          // Should that fail (nu_s < 1 after negative plastic work), walk out.
          for (unsigned int e = 0; !(res.r >= 0); ++e)
            {
              if (e == 60 || std::isnan(res.r))
                throw_no_convergence(deps, z0, res.r, "found no bracket of the root");
              hi  = z0 + 2 * (std::max({std::abs(hi - z0), std::abs(predictor - z0), round_off}) * sign);
              res = rho(hi);
            }
        }
      else if (res.r > 0)
        {
          // z_n lies beyond the (degraded) saturation value: z moves against
          // deps, towards 0, where rho(0) = -eta_n |z_n| - |deps| < 0 if z_n has
          // the sign of deps. Otherwise walk out from z_n.
          double distance = (sign * z0 > 0 ? -z0 : -sign * std::max(std::abs(deps) / eta0, z_y));
          for (unsigned int e = 0;; ++e)
            {
              const double value = rho(z0 + distance).r;
              if (value < 0)
                break;
              if (e == 60 || std::isnan(value))
                throw_no_convergence(deps, z0, res.r, "found no bracket of the root");
              distance *= 2;
            }
          lo = z0 + distance;
        }

      // Safeguarded Newton from the end with rho > 0: in the loading branch r is
      // convex and increasing in z, so Newton converges monotonically from there;
      // bisection where Newton would leave the bracket (non-convex unloading
      // branch for beta > gamma, kink at z = 0 for n < 1).
      double             z          = hi;
      const double       scale      = tolerance * z_y;
      const double       collapse_width = 4 * std::numeric_limits<double>::epsilon() * z_y;
      const unsigned int iterations = safeguarded_newton(
        z, lo, res, [&](const double x) { return rho(x); },
        [](const auto &r) { return std::make_pair(r.r, r.dr_dz); }, [&](double) { return scale; },
        [&](double) { return collapse_width; }, max_iterations,
        [&](const char *what, const double x, const auto &r) { throw_no_convergence(deps, x, r.r, what); });

      v[0] = z;
      if constexpr (degrading_)
        {
          v[1] = res.eta;
          v[2] = res.energy;
        }
      dz_ddeps = -res.dr_ddeps / (res.dr_dz * sign);
      return iterations;
    }



    template <bool degrading_, BoucWenIntegrator integrator_>
    inline __attribute__((always_inline)) unsigned int
    BoucWenUniaxial::update_point(const double deps,
                                  double      &stress,
                                  double      *state,
                                  double      *tangent) const
    {
      Vector<degrading_> v;
      for (unsigned int i = 0; i < v.size(); ++i)
        v[i] = state[i];
      const double z0 = v[0];

      unsigned int work     = 1;
      double       dz_ddeps = 0;
      if (!std::isfinite(deps))
        throw_not_finite(deps, v[0]);
      if (deps == 0)
        {
          if (tangent)
            *tangent = a * k + k_h * rate_tangent<degrading_>(v, 0.0);
          return 0;
        }

      if constexpr (integrator_ == BoucWenIntegrator::forward_euler)
        {
          if (tangent)
            dz_ddeps = rate_tangent<degrading_>(v, deps);
          const Vector<degrading_> f = rates<degrading_>(v, deps);
          for (unsigned int i = 0; i < v.size(); ++i)
            v[i] += f[i];
          // From |z| <= z_s a step moves z by at most |deps| max(1, nu_s - 1) (the
          // factor 1 - nu_s H1 H2 lies in [1 - nu_s, 1] there, and eta >= 1). Beyond
          // that the explicit scheme has left the admissible set and is unstable:
          // |z| then grows without bound to inf and NaN within a few increments.
          double reach = std::abs(deps);
          if constexpr (degrading_)
            reach *= std::max(1.0, c_nu_scaled * state[energy_index]);
          if (!(std::abs(v[0]) <= z_saturation + reach))
            throw_unstable(deps, z0, v[0]);
        }
      else if constexpr (integrator_ == BoucWenIntegrator::adaptive)
        {
          work = integrate_adaptive<degrading_>(v, deps);
          if (tangent)
            dz_ddeps = rate_tangent<degrading_>(v, deps);
        }
      else
        work = integrate_backward_euler<degrading_>(v, deps, dz_ddeps);

      for (unsigned int i = 0; i < v.size(); ++i)
        state[i] = v[i];
      stress += a * k * deps + k_h * (v[0] - z0);
      if (tangent)
        *tangent = a * k + k_h * dz_ddeps;
      return work;
    }
  } // namespace Material
} // namespace hysteron

#endif
