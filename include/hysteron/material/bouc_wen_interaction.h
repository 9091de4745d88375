#ifndef hysteron_material_bouc_wen_interaction_h
#define hysteron_material_bouc_wen_interaction_h

#include <deal.II/base/tensor.h>

#include <hysteron/material/bouc_wen_parameters.h>

#include <array>
#include <string>

namespace hysteron
{
  namespace Material
  {
    /**
     * The coupled ("interaction") Bouc-Wen law of a group of three springs that yield
     * together under one yield criterion in their hysteretic forces: the facet springs
     * of the RBSN method (normal, tangential, rotational; dissertation eq. 3.38-3.42),
     * usable for any three force-deformation pairs.
     *
     * <h3>The law</h3>
     * Deformations delta = (delta_n, delta_t, phi), stiffnesses k_i, yield values
     * F_y,i (F_y,n, F_y,t, M_y), post-yield ratio a, and as in the uniaxial law
     * (eq. 3.32-3.34)
     *
     *   F = a K delta + F^h,   F^h = E z,   K = diag(k_i),   E = (1 - a) K,
     *
     * with the hysteretic deformations z. The uniaxial law saturates at z_i = z_y,i =
     * F_y,i / k_i, i.e. at F^h_i = (1 - a) F_y,i =: F^h_y,i. The yield criterion is the
     * ellipsoid in hysteretic forces
     *
     *   Phi(F^h) = sqrt(sum_i (F^h_i / F^h_y,i)^2) <= 1             (eq. 3.41),
     *
     * which in the normalised variables w_i = z_i / z_y,i = F^h_i / F^h_y,i is the unit
     * sphere, Phi = |w|. With g = dPhi/dF^h (g_i = F^h_i / (F^h_y,i^2 Phi)) the rate law
     * is eq. 3.38 with the interaction matrix of eq. 3.42 (the spring form of eq. 2.35):
     *
     *   z' = (I - H1 H2 R) delta',   R = (g^T E g)^(-1) g g^T E,
     *   H1 = Phi^n,   H2 = beta + gamma sgn(g^T E delta').
     *
     * <h3>Two corrections of eq. 3.40</h3>
     * - The dissertation prints H1 = |Phi + 1|^n. With Phi normalised to 1 at yield (eq. 3.41)
     *   this is >= 1 already at F^h = 0 (the springs would flow from the start); the
     *   smooth Heaviside function of eq. 2.33 is the n-th power of the criterion
     *   normalised to 1 at yield, so H1 = Phi^n (|Phi + 1|^n would be right for a
     *   yield function written Phi - 1, i.e. if "Phi" in eq. 3.40 stood for Phi - 1).
     * - The dissertation's sign argument is F^h . delta'. We use g^T E delta', the rate of Phi
     *   of an elastic trial (the argument n : D : eps' of the triaxial law, eq. 2.33).
     *   Both agree when one component is loaded alone, but F^h . delta' weights the
     *   components differently from Phi: where F^h . delta' < 0 < g^T E delta' the
     *   "unloading" switch (H2 = 0 for beta = gamma) would let Phi grow past 1 without
     *   flow, and where g^T E delta' < 0 < F^h . delta' the flow would be
     *   negative (lambda' < 0, negative dissipation).
     * As everywhere in hysteron gamma multiplies the sign (doc/theory.md; eq. 3.36 and
     * 3.40 print beta and gamma swapped).
     *
     * <h3>Derivation (in w)</h3>
     * With Z = diag(z_y,i), w = Z^(-1) z and d = Z^(-1) delta (deformations in units of
     * the yield deformations):
     *   E g = w / (Phi z_y)   (componentwise: (1 - a) k_i w_i / (F^h_y,i Phi) = w_i / (z_y,i Phi)),
     *   g^T E delta' = (w . d') / Phi,
     *   g^T E g = sum_i c_i w_i^2 / Phi^2,   c_i = 1 / (F^h_y,i z_y,i) [1/J],
     * and with R delta' = g (g^T E delta') / (g^T E g), Z^(-1) g = C w / Phi (C = diag(c_i)):
     *
     *   w' = d' - H1 H2 (C w) (w . d') / (w^T C w),   H2 = beta + gamma sgn(w . d').
     *
     * Only the ratios of the c_i matter; the code uses c_i / max_j c_j. The plastic
     * deformation rate delta' - z' is along Z C w, i.e. along g: the flow is associated
     * in F^h space, with the energy metric E.
     * - Consistency: Phi Phi' = w . w' = (w . d') (1 - H1 H2 (w^T C w) / (w^T C w)) =
     *   (1 - H1 H2) (w . d'). With H1 H2 = 1 on the surface, Phi' = 0: the flow keeps
     *   Phi = 1. For beta + gamma = 1, Phi = 1 is the attractor of loading; in general
     *   the saturation value is Phi_s = (beta + gamma)^(-1/n), as in the uniaxial law.
     * - One component loaded alone (w = w_1 e_1, d' = d'_1 e_1, from a state with the
     *   other components zero): (C w)(w . d') / (w^T C w) = c_1 w_1 w_1 d'_1 / (c_1 w_1^2)
     *   = d'_1 e_1, so w'_1 = d'_1 (1 - |w_1|^n (beta + gamma sgn(w_1 d'_1))) and the
     *   other components stay zero: exactly the uniaxial law (eq. 3.36). Hence the same
     *   yield values F_y,i in pure axial, shear or bending, and with beta = gamma = 1/2
     *   elastic unloading (H2 = 0 for w . d' < 0).
     * - Tangent: F' = D_t delta' with D_t = a K + E (I - H1 H2 R) =
     *   a K - H1 H2 (E g)(E g)^T / (g^T E g) + E: symmetric (continuum form).
     *
     * <h3>Integrators (the material's Integrator), over one increment Delta delta</h3>
     * The rates are integrated in pseudo time s in [0, 1] (d' = Delta d), as in the
     * uniaxial law.
     * - forward euler: w1 = w0 + f(w0) (one evaluation, the dissertation's scheme),
     *   tangent the derivative of this update, I - H1 H2 (C w0) w0^T / (w0^T C w0) in w.
     * - adaptive: Bogacki-Shampine 3(2) with error control (bogacki_shampine_32(), the
     *   uniaxial law's loop), error of w (i.e. of z_i / z_y,i) against the Tolerance, and
     *   after each sub-step the projection w -> w Phi_s / Phi if Phi > Phi_s. The ball
     *   Phi <= Phi_s is invariant for the exact flow (on its boundary
     *   Phi' = (1 - H1 H2)(w . d') / Phi <= 0 in both branches, since
     *   (beta - gamma) / (beta + gamma) < 1), and the radial scaling is the Euclidean
     *   closest-point projection onto it, so it can only reduce the error of w. Tangent:
     *   the continuum tangent at the end state.
     * - backward euler: r(w) = w - w_tr + H2 q(w) C w = 0, w_tr = w0 + Delta d,
     *   q = Phi^n (w . Delta d) / (w^T C w), H2 of the end state. This is a closest-point
     *   structure: with mu = H2 q, w = (I + mu C)^(-1) w_tr componentwise, so the three
     *   equations reduce exactly to one in mu,
     *     g(mu) = mu - H2 Phi(mu)^n (w(mu) . Delta d) / (w(mu)^T C w(mu)) = 0,
     *   and for any mu, r(w(mu)) = -g(mu) C w(mu): |r| <= Phi |g|. A root with mu > 0
     *   has w . Delta d > 0 and a root with mu < 0 has w . Delta d < 0 (from g = 0), so
     *   the branch of H2 is decided by the elastic trial: w_tr . Delta d > 0: loading,
     *   H2 = beta + gamma, g(0) < 0 and g -> +infinity, a root in mu > 0 always exists;
     *   w_tr . Delta d < 0: H2 = beta - gamma (0 for beta = gamma: exactly elastic),
     *   root in (-1/max c_i, 0). The scalar equation is solved by a bracketed Newton
     *   iteration with the analytic derivative (bisection where Newton leaves the
     *   bracket); no bracket or no convergence is a RuntimeError. The consistent 3x3
     *   tangent follows from the implicit function theorem on the full residual,
     *   dw/d(Delta d) = -(dr/dw)^(-1) dr/d(Delta d) (H2 fixed: the branch is locally
     *   constant). It is not symmetric in general.
     * Every tangent is returned in physical units, D_t = a K + E Z (dw/dd) Z^(-1).
     *
     * <h3>Degradation</h3>
     * Not supported (unsupported() says so, and reinit() throws): the uniaxial law's
     * intrinsic time xi' = |delta_p'| and its energy scale F_y z_y belong to one spring;
     * for the coupled facet the plastic deformation (delta_n, delta_t in m, phi in rad)
     * has no unique norm and the three springs no common energy scale, so eta and nu_s
     * would be a new model, not the dissertation's.
     *
     * <h3>State</h3>
     * The three hysteretic deformations z = (z_n, z_t, z_phi) (the units of delta),
     * read and written through a pointer and a stride (the RBSN stores them in the
     * slots of its uniaxial springs).
     */
    class BoucWenInteraction
    {
    public:
      using Vector = std::array<double, 3>;
      using Matrix = dealii::Tensor<2, 3>;

