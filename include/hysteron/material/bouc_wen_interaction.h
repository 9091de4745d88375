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
     * The coupled ("interaction") Bouc-Wen law of a group of N springs that yield together
     * under one yield criterion in their hysteretic forces: the facet springs of the RBSN
     * method (dissertation eq. 3.38-3.42), N = 3 in 2D (normal, tangential, rotational) and
     * N = 6 in 3D (normal, two shear, two bending, torsion), usable for any N
     * force-deformation pairs. Explicitly instantiated for N = 3 and N = 6.
     *
     * <h3>The law</h3>
     * Deformations delta = (delta_1, ..., delta_N) (2D: delta_n, delta_t, phi; 3D: delta_n,
     * delta_1, delta_2, phi_1, phi_2, phi_n), stiffnesses k_i, yield values F_y,i (2D: F_y,n,
     * F_y,t, M_y; 3D: N_y, V_y,1, V_y,2, M_y,1, M_y,2, T_y), post-yield ratio a, and as in the
     * uniaxial law (eq. 3.32-3.34)
     *
     *   F = a K delta + F^h,   F^h = E z,   K = diag(k_i),   E = (1 - a) K,
     *
     * with the hysteretic deformations z. The uniaxial law saturates at z_i = z_y,i =
     * F_y,i / k_i, i.e. at F^h_i = (1 - a) F_y,i =: F^h_y,i. The yield criterion is the
     * ellipsoid in hysteretic forces
     *
     *   Phi(F^h) = sqrt(sum_{i=1}^N (F^h_i / F^h_y,i)^2) <= 1        (eq. 3.41),
     *
     * which in the normalised variables w_i = z_i / z_y,i = F^h_i / F^h_y,i is the unit
     * sphere of R^N, Phi = |w|. With g = dPhi/dF^h (g_i = F^h_i / (F^h_y,i^2 Phi)) the rate
     * law is eq. 3.38 with the interaction matrix of eq. 3.42 (the spring form of eq. 2.35):
     *
     *   z' = (I - H1 H2 R) delta',   R = (g^T E g)^(-1) g g^T E,
     *   H1 = Phi^n,   H2 = beta + gamma sgn(g^T E delta').
     *
     * Nothing in the law or below depends on N: E, K, Z and C are diagonal, so every
     * step is componentwise, and the only coupling is through the scalars Phi^2 = w . w,
     * w . d and w^T C w.
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
     * the yield deformations), componentwise for i = 1..N:
     *   (E g)_i = (1 - a) k_i F^h_i / (F^h_y,i^2 Phi) = w_i / (z_y,i Phi),
     *   g^T E delta' = sum_i w_i delta'_i / (z_y,i Phi) = (w . d') / Phi,
     *   g^T E g = sum_i c_i w_i^2 / Phi^2,   c_i = 1 / (F^h_y,i z_y,i) [1/J],
     * and with R delta' = g (g^T E delta') / (g^T E g), (Z^(-1) g)_i = c_i w_i / Phi
     * (C = diag(c_i)):
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
     * - One component loaded alone (w = w_m e_m, d' = d'_m e_m, from a state with the
     *   other components zero): (C w)(w . d') / (w^T C w) = c_m w_m w_m d'_m e_m /
     *   (c_m w_m^2) = d'_m e_m, so w'_m = d'_m (1 - |w_m|^n (beta + gamma sgn(w_m d'_m)))
     *   and the other N - 1 components stay zero: exactly the uniaxial law (eq. 3.36).
     *   Hence the same yield values F_y,i in pure axial, shear, bending or torsion, and
     *   with beta = gamma = 1/2 elastic unloading (H2 = 0 for w . d' < 0).
     * - Proportional loading d' = d_0 t': the flow saturates where the flow direction C w
     *   is parallel to d_0 and Phi = Phi_s, i.e. w = Phi_s C^(-1) d_0 / |C^(-1) d_0|.
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
     *   structure: with mu = H2 q, (I + mu C) w = w_tr, i.e. w_i = w_tr,i / (1 + mu c_i)
     *   (C diagonal), so the N equations reduce exactly to one in mu,
     *     g(mu) = mu - H2 Phi(mu)^n (w(mu) . Delta d) / (w(mu)^T C w(mu)) = 0,
     *   and for any mu, r(w(mu)) = -g(mu) C w(mu): |r| <= Phi |g|. A root with mu > 0
     *   has w . Delta d > 0 and a root with mu < 0 has w . Delta d < 0 (from g = 0), so
     *   the branch of H2 is decided by the elastic trial: w_tr . Delta d > 0: loading,
     *   H2 = beta + gamma, g(0) < 0 and g -> +infinity, a root in mu > 0 always exists;
     *   w_tr . Delta d < 0: H2 = beta - gamma (0 for beta = gamma: exactly elastic),
     *   root in (-1/max c_i, 0). A loading step does not leave the ball Phi <= Phi_s: at
     *   a root, w . w = w . w_tr - mu w^T C w = w . w0 + (w . Delta d)(1 - H1 H2), and
     *   Phi > Phi_s (H1 H2 > 1) with w . Delta d > 0 would give w . w < w . w0 <= Phi Phi0,
     *   i.e. Phi < Phi0 <= Phi_s, a contradiction (an unloading step likewise ends with
     *   Phi <= Phi0 wherever H1 (beta - gamma) <= 1; for beta = gamma it is elastic with
     *   w . w = w . w0 + w . Delta d < w . w0). The scalar equation is solved by a bracketed Newton
     *   iteration with the analytic derivative (bisection where Newton leaves the
     *   bracket); no bracket or no convergence is a RuntimeError. The consistent N x N
     *   tangent follows from the implicit function theorem on the full residual,
     *   dw/d(Delta d) = -(dr/dw)^(-1) dr/d(Delta d) (H2 fixed: the branch is locally
     *   constant), with
     *     dr/dw = I + H2 (q C + (C w) (x) dq/dw),   dr/d(Delta d) = -I + H2 (C w) (x) dq/dd,
     *     dq/dw_j = H1 (n P w_j / Phi^2 + Delta d_j - 2 P c_j w_j / A) / A,
     *     dq/dd_j = H1 w_j / A,   P = w . Delta d,   A = w^T C w
     *   (dPhi^n/dw_j = n Phi^(n-2) w_j). It is not symmetric in general. The N x N system
     *   is solved by LU with partial pivoting; N = 3 keeps the closed-form 3 x 3 inverse
     *   it has always used, so that 2D results are unchanged to the bit.
     * Every tangent is returned in physical units, D_t = a K + E Z (dw/dd) Z^(-1).
     *
     * <h3>Degradation</h3>
     * Not supported (unsupported() says so, and reinit() throws): the uniaxial law's
     * intrinsic time xi' = |delta_p'| and its energy scale F_y z_y belong to one spring;
     * for the coupled facet the plastic deformation (translations in m, rotations in rad)
     * has no unique norm and the N springs no common energy scale, so eta and nu_s
     * would be a new model, not the dissertation's.
     *
     * <h3>State</h3>
     * The N hysteretic deformations z = (z_1, ..., z_N) (the units of delta), read and
     * written through a pointer and a stride.
     */
    template <unsigned int N>
    class BoucWenInteraction
    {
      static_assert(N >= 1, "BoucWenInteraction needs at least one component");

    public:
      static constexpr unsigned int n_components = N;
      using Vector = std::array<double, N>;
      using Matrix = dealii::Tensor<2, N>;

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

      /// Phi_s = (beta + gamma)^(-1/n), the value of Phi at saturation.
      double
      saturation() const
      {
        return phi_saturation;
      }

      /// z = 0.
      void
      initialize_state(double *z, const unsigned int stride = 1) const
      {
        for (unsigned int i = 0; i < N; ++i)
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
      /// (1, ..., 1), the values before reinit().
      static constexpr Vector
      ones()
      {
        Vector v{};
        for (unsigned int i = 0; i < N; ++i)
          v[i] = 1;
        return v;
      }

      BoucWenParameters prm;
      Vector            k = ones(), z_y = ones(), inv_z_y = ones();
      Vector            c = ones(); ///< c_i / max_j c_j, c_i = 1 / (F^h_y,i z_y,i)
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

      /// The reduced backward Euler equation of backward_euler() at nu = s mu >= 0:
      /// w(mu) = w_tr / (1 + mu c), G(nu) = s g(s nu) and its derivative, and what the
      /// tangent needs at w.
      struct Reduced
      {
        double G, dG; ///< s g and dg/dmu (= dG/dnu)
        Vector w;
        double phi2, h1, P, A;
      };

      Reduced
      reduced(const Vector &w_tr, const Vector &d, const double s, const double H2, const double nu)
        const;

      /// dw1/dd of the backward Euler solution v.w (implicit function theorem).
      void
      implicit_tangent(const Vector &d, const Reduced &v, const double H2, Matrix &dw_dd) const;

      unsigned int
      backward_euler(Vector &w, const Vector &d, Matrix *dw_dd) const;

      [[noreturn]] void
      fail(const std::string &what, const Vector &w, const Vector &d) const;
    };

    // The instantiations in bouc_wen_interaction.cc: the 2D and the 3D RBSN facet.
    extern template class BoucWenInteraction<3>;
    extern template class BoucWenInteraction<6>;
  } // namespace Material
} // namespace hysteron

#endif
