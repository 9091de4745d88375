#ifndef hysteron_material_bouc_wen_uniaxial_h
#define hysteron_material_bouc_wen_uniaxial_h

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
      /// may be zero (then eta stays 1 and e_h is only book-kept). The library
      /// instantiates all six variants (source/material/bouc_wen_uniaxial.cc).
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

    /// The recoverable energy 1/2 a k delta^2 + 1/2 (1 - a) k z^2 of a Bouc-Wen spring
    /// with post-yield ratio @p a, stiffness @p k, deformation @p delta and state @p z.
    inline double
    bouc_wen_strain_energy(const double a, const double k, const double delta, const double z)
    {
      return 0.5 * a * k * delta * delta + 0.5 * (1 - a) * k * z * z;
    }
  } // namespace Material
} // namespace hysteron

#endif