      /// Sub-step attempts (adaptive) and iterations (backward Euler) before a RuntimeError.
      static constexpr unsigned int max_substeps   = 100000;
      static constexpr unsigned int max_iterations = 200;

      BoucWenInteraction() = default;

      BoucWenInteraction(const BoucWenParameters &parameters,
                         const Vector            &stiffness,
                         const Vector            &yield_values);

      /// Throws std::invalid_argument for non-positive values or unsupported() parameters.
      void
      reinit(const BoucWenParameters &parameters,
             const Vector            &stiffness,
             const Vector            &yield_values);

      /// Why the law cannot use @p parameters (degradation), or "" if it can.
      static std::string
      unsupported(const BoucWenParameters &parameters);

      const BoucWenParameters &
      parameters() const
      {
        return prm;
      }

      /// z_y,i = F_y,i / k_i.
      const Vector &
      yield_deformations() const
      {
        return z_y;
      }

      /// z = 0.
      void
      initialize_state(double *z, const unsigned int stride = 1) const
      {
        for (unsigned int i = 0; i < 3; ++i)
          z[i * stride] = 0;
      }

      /// Phi = |w| = sqrt(sum_i (z_i / z_y,i)^2) = sqrt(sum_i (F^h_i / F^h_y,i)^2).
      double
      yield_function(const double *z, const unsigned int stride = 1) const;

