// The wider Bouc-Wen family as uniaxial spring laws: Baber-Noori pinching (BWBN), an
// asymmetric law and OpenSees' BoucWen and BoucWenOriginal (doc/theory.md, "The Bouc-Wen
// family"). One implicit step per increment, solved with forward-mode derivatives.
#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_family.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include "material/update_each_spring.h"

#include "material/safeguarded_newton.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      /// A value and its derivative with respect to one input (forward mode): the rate
      /// functions are written once and give the Newton derivative and the tangent.
      struct Dual
      {
        double v = 0, d = 0;
      };

      inline Dual
      operator+(const Dual a, const Dual b)
      {
        return {a.v + b.v, a.d + b.d};
      }
      inline Dual
      operator-(const Dual a, const Dual b)
      {
        return {a.v - b.v, a.d - b.d};
      }
      inline Dual
      operator*(const Dual a, const Dual b)
      {
        return {a.v * b.v, a.d * b.v + a.v * b.d};
      }
      inline Dual
      operator/(const Dual a, const Dual b)
      {
        return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)};
      }
      inline Dual
      operator*(const double a, const Dual b)
      {
        return {a * b.v, a * b.d};
      }
      inline Dual
      operator+(const double a, const Dual b)
      {
        return {a + b.v, b.d};
      }
      inline Dual
      operator-(const double a, const Dual b)
      {
        return {a - b.v, -b.d};
      }
      inline Dual
      exp(const Dual a)
      {
        const double e = std::exp(a.v);
        return {e, e * a.d};
      }
      /// |a|^n, with the derivative 0 at a = 0 (the one-sided limit for n > 1; the rate
      /// functions multiply it by factors that vanish there or keep it bounded).
      inline Dual
      pow_abs(const Dual a, const double n)
      {
        if (a.v == 0)
          return {0, 0};
        const double p = std::pow(std::abs(a.v), n);
        return {p, n * p / a.v * a.d};
      }
      inline Dual
      pow(const Dual a, const double n)
      {
        const double p = std::pow(a.v, n);
        return {p, n * p / a.v * a.d};
      }

      /// OpenSees' signum: +1 for x > 0, else -1 (0 included).
      inline double
      signum(const double x)
      {
        return x > 0 ? 1.0 : -1.0;
      }
      /// sgn with sgn(0) = 0.
      inline double
      sign(const double x)
      {
        return (x > 0) - (x < 0);
      }

      /// A spring's stiffness and yield value from its host.
      struct Spring
      {
        double k, y;
      };

      /// The force of the laws with a linear and a hysteretic branch in parallel,
      /// F = alpha k delta + (1 - alpha) k z, its partial derivatives and recoverable energy.
      struct ParallelBranches
      {
        double alpha;

        std::pair<double, double>
        force(const double delta, const double z, const Spring &s) const
        {
          return {alpha * s.k * delta + (1 - alpha) * s.k * z, alpha * s.k};
        }
        double
        force_by_z(const double, const Spring &s) const
        {
          return (1 - alpha) * s.k;
        }
        double
        strain_energy(const double delta, const double z, const Spring &s) const
        {
          return bouc_wen_strain_energy(alpha, s.k, delta, z);
        }
      };

      /**
       * OpenSees `BoucWen` (Haukaas), z in the units of delta:
       *   z' = delta' [A - nu |z|^n (gamma + beta sgn(z delta'))] / eta,
       *   A = A0 - dA e, nu = 1 + dnu e, eta = 1 + deta e,  e' = (1 - alpha) k z delta',
       *   F = alpha k delta + (1 - alpha) k z.
       * The saturation value is (A / (nu (beta + gamma)))^(1/n): beta and gamma carry the
       * units of delta^-n and the spring's yield value is not used.
       */
      struct OpenSeesBoucWen : ParallelBranches
      {
        double n, beta, gamma, A0, dA, dnu, deta;

        template <typename T>
        T
        rate(const T &z, const T &e, const double direction, const Spring &) const
        {
          const double psi = gamma + beta * signum(direction * z.v);
          return (A0 - dA * e - (1 + dnu * e) * pow_abs(z, n) * T{psi, 0}) / (1 + deta * e);
        }
        double
        energy_factor(const Spring &s) const
        {
          return (1 - alpha) * s.k;
        }
        double
        scale(const double, const Spring &) const
        {
          return std::pow(A0 / (beta + gamma), 1 / n);
        }
      };

      /**
       * Baber-Noori pinching with Foliente's parameters, written in the normalised
       * variables x = delta / z_y, w = z / z_y (z_y = y / k), so that one set of
       * dimensionless parameters serves springs of any size:
       *   dw/dx = h(w) [A - nu |w|^n (gamma + beta sgn(w x'))] / eta,  e = int w dx,
       *   h = 1 - zeta_1 exp(-((w sgn(x') - q w_u) / zeta_2)^2),
       *   w_u = (A / (nu (beta + gamma)))^(1/n), zeta_1 = zeta_s (1 - exp(-p e)),
       *   zeta_2 = (psi_0 + dpsi e)(lambda + zeta_1).
       */
      struct Pinching : ParallelBranches
      {
        double n, beta, gamma, A0, dA, dnu, deta, zeta_s, p, q, psi0, dpsi, lambda;

        template <typename T>
        T
        rate(const T &z, const T &e, const double direction, const Spring &s) const
        {
          const double z_y  = s.y / s.k;
          const T      w    = (1 / z_y) * z;
          const T      A    = A0 - dA * e;
          const T      nu   = 1 + dnu * e;
          const double psi  = gamma + beta * signum(direction * z.v);
          const T      base = (A - nu * pow_abs(w, n) * T{psi, 0}) / (1 + deta * e);
          const T      w_u  = pow(A / ((beta + gamma) * nu), 1 / n);
          const T      z1   = zeta_s * (1 - exp(-p * e));
          const T      z2   = (psi0 + dpsi * e) * (lambda + z1);
          const T      x    = (signum(direction) * w - q * w_u) / z2;
          return (1 - z1 * exp(-1.0 * x * x)) * base;
        }
        double
        energy_factor(const Spring &s) const
        {
          return s.k * s.k / (s.y * s.y); // e = int z d delta / z_y^2
        }
        double
        scale(const double, const Spring &s) const
        {
          return s.y / s.k;
        }
      };

      /**
       * The smooth law (the project's convention: beta constant, gamma the sign term)
       * with the yield value y in tension (z >= 0) and r_c y in compression:
       *   z' = delta' [1 - |z / z_y(z)|^n (beta + gamma sgn(z delta'))],
       *   z_y(z) = y / k for z >= 0, r_c y / k for z < 0;
       * continuous at z = 0, where |z|^n vanishes.
       */
      struct Asymmetric : ParallelBranches
      {
        double n, beta, gamma, ratio;

        template <typename T>
        T
        rate(const T &z, const T &, const double direction, const Spring &s) const
        {
          const double z_y = (z.v >= 0 ? 1.0 : ratio) * s.y / s.k;
          const double h2  = beta + gamma * sign(direction * z.v);
          return 1 - pow_abs((1 / z_y) * z, n) * T{h2, 0};
        }
        double
        energy_factor(const Spring &) const
        {
          return 0;
        }
        double
        scale(const double z, const Spring &s) const
        {
          return (z >= 0 ? 1.0 : ratio) * s.y / s.k;
        }
      };

      /**
       * OpenSees `BoucWenOriginal` (Schellenberg), with its dimensionless hysteretic
       * variable u = z / eps_y (eps_y = y / k):
       *   u' = delta' / eps_y [1 - |u|^n (gamma + beta sgn(u delta'))],
       *   F = q_d u + k_2 delta + k_3 sgn(delta) |delta|^mu,
       *   k_2 = alpha_L k, k_3 = alpha_NL k, q_d = y - k_2 eps_y - k_3 eps_y^mu.
       */
      struct OpenSeesBoucWenOriginal
      {
        double alpha_L, alpha_NL, mu, n, beta, gamma;

        template <typename T>
        T
        rate(const T &z, const T &, const double direction, const Spring &s) const
        {
          const double eps_y = s.y / s.k;
          const double psi   = gamma + beta * sign(direction * z.v);
          return 1 - pow_abs((1 / eps_y) * z, n) * T{psi, 0};
        }
        double
        energy_factor(const Spring &) const
        {
          return 0;
        }
        double
        q_d(const Spring &s) const
        {
          const double eps_y = s.y / s.k;
          return s.y - alpha_L * s.k * eps_y - alpha_NL * s.k * std::pow(eps_y, mu);
        }
        std::pair<double, double>
        force(const double delta, const double z, const Spring &s) const
        {
          const double k3 = alpha_NL * s.k, a = std::abs(delta);
          return {q_d(s) * z * s.k / s.y + alpha_L * s.k * delta + k3 * sign(delta) * std::pow(a, mu),
                  alpha_L * s.k + (a > 0 ? k3 * mu * std::pow(a, mu - 1) : 0.0)};
        }
        double
        force_by_z(const double, const Spring &s) const
        {
          return q_d(s) * s.k / s.y;
        }
        double
        scale(const double, const Spring &s) const
        {
          return s.y / s.k;
        }
        double
        strain_energy(const double delta, const double z, const Spring &s) const
        {
          const double a = std::abs(delta);
          return 0.5 * force_by_z(z, s) * z * z + 0.5 * alpha_L * s.k * delta * delta +
                 alpha_NL * s.k * std::pow(a, mu + 1) / (mu + 1);
        }
      };



      /**
       * The springs of one variant: state (z, e, delta) per spring. An increment Delta
       * solves r(z_1) = z_1 - z_0 - Delta g(z_1, e_0 + c Delta z_1) = 0, bracketed from
       * z_0 towards the root, by the safeguarded Newton iteration; the tangent is
       * dF/d delta + dF/dz dz_1/dDelta with dz_1/dDelta = -(dr/dDelta) / (dr/dz_1).
       */
      template <typename Law>
      class FamilySprings : public UniaxialSpringLaw
      {
      public:
        FamilySprings(const Law &law, const double yield_stress, const bool uses_yield)
          : law(law)
          , sigma_y(yield_stress)
          , uses_yield(uses_yield)
        {}

        double
        yield_stress() const override
        {
          return sigma_y;
        }

        bool
        scales_with_yield_value() const override
        {
          return uses_yield;
        }

        unsigned int
        n_state_variables() const override
        {
          return 3;
        }

        unsigned int
        add_spring(const double k, const double yield_value, double *state) override
        {
          springs.push_back(Spring{k, yield_value});
          state[0] = state[1] = state[2] = 0;
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
          return update_each_spring(n, failure, [&](const unsigned int i) {
            advance(springs[first + i], increment[i], force[i], state + 3 * i,
                    tangent ? tangent + tangent_stride * i : nullptr);
          });
        }

        double
        h1(const unsigned int spring, const double *state) const override
        {
          // |z / z_y|^n as the smooth law's H1 (z_y the law's yield deformation on z's side).
          return std::min(1.0, std::pow(std::abs(state[0]) / law.scale(state[0], springs[spring]), law.n));
        }

        double
        hysteretic_variable(const unsigned int, const double *state) const override
        {
          return state[0];
        }

        double
        strain_energy(const unsigned int spring, const double delta, const double *state) const override
        {
          return law.strain_energy(delta, state[0], springs[spring]);
        }

      private:
        /// r(z_1) with its derivative by z_1 (seed 1 on z) or by Delta (seed on Delta).
        Dual
        residual(const Spring &s, const double z0, const double e0, const Dual z1, const Dual D) const
        {
          const Dual e1 = e0 + law.energy_factor(s) * (D * z1);
          return z1 - Dual{z0, 0} - D * law.rate(z1, e1, D.v, s);
        }

        /// dz_1 / dDelta of the update from (z0, e0) by @p D that ended at @p z; for Delta = 0
        /// the loading and unloading derivatives differ: the loading one.
        double
        increment_derivative(const Spring &s, const double z0, const double e0, const double D, const double z) const
        {
          if (D == 0)
            return law.rate(Dual{z0, 0}, Dual{e0, 0}, 1.0, s).v;
          const Dual r_z = residual(s, z0, e0, Dual{z, 1}, Dual{D, 0});
          const Dual r_D = residual(s, z0, e0, Dual{z, 0}, Dual{D, 1});
          return -r_D.d / r_z.d;
        }

        /// One increment: state and force to the end; with @p tangent, dF / dDelta into it.
        void
        advance(const Spring &s, const double D, double &force, double *state, double *tangent) const
        {
          const double z0 = state[0], e0 = state[1], d0 = state[2];
          double       z  = z0;
          if (D != 0)
            z = solve(s, z0, e0, D, law.scale(z0, s));
          state[0]           = z;
          state[1]           = e0 + law.energy_factor(s) * D * z;
          state[2]           = d0 + D;
          const auto F       = law.force(state[2], z, s);
          force              = F.first;
          if (!std::isfinite(force) || !std::isfinite(state[1]))
            throw RuntimeError(failure_message("a force or energy that is not finite", D, z0));
          if (tangent)
            *tangent = F.second + law.force_by_z(z, s) * increment_derivative(s, z0, e0, D, z);
        }

        /// The root z_1: a bracket grown from z_0 against the sign of r(z_0), then Newton.
        double
        solve(const Spring &s, const double z0, const double e0, const double D, const double scale) const
        {
          const auto evaluate = [&](const double x) { return residual(s, z0, e0, Dual{x, 1}, Dual{D, 0}); };
          Dual       r0       = evaluate(z0);
          if (r0.v == 0)
            return z0;
          const double direction = r0.v > 0 ? -1.0 : 1.0;
          double       step      = std::abs(r0.v) + 1e-12 * scale;
          double       x         = z0 + direction * step;
          Dual         rx        = evaluate(x);
          for (unsigned int i = 0; (rx.v > 0) == (r0.v > 0); ++i)
            {
              if (i > 200 || !std::isfinite(rx.v))
                throw RuntimeError(failure_message("no bracket of the root", D, z0));
              step *= 2;
              x  = z0 + direction * step;
              rx = evaluate(x);
            }
          // safeguarded_newton starts from the end with r >= 0.
          double lo = z0, hi = x;
          Dual   value = rx;
          if (rx.v < 0)
            {
              std::swap(lo, hi);
              value = r0;
            }
          const double tolerance = 1e-13 * scale;
          safeguarded_newton(
            hi,
            lo,
            value,
            evaluate,
            [](const Dual r) { return std::make_pair(r.v, r.d); },
            [&](double) { return tolerance; },
            [](const double h) { return 4 * std::numeric_limits<double>::epsilon() * std::abs(h); },
            200,
            [&](const char *why, double, const Dual &) {
              throw RuntimeError(failure_message(why, D, z0));
            });
          return hi;
        }

        static std::string
        failure_message(const std::string &why, const double D, const double z0)
        {
          std::ostringstream m;
          m << "Bouc-Wen family law: " << why << " in the implicit update of a spring (increment "
            << D << ", z = " << z0 << ")";
          return m.str();
        }

        const Law           law;
        const double        sigma_y;
        const bool          uses_yield;
        std::vector<Spring> springs;
      };
    } // namespace



    std::unique_ptr<UniaxialSpringLaw>
    create_bouc_wen_variant(const BoucWenFamilyParameters &p, const double yield_stress)
    {
      switch (p.variant)
        {
          case UniaxialVariant::pinching:
            return std::make_unique<FamilySprings<Pinching>>(
              Pinching{{p.alpha}, p.n, p.beta, p.gamma, p.A0, p.delta_A, p.delta_nu, p.delta_eta,
                       p.zeta_s, p.p, p.q, p.psi0, p.delta_psi, p.lambda},
              yield_stress, true);
          case UniaxialVariant::asymmetric:
            return std::make_unique<FamilySprings<Asymmetric>>(
              Asymmetric{{p.alpha}, p.n, p.beta, p.gamma, p.compression_ratio}, yield_stress, true);
          case UniaxialVariant::opensees_bouc_wen:
            return std::make_unique<FamilySprings<OpenSeesBoucWen>>(
              OpenSeesBoucWen{{p.alpha}, p.n, p.beta, p.gamma, p.A0, p.delta_A, p.delta_nu, p.delta_eta},
              yield_stress, false);
          case UniaxialVariant::opensees_bouc_wen_original:
            return std::make_unique<FamilySprings<OpenSeesBoucWenOriginal>>(
              OpenSeesBoucWenOriginal{p.alpha_L, p.alpha_NL, p.mu, p.n, p.beta, p.gamma},
              yield_stress, true);
          default:
            throw std::logic_error("create_bouc_wen_variant: the smooth law is BoucWenUniaxial");
        }
    }
  } // namespace Material
} // namespace hysteron
