#ifndef hysteron_material_bouc_wen_uniaxial_h
#define hysteron_material_bouc_wen_uniaxial_h

#include <hysteron/material/bogacki_shampine.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/integer_power.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    /**
     * The uniaxial (one-component) smooth Bouc-Wen law with optional stiffness
     * degradation and strength deterioration, for a 1D stress-strain point or a
     * spring (force-displacement). It works on a generic "stiffness" k and
     * "yield value" y: k = E and y = sigma_y for stresses and strains,
     * k = spring stiffness and y = F_y for the springs of the RBSN method
     * (eq. 3.32-3.36). With z_y = y / k (the yield strain eps_y, resp. the yield
     * displacement):
     *
     *   sigma = a k eps + (1 - a) k z,
     *   z'    = eps' / eta [1 - nu_s |z/z_y|^n (beta + gamma sgn(z eps'))],
     *
     * (eq. 2.3, 2.5, 2.37; gamma multiplies the sign term, doc/theory.md; eq. 3.36
     * prints beta and gamma swapped). We write H1 = |z/z_y|^n and
     * H2 = beta + gamma sgn(z eps') as in eq. 2.33.
     *
     * <h3>Closed forms</h3>
     * Monotonic loading from z = 0 with beta + gamma = 1, no degradation, and
     * x = eps / z_y, u = z / z_y: du/dx = 1 - u^n, so n = 1 gives u = 1 - exp(-x),
     * n = 2 gives u = tanh(x), and for every n the stress saturates on the line
     * a k eps + (1 - a) y. With beta = gamma = 1/2, H2 = 0 on unloading
     * (sgn(z eps') < 0), so unloading is exactly elastic: z' = eps' / eta.
     *
     * <h3>Degradation (the project's dimensionally consistent form)</h3>
     * The dissertation's eq. 2.41 and 2.45 define the intrinsic time xi with different
     * units (strain rate in 2.41, stress times strain rate in 2.45) and put
     * factors beta, nu_s and (z/z_y)^(n-1) in different places. We use the
     * endochronic form of Erlicher and Bursi with strain units throughout.
     * The plastic strain rate of the hysteretic element (spring (1 - a) k / eta
     * in series with a slider) is the part of eps' that does not change z:
     *
     *   eps_p' = eps' - eta z' = nu_s H1 H2 eps'             (from the z' equation),
     *
     * and the intrinsic time is its absolute value (H2 >= 0 since |gamma| <= beta):
     *
     *   xi'   = |eps' - eta z'| = nu_s H1 H2 |eps'|,
     *   eta'  = c_eta eta^(-m_u) xi',                 eta(0) = 1,
     *   e_h'  = (1 - a) k z (eps' - eta z'),          e_h(0) = 0,
     *   nu_s  = 1 + c_nu e_h / (y z_y)                (= 1 + c_nu e_h / (sigma_y eps_y)).
     *
     * Mapping to the dissertation: eq. 2.42, eta' = c_eta eta^(-m_u) beta nu_s xi_diss',
     * with xi_diss' = (1 + gamma/beta sgn(z eps')) H1 |eps'| (eq. 2.45 with the
     * strain rate in place of sigma^T eps'), is exactly our eta' since
     * beta (1 + gamma/beta sgn) = H2. eta is the dissertation's n_s of eq. 2.37-2.38, and
     * nu_s is eq. 2.38 with e_h normalised by the elastic energy density scale
     * y z_y = sigma_y^2 / E, so that c_nu is dimensionless. With Table 2-2
     * (c_eta = 30, m_u = 1, c_nu = 0.001, three cycles of 0.6 %) this gives
     * eta = 1.993 and nu_s = 1.043 at the end; the plateau of z falls by
     * nu_s^(-1/n) = 0.26 % (n = 16), the peak stress by 0.16 % from cycle 1 to 3
     * (prm/bouc_wen_degradation.prm). e_h is the energy dissipated by the slider
     * (J/m^3, or J for springs): over a closed cycle without degradation its
     * increase equals the loop area of (eps, sigma), since
     * oint (1 - a) k z (d eps - dz) = oint sigma d eps. Within a cycle it can
     * decrease slightly when beta > gamma (negative plastic work on unloading,
     * a known property of the Bouc-Wen law); with beta = gamma it never does.
     * Erlicher and Bursi's admissibility condition eq. 2.40, eta' <= eta nu xi',
     * reads c_eta eta^(-m_u) <= eta nu_s here; it is not enforced (Table 2-2's
     * c_eta = 30 does not satisfy it at the start).
     *
     * <h3>State</h3>
     * A flat array of doubles per point, named by StateIndex: z, and with
     * degradation eta and e_h (nu_s is derived). Without degradation
     * (c_eta = c_nu = 0) the state is z alone and no degradation work is done:
     * the kernels are templates on `degrading`, chosen once per call of update().
     * H1 and H2 are not stored; h1() and h2() derive them for output.
     *
     * <h3>Integration over one increment deps</h3>
     * The rate equations are integrated in pseudo-time over the increment
     * (eps' = deps, so y(1) = y(0) + int_0^1 f(y) ds):
     * - forward euler: one evaluation at the start state (first order; stable
     *   only for deps / z_y <~ 2 / n, doc/theory.md); a step that ends farther
     *   beyond the saturation value z_s than one increment can reach from inside
     *   it (the scheme has become unstable, inf and NaN follow) is a RuntimeError;
     * - adaptive: Bogacki-Shampine 3(2) with first-same-as-last and error
     *   control (error of z scaled by z_y, of eta absolute, of e_h by y z_y,
     *   each per sub-step against the Tolerance; the third-order solution is
     *   kept); the whole increment is tried first; at most max_substeps
     *   attempts, else RuntimeError. After each sub-step z is projected onto
     *   |z| <= z_s = z_y (beta + gamma)^(-1/n), a set the exact solution never
     *   leaves (while nu_s >= 1), so |z| never exceeds the saturation value;
     * - backward euler: implicit in z, eta and e_h; eta and e_h are eliminated
     *   exactly for a given z (see implicit_residual()), so the local problem
     *   is a scalar equation in z_{n+1}, solved by a bracketed (safeguarded)
     *   Newton iteration with the analytic derivative. The sign term uses
     *   sgn(z_{n+1} deps) at the current iterate: since H1 = 0 at z = 0 the
     *   residual is continuous across the sign switch, so the bracket always
     *   contains the root and bisection takes over where Newton would jump
     *   across the kink. Non-convergence is a RuntimeError.
     *
     * Every integrator returns the tangent d sigma / d deps of its own update:
     * forward Euler k (a + (1 - a) (1 - nu_s H1 H2) / eta) at the start state;
     * adaptive the same expression at the end state (the derivative of the
     * exact flow with respect to its length, hence consistent to the
     * tolerance); backward Euler the consistent algorithmic tangent
     * -k (1 - a) (dr/d deps) / (dr/dz_{n+1}) + a k. For deps = 0 the tangent uses
     * H2 = beta (sgn = 0), the mean of the loading and unloading tangents.
     */
    class BoucWenUniaxial
    {
    public:
      /// The slots of the per-point state.
      enum StateIndex : unsigned int
      {
        z_index      = 0, ///< hysteretic variable z (strain or displacement units)
        eta_index    = 1, ///< stiffness degradation eta >= 1 (degradation only)
        energy_index = 2  ///< dissipated energy e_h (degradation only)
      };

      /// The largest state (with degradation).
      static constexpr unsigned int max_n_state_variables = 3;

      /// Sub-step attempts of the adaptive integrator, iterations of the
      /// implicit one, before a RuntimeError.
      static constexpr unsigned int max_substeps   = 100000;
      static constexpr unsigned int max_iterations = 200;

      BoucWenUniaxial() = default;

      /// The law for stresses: k = @p stiffness (E), y = parameters.yield_stress.
      BoucWenUniaxial(const BoucWenParameters &parameters, const double stiffness);

      /// The law for a spring: stiffness k and yield force (or moment) @p yield_value.
      BoucWenUniaxial(const BoucWenParameters &parameters,
                      const double             stiffness,
                      const double             yield_value);

      void
      reinit(const BoucWenParameters &parameters, const double stiffness, const double yield_value);

      const BoucWenParameters &
      parameters() const
      {
        return prm;
      }

      double
      stiffness() const
      {
        return k;
      }

      double
      yield_value() const
      {
        return y;
      }

      /// z_y = y / k (the yield strain or displacement).
      double
      yield_deformation() const
      {
        return z_y;
      }

      bool
      degradation() const
      {
        return degrading;
      }

      /// 1 (z) or 3 (z, eta, e_h).
      unsigned int
      n_state_variables() const
      {
        return degrading ? 3 : 1;
      }

      /// "z" and, with degradation, "eta", "e_h".
      std::vector<std::string>
      state_variable_names() const;

      /// The virgin state: z = 0, eta = 1, e_h = 0.
      void
      initialize_state(double *state) const
      {
        state[z_index] = 0;
        if (degrading)
          {
            state[eta_index]    = 1;
            state[energy_index] = 0;
          }
      }

      /// sigma = a k eps + (1 - a) k z.
      double
      stress(const double strain, const double *state) const
      {
        return a * k * strain + k_h * state[z_index];
      }

      /// nu_s = 1 + c_nu e_h / (y z_y) (1 without degradation).
      double
      nu_s(const double *state) const
      {
        return degrading ? 1 + c_nu_scaled * state[energy_index] : 1.0;
      }

      /// H1 = |z / z_y|^n.
      double
      h1(const double *state) const
      {
        return abs_pow(state[z_index] * inv_z_y);
      }

      /// H2 = beta + gamma sgn(z deps).
      double
      h2(const double *state, const double deps) const
      {
        return beta_plus_gamma_sign(state[z_index] * deps);
      }

      /**
       * The time rates of the state for the deformation rate @p deformation_rate
       * (eps', or delta' of a spring), for an integrator of the state in physical
       * time (the RBSN's variable-order analysis): @p state_rate receives
       * n_state_variables() values,
       *
       *   z' = eps' (1 - nu_s H1 H2) / eta,  eta' = c_eta eta^(-m_u) |eps' - eta z'|,
       *   e_h' = (1 - a) k z (eps' - eta z'),
       *
       * the right-hand side that update() integrates in pseudo-time (the rates
       * are homogeneous of degree one in eps'). The Integrator of the parameters
       * plays no part.
       */
      void
      state_rate(const double *state, const double deformation_rate, double *state_rate) const;

      /**
       * The derivatives of state_rate(): @p d_state (n x n, row-major,
       * d rate_i / d state_j) and @p d_deformation_rate (n values, d rate_i / d eps'),
       * n = n_state_variables(). The rates are smooth except where z eps' changes
       * sign (H2 jumps; the rates stay continuous because they carry the factor
       * eps' and H1 = 0 at z = 0): there the derivatives use sgn = 0, H2 = beta,
       * the mean of the loading and unloading branches, as the tangent of
       * update() does for deps = 0; likewise d|g|/dg = 0 at g = 0.
       */
      void
      state_rate_derivatives(const double *state,
                             const double  deformation_rate,
                             double       *d_state,
                             double       *d_deformation_rate) const;

      /**
       * Advance one point by the increment @p deps with the integrator of the
       * parameters. @p stress: in, the stress at the start; out, at the end
       * (sigma_{n+1} = sigma_n + a k deps + (1 - a) k (z_{n+1} - z_n)).
       * @p state: n_state_variables() doubles. @p tangent: nullptr, or receives
       * d sigma_{n+1} / d deps. Returns the work done: 1 (forward Euler), the
       * accepted sub-steps (adaptive), the Newton iterations (backward Euler).
       */
      unsigned int
      update(const double deps, double &stress, double *state, double *tangent = nullptr) const;

      /**
       * update() for @p n points: deps[i], stresses[i], the state of point i at
       * states + i * n_state_variables(), tangents nullptr or n values. The
       * integrator and the degradation switch are dispatched once. No
       * allocation. Returns the summed work.
       */
      unsigned long
      update(const unsigned int n,
             const double      *deps,
             double            *stresses,
             double            *states,
             double            *tangents) const;

      /**
       * Call @p function(std::integral_constant<bool, degrading>,
       * std::integral_constant<BoucWenIntegrator, integrator>) with the variant
       * of this law: the one run-time dispatch for a loop of update_point()
       * calls (as in the batch update()).
       */
      template <typename Function>
      decltype(auto)
      dispatch(Function &&function) const;

      /// The kernel behind update(), for a fixed variant (no dispatch). With
      /// degrading = true the state must have 3 slots; the constants c_eta, c_nu
      /// may be zero (then eta stays 1 and e_h is only book-kept).
      template <bool degrading_, BoucWenIntegrator integrator_>
      unsigned int
      update_point(const double deps, double &stress, double *state, double *tangent) const;

    private:
      /// State vector of the integrators: z (and eta, e_h).
      template <bool degrading_>
      using Vector = std::array<double, degrading_ ? 3 : 1>;

      BoucWenParameters prm;
      bool              degrading    = false;
      double            k            = 1;
      double            y            = 1;
      double            z_y          = 1;
      double            inv_z_y      = 1;
      double            a            = 0;
      double            k_h          = 1; ///< (1 - a) k
      double            n            = 1;
      unsigned int      n_integer    = 0; ///< n if it is an integer in [1, 64], else 0
      double            beta         = 0.5;
      double            gamma        = 0.5;
      double            c_eta        = 0;
      double            m_u          = 1;
      double            c_nu_scaled  = 0; ///< c_nu / (y z_y)
      double            tolerance    = 1e-6;
      double            energy_scale = 1; ///< y z_y, the error scale of e_h
      double            z_saturation = 1; ///< z_y (beta + gamma)^(-1/n)

      /// |x|^n, by repeated squaring for integer n (the common n = 1, 2, 8, 16).
      double
      abs_pow(const double x) const
      {
        const double ax = std::abs(x);
        if (n_integer > 0)
          return integer_power(ax, n_integer);
        return std::pow(ax, n);
      }

      /// beta + gamma sgn(s).
      double
      beta_plus_gamma_sign(const double s) const
      {
        return s > 0 ? beta + gamma : (s < 0 ? beta - gamma : beta);
      }

      /// eta^(-m_u).
      double
      eta_power(const double eta) const
      {
        if (m_u == 1)
          return 1 / eta;
        if (m_u == 0)
          return 1;
        return std::pow(eta, -m_u);
      }

      /// dy/ds of the pseudo-time integration over the increment deps.
      template <bool degrading_>
      Vector<degrading_>
      rates(const Vector<degrading_> &v, const double deps) const;

      /// dz_{n+1}/d deps = (1 - nu_s H1 H2) / eta at @p v (H2 with sgn(z deps)).
      template <bool degrading_>
      double
      rate_tangent(const Vector<degrading_> &v, const double deps) const;

      /// The implicit (backward Euler) residual as a function of z_{n+1} alone.
      struct Residual
      {
        double r;        ///< eta (z - z_n) - deps + g  [strain]
        double dr_dz;    ///< total derivative (eta, e_h eliminated)
        double dr_ddeps; ///< partial derivative at fixed z
        double eta;      ///< eta_{n+1}(z)
        double energy;   ///< e_h,{n+1}(z)
      };

      template <bool degrading_>
      Residual
      implicit_residual(const double z, const double deps, const Vector<degrading_> &v0) const;

      /// Solve eta - eta_n - c_eta eta^(-m_u) xi = 0 for eta (increasing in eta,
      /// concave: Newton from eta_n converges monotonically), and give
      /// d eta / d xi.
      void
      implicit_eta(const double eta_n, const double xi, double &eta, double &deta_dxi) const;

      template <bool degrading_>
      unsigned int
      integrate_adaptive(Vector<degrading_> &v, const double deps) const;

      template <bool degrading_>
      unsigned int
      integrate_backward_euler(Vector<degrading_> &v, const double deps, double &dz_ddeps) const;

      [[noreturn]] void
      throw_not_finite(const double deps, const double z) const;
      [[noreturn]] void
      throw_unstable(const double deps, const double z0, const double z) const;
      [[noreturn]] void
      throw_too_many_substeps(const double deps, const double z) const;
      [[noreturn]] void
      throw_no_convergence(const double       deps,
                           const double       z,
                           const double       residual,
                           const std::string &why) const;
    };



    // ---------------------------------------------------------------------------
    // Inline kernels
    // ---------------------------------------------------------------------------

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
      double       z          = hi;
      unsigned int iterations = 0;
      while (res.r != 0)
        {
          if (++iterations > max_iterations)
            throw_no_convergence(deps, z, res.r, "too many iterations");
          if (res.r < 0)
            lo = z;
          else
            hi = z;
          double       step = res.r / res.dr_dz;
          const double next = z - step;
          if (!std::isfinite(step) || (next - lo) * (next - hi) > 0)
            step = z - 0.5 * (lo + hi);
          z -= step;
          res = rho(z);
          if (std::isnan(res.r))
            throw_no_convergence(deps, z, res.r, "the residual is not a number");
          if (std::abs(step) <= tolerance * z_y && std::abs(res.r) <= tolerance * z_y &&
              std::isfinite(res.dr_dz))
            break;
          if (std::abs(lo - hi) <= 4 * std::numeric_limits<double>::epsilon() * z_y)
            break; // the bracket has collapsed to round-off
        }

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
    inline unsigned int
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



    inline void
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



    inline void
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



    template <typename Function>
    inline decltype(auto)
    BoucWenUniaxial::dispatch(Function &&function) const
    {
      using I         = BoucWenIntegrator;
      const auto call = [&](auto integrator) -> decltype(auto) {
        return degrading ? function(std::true_type(), integrator) :
                           function(std::false_type(), integrator);
      };
      switch (prm.integrator)
        {
          case I::forward_euler:
            return call(std::integral_constant<I, I::forward_euler>());
          case I::adaptive:
            return call(std::integral_constant<I, I::adaptive>());
          default:
            return call(std::integral_constant<I, I::backward_euler>());
        }
    }



    inline unsigned int
    BoucWenUniaxial::update(const double deps, double &stress, double *state, double *tangent) const
    {
      return dispatch([&](auto degrading_, auto integrator_) {
        return update_point<degrading_, integrator_>(deps, stress, state, tangent);
      });
    }
  } // namespace Material
} // namespace hysteron

#endif