      /// H1 = Phi^n.
      double
      h1(const double *z, const unsigned int stride = 1) const;

      /// F = a K delta + (1 - a) K z.
      Vector
      forces(const Vector &delta, const double *z, const unsigned int stride = 1) const;

      /**
       * The rate law z' = (I - H1 H2 R) delta' at the state @p z for the deformation
       * rate @p delta_rate (or an increment: the law is rate independent), into
       * @p z_rate. For integrators of the whole system (the variable-order analysis).
       */
      void
      rates(const double       *z,
            const Vector       &delta_rate,
            double             *z_rate,
            const unsigned int  stride = 1) const;

      /// dF/d delta = a K + E (I - H1 H2 R) at @p z, H2 with the sign for the
      /// direction @p delta_rate (0: H2 = beta, the mean of loading and unloading).
      Matrix
      continuum_tangent(const double *z, const Vector &delta_rate, const unsigned int stride = 1)
        const;

      /**
       * Advance by the increment @p ddelta with the integrator of the parameters.
       * @p force: in, F at the start; out, at the end (F += a K ddelta + E (z1 - z0)).
       * @p z: the state (stride @p stride). @p tangent: nullptr, or receives dF1/d ddelta.
       * Returns the work: 1 (forward Euler), accepted sub-steps (adaptive), Newton
       * iterations (backward Euler). Failures are RuntimeErrors.
       */
      unsigned int
      update(const Vector      &ddelta,
             Vector            &force,
             double            *z,
             Matrix            *tangent,
             const unsigned int stride = 1) const;

    private:
      BoucWenParameters prm;
      Vector            k{{1, 1, 1}}, z_y{{1, 1, 1}}, inv_z_y{{1, 1, 1}};
      Vector            c{{1, 1, 1}}; ///< c_i / max_j c_j, c_i = 1 / (F^h_y,i z_y,i)
      double            a = 0, n = 8, beta = 0.5, gamma = 0.5, tolerance = 1e-6;
      unsigned int      n_integer    = 0; ///< n if an integer in [1, 64], else 0
      double            phi_saturation = 1; ///< (beta + gamma)^(-1/n)

      /// H1 = Phi^n from Phi^2 (no square root for even integer n).
      double
      h1_of_squared(const double phi2) const;

      /// w' for d' in w variables; H2 = beta + gamma sgn(w . d).
      Vector
      rates_w(const Vector &w, const Vector &d) const;

      /// dw1/dd of the continuum law at w (the forward Euler derivative).
      Matrix
      tangent_w(const Vector &w, const Vector &d) const;

      unsigned int
      backward_euler(Vector &w, const Vector &d, Matrix *dw_dd) const;

      [[noreturn]] void
      fail(const std::string &what, const Vector &w, const Vector &d) const;
    };
  } // namespace Material
} // namespace hysteron

#endif
