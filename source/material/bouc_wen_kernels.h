#ifndef hysteron_source_material_bouc_wen_kernels_h
#define hysteron_source_material_bouc_wen_kernels_h

#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_constants.h>
#include <hysteron/material/elasticity.h>
#include <hysteron/material/integer_power.h>

#include "material/bouc_wen_kernel_helpers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace Material
  {
    /**
     * Point kernels of the triaxial Bouc-Wen law (class BoucWen). Everything here
     * is a template on the stress state, the hardening kind and degradation, so
     * that a batch pays for exactly the features its material uses: no virtual
     * call, no allocation, fixed-size arrays only.
     *
     * <h3>Notation</h3>
     * Inside the kernels symmetric tensors are Mandel vectors: normal components
     * first, shear components multiplied by sqrt(2), in the order
     * xx, yy, zz, xy, yz, xz (3D) or xx, yy, zz, xy (2D). Then A : B is the plain
     * dot product, the deviatoric projector and the isotropic stiffness are
     * symmetric matrices, and a Jacobian is an ordinary matrix. The tensor
     * (not engineering) shear component is eps_xy = mandel_xy / sqrt(2); the
     * conversion to SymmetricTensor happens only at the interface.
     *
     * Two vector lengths: F, the full relative stress / plastic strain (6 in 3D,
     * 4 in 2D: the zz component exists in both plane states), and K, the
     * components integrated with the stiffness D: K = F in 3D and plane strain
     * (eps_zz' = 0, sigma_zz carried), K = 3 (xx, yy, xy) in plane stress, where D
     * is the plane-stress stiffness and the flow vector enters D only through its
     * in-plane part. The isotropic stiffness is D = lambda_eff 1 (x) 1 + 2 mu I on
     * the normal components of the K vector (lambda_eff = E nu / (1 - nu^2) in
     * plane stress), so that D v costs O(K).
     *
     * <h3>Derivation of the rate law</h3>
     * Yield function Phi = q(sigma - alpha) - sigma_y(eps_iso), q the von Mises
     * equivalent stress (homogeneous of degree 1), flow vector
     * n = dq/dsigma = 3/2 dev(xi) / q, xi = sigma - alpha, so n : n = 3/2 (3D tensors,
     * also in plane stress, where n_zz != 0) and n : xi = q. Associated flow
     * eps_p' = lambda' n gives the equivalent plastic strain rate
     * sqrt(2/3 eps_p' : eps_p') = |lambda'|. Mixed hardening: eps_iso' = m |lambda'|,
     * sigma_y = sigma_y0 + H' eps_iso; alpha' = (1 - m) C_p eps_p' (Prager).
     * Consistency Phi' = 0 with sigma' = D : (eps' - lambda' n):
     *   n:D:eps' - lambda' n:D:n - (1 - m) C_p lambda' n:n - m H' lambda' = 0
     *   => lambda' = lambda1 n:D:eps',  lambda1 = 1 / ((1 - m) 3/2 C_p + m H' + n:D:n),
     * and with C_p = 2/3 H' the hardening part is (1 - m) H' + m H' = H' for every m
     * (so Fig. 4.18 step 6 and eq. 4.51 agree once C_p = 2/3 H').
     * Bouc-Wen smoothing: lambda' = H1 H2 lambda1 n:D:eps', H1 = (q / sigma_y)^n,
     * H2 = beta + gamma sgn(n:D:eps'). Then
     *   sigma' = D : eps' - H1 H2 lambda1 (D:n)(n:D:eps') = E_t : eps',
     *   E_t = D - H1 H2 lambda1 (D:n) (x) (n:D)   (symmetric).
     * With H1 H2 = 1: Phi' = (1 - H1 H2) n:D:eps' = 0, so q = sigma_y is an attractor
     * and H1 <= 1 holds for the exact solution (beta + gamma = 1). Check, uniaxial
     * stress, kinematic (m = 0): alpha = C_p eps_p, eps_p = eps_p,xx diag(1, -1/2, -1/2),
     * q = |sigma - C_p 3/2 eps_p,xx| = |sigma - H' eps_p,xx|; on yield
     * d sigma = H' d eps_p and d eps = d sigma / E + d eps_p, so
     * E_t = E H' / (E + H') = a E. With beta > gamma, H2 > 0 while unloading and
     * lambda' < 0: eps_ps' = |lambda'| keeps the equivalent plastic strain increasing.
     *
     * Since alpha' = (1 - m) C_p eps_p' with a constant factor and both start at
     * zero, alpha = (1 - m) C_p eps_p at all times (every Runge-Kutta method and
     * backward Euler preserve this linear invariant): the kernels integrate eps_p
     * and derive alpha from it.
     *
     * <h3>Degradation (eq. 2.46 with the project's dimensionless convention)</h3>
     *   sigma' = D : (eps'/eta - lambda' n),  lambda' = nu_s H1 H2 lambda1 n:D:eps' / eta,
     * i.e. eta scales the whole rate: the undegraded law is driven by the reduced
     * strain rate eps'/eta (elastic and post-yield stiffness both divided by eta,
     * the yield surface unchanged), which reproduces
     * sigma' = (1/eta) D (I - nu_s H1 H2 R) eps'. The plastic strain, the back stress
     * (alpha = (1 - m) C_p eps_p), the isotropic hardening (eps_iso = m eps_ps) and the
     * consistency condition all refer to this reduced strain: with nu_s = 1 and
     * H1 H2 = 1, Phi' = n:D:eps'/eta - lambda' (n:D:n + H') = 0 as before; nu_s > 1
     * makes the surface q = sigma_y nu_s^(-1/n) the attractor (strength loss).
     * Intrinsic time xi' = eps_ps' (strain units); eta' = c_eta eta^(-m_u) xi' with
     * eta(0) = 1 integrates in closed form:
     *   eta = (1 + (m_u + 1) c_eta eps_ps)^(1 / (m_u + 1)),
     * so eta is a function of eps_ps (no ODE, no drift). Dissipated energy density
     * e_h' = sigma : eps_p' = lambda' sigma:n [J/m^3] (eq. 2.44),
     * nu_s = 1 + c_nu e_h / (sigma_y0 eps_y), eps_y = sigma_y0 / E.
     * e_h includes the recoverable energy of the back stress (sigma : eps_p' =
     * (sigma - alpha) : eps_p' + alpha : eps_p'), so under kinematic hardening it can
     * dip slightly early in a reloading, where alpha : n < 0 and H1 is still small.
     * Plane stress: the out-of-plane strain is not a function of the state when
     * eta varies: eps_zz' = eta (-nu/E (sigma_xx' + sigma_yy') + eps_p,zz') is
     * integrated (slot "epsilon_zz"); without degradation
     * eps_zz = -nu/E (sigma_xx + sigma_yy) + eps_p,zz exactly.
     *
     * <h3>Plane stress: reduced forms</h3>
     * As in the dissertation (Fig. 4.18), plane stress uses D_ps, the in-plane part
     * n_p of n and lambda1 = 1 / (H' + n_p:D_ps:n_p), while the hardening terms use the
     * 3D n : n = 3/2. This is the static condensation of the 3D law with
     * sigma_zz' = 0 only where H1 H2 is 0 or 1: condensing the smooth 3D law gives
     *   1 / lambda1 = H' + n:D:n - H1 H2 (n:D:n - n_p:D_ps:n_p).
     * The two agree in the elastic range and on the plateau and differ in the knee
     * (0.25 % of sigma_y at n = 8, 0.07 % at n = 32 on a multiaxial cyclic path).
     *
     * <h3>Integrators</h3>
     * Rate independence: over one increment deps the rates are integrated in the
     * pseudo time s in [0, 1] with eps' = deps.
     * - forward Euler: y1 = y0 + f(y0) (Fig. 4.18 with eq. 4.51), tangent E_t(y0).
     *   Without degradation BoucWen::update() does not call forward_euler() but a
     *   fused equivalent (FusedForwardEuler in bouc_wen.cc): tensor components read
     *   and written in place, no square root or division for n and lambda1
     *   (q^2 form), H1 = (q^2/sigma_y^2)^(n/2) for even n, several points
     *   interleaved; it agrees with forward_euler() + H1_at() to round-off. The
     *   stored H1 is still that of the end state.
     * - adaptive: Bogacki-Shampine 3(2), FSAL, first trying h = 1, error norm
     *   max |err_i| / scale_i with scales sigma_y0 (stresses), eps_y (strains),
     *   sigma_y0 eps_y (e_h), step factor 0.9 (tol/err)^(1/3) in [0.2, 5]; a
     *   non-finite trial step (overflow of (q/sigma_y)^n in a too long step) is
     *   shortened; an accepted step must also pass the second estimate of
     *   stiff_error(), since the 3(2) difference can be small by accident in the knee
     *   (bogacki_shampine_32()); at most Constants::max_substeps attempts, then RuntimeError. At
     *   the end of the increment a drift correction (see drift_correction()) keeps
     *   nu_s H1 <= 1 (exact solutions do, except with strength deterioration, which
     *   is not corrected), which an explicit method near its stability
     *   limit on the stiff relaxation towards q = sigma_y otherwise misses by a few
     *   tolerances for large n. Tangent: E_t at the end state (sign of the current
     *   increment). The stages use stage_rates() (q^2 form, no n or lambda1); the
     *   drift correction without degradation starts from the last stage
     *   (drift_correction_stage()). Without a tangent, BoucWen::update() runs the
     *   first attempt of four points stage by stage together (adaptive_points()),
     *   which overlaps their dependency chains.
     * - backward Euler: rates at the end of the increment, H2 frozen from the
     *   trial direction sgn(n_tr : D : deps), n_tr at sigma0 + D deps/eta0 - alpha0
     *   (in 3D / plane strain without degradation n_tr is exactly the end-state
     *   direction, radial return, so this is the fully implicit H2; it also treats a
     *   reversal that crosses the surface within the increment as loading). 3D and
     *   plane strain without degradation, loading: one scalar Newton equation
     *   (radial_return()); otherwise Newton on (sigma, w[, dlambda, e_h]) with the
     *   analytic Jacobian, scaled unknowns and backtracking (backward_euler()). The
     *   consistent tangent follows from the implicit function theorem.
     */
    namespace BoucWenKernels
    {
      template <StressState S, bool kinematic, bool degrading>
      struct Law
      {
        using G                                    = Geometry<S>;
        static constexpr unsigned int K            = G::K;
        static constexpr unsigned int F            = G::F;
        static constexpr unsigned int n_nor        = G::n_normal;
        static constexpr bool         track_eps_zz = degrading && S == StressState::plane_stress;
        static constexpr bool         is_kinematic = kinematic;
        static constexpr bool         is_degrading = degrading;

        static constexpr unsigned int i_epsp   = K;
        static constexpr unsigned int i_eps_ps = K + F;
        static constexpr unsigned int i_e_h    = K + F + 1;
        static constexpr unsigned int i_eps_zz = i_e_h + (degrading ? 1 : 0);
        static constexpr unsigned int N        = i_eps_zz + (track_eps_zz ? 1 : 0);

        using VecK = std::array<double, K>;
        using VecF = std::array<double, F>;
        using VecN = std::array<double, N>;
        using MatK = std::array<std::array<double, K>, K>;

        /// The stored state: named slots (see BoucWen::state_variable_names()).
        struct Slots
        {
          static constexpr unsigned int H1       = 0;
          static constexpr unsigned int H2       = 1;
          static constexpr unsigned int eps_ps   = 2;
          static constexpr unsigned int epsp     = 3;        ///< F tensor components
          static constexpr unsigned int alpha    = epsp + F; ///< F components, kinematic only
          static constexpr unsigned int sigma_zz = alpha + (kinematic ? F : 0); ///< plane strain
          static constexpr unsigned int e_h =
            sigma_zz + (S == StressState::plane_strain ? 1 : 0); ///< degradation: e_h, eta, nu_s
          static constexpr unsigned int eta    = e_h + 1;
          static constexpr unsigned int nu_s   = e_h + 2;
          static constexpr unsigned int eps_zz = e_h + (degrading ? 3 : 0); ///< plane stress
          static constexpr unsigned int size   = eps_zz + (track_eps_zz ? 1 : 0);
        };

        /// out = D v (K vectors).
        static void
        apply_D(const Constants &c, const double *v, double *out);

        static double
        D_entry(const Constants &c, const unsigned int a, const unsigned int b);

        template <unsigned int L>
        static double
        dot(const double *a, const double *b);

        /// dev(xi), xi = embed(sigma) - alpha (alpha = nullptr: none); returns q.
        static double
        relative_deviator(const double *sigma, const double *alpha, VecF &dev);

        /// eta(eps_ps) = (1 + (m_u + 1) c_eta eps_ps)^(1/(m_u + 1)), the closed-form
        /// solution of eta' = c_eta eta^(-m_u) eps_ps', eta(0) = 1.
        static double
        eta_of(const Constants &c, const double eps_ps);

        static double
        H1_of(const Constants &c, const double q, const double sigma_y);

        /// What a rate evaluation knows besides the rates.
        struct Rates
        {
          VecF   n;
          VecK   Dn;
          double q = 0, sigma_y = 1, H1 = 0, H2 = 0, lambda1 = 0, eta = 1, nu = 1;
        };

        /// What stage_rates() knows about its state besides the rates.
        struct Stage
        {
          VecF   d;  ///< dev(sigma - alpha)
          VecK   Dd; ///< D d (K components)
          double q2 = 0, q = 0, sigma_y = 1, H1 = 0, H2 = 0, eta = 1, nu = 1;
          double dDe = 0, dDd = 0; ///< d:D:deps, d:D:d (plane stress or degradation)
          /// 1 / sigma_y^2 and (plane stress, even n) 1 / (H' q^2 + 9/4 d:D:d); 0: not set
          double inv_sy2 = 0, inv_den = 0;
        };

        /// dy = f(y) for the strain increment deps (De = D deps).
        static void
        rates(const Constants &c, const double *y, const VecK &De, double *dy, Rates &r);

        /**
         * dy = f(y) as rates(), for the stages of adaptive(): the rates only (no
         * Rates filled), in the q^2 form of FusedForwardEuler. With d = dev(xi),
         * q^2 = 3/2 d:d, n = 3/2 d / q:
         *   lambda' n = g d, lambda' D n = g D d, |lambda'| = 2/3 |g| q,
         *   g = nu_s H1 H2 9/4 d:De / (eta (H' q^2 + 9/4 d:D:d)),
         * which equals rates() up to round-off without n and lambda1. For even n,
         * H1 = t^(n/2) with t = q^2 / sigma_y^2 (no square root on the path to g; the
         * one for |lambda'| runs aside). In 3D and plane strain without degradation
         * d is a full traceless K vector, D d = 2 mu d and d:D:d = 4/3 mu q^2, so
         *   g = H2 (H1 / q^2) d:De 9/4 / (H' + 3 mu),   H1 / q^2 = t^(n/2 - 1) / sigma_y^2:
         * no division that waits for the deviator. Returns H1; @p info (if given):
         * what it knows about the state.
         */
        static inline __attribute__((always_inline)) double
        stage_rates(const Constants &c,
                    const double    *y,
                    const VecK      &De,
                    double          *dy,
                    Stage           *info = nullptr);

        /// The first part of stage_rates(): the deviator and the products with it
        /// (into @p st; everything up to the power and the divisions).
        static inline __attribute__((always_inline)) void
        stage_begin(const Constants &c, const double *y, const VecK &De, Stage &st);

        /// The second part of stage_rates(): H1, g and the rates dy.
        static inline __attribute__((always_inline)) void
        stage_end(const Constants &c, const double *y, const VecK &De, Stage &st, double *dy);

        /// E_t = (D - nu_s H1 H2 lambda1 (D n) (x) (D n)) / eta (eq. 2.47, Mandel).
        static void
        continuum_tangent(const Constants &c, const Rates &r, MatK &T);

        /// H1 at the state y.
        static double
        H1_at(const Constants &c, const double *y);

        /// One explicit step over the whole increment; r: the rates at the start.
        static void
        forward_euler(const Constants &c, VecN &y, const VecK &deps, Rates &r);

        /// Scaled error norm (max norm) of an embedded estimate (<= 1: accept).
        static double
        error_norm(const Constants &c, const VecN &err);

        /// The plastic correction y -> y + dlambda (-D n, n, 1, sigma:n, ...) along
        /// the flow direction n of @p r (linear in dlambda; sigma + D eps_p unchanged).
        static void
        plastic_correction(const Constants &c, VecN &y, const Rates &r, const double dlambda);

        /**
         * Drift correction (Sloan et al. 2001): without strength deterioration
         * (nu_s = 1, or stiffness degradation only) the exact solution keeps
         * nu_s H1 <= 1 (Phi' = n:D:eps'/eta (1 - nu_s H1 H2)). With it, nu_s grows
         * with e_h and lowers the saturation stress sigma_y nu_s^(-1/n) while q lags
         * behind it, so the exact nu_s H1 exceeds 1 (by 0.5 % after one increment of
         * 3 eps_y at c_nu = 0.05, n = 8) and finish() applies no correction. An explicit
         * method near its stability limit on this stiff relaxation (rate ~ n E deps /
         * sigma_y) settles slightly outside. If nu_s H1 > 1 at the end of an
         * increment, return to q = q* = sigma_y nu_s^(-1/n) along the flow direction
         * by Newton's method on q - q* in dlambda (one step is exact in 3D and plane
         * strain without degradation, where D n = 2 mu n). The correction is of the
         * size of the local error. Updates r.q, r.sigma_y, r.nu and r.H1.
         */
        static void
        drift_correction(const Constants &c, VecN &y, Rates &r);

        /// d = dev(sigma - alpha) of the state y; returns q^2 = 3/2 d:d. (Each component
        /// is stored once from registers; a local copy assembled on the stack and
        /// copied as a whole was read back as pairs and stalled on store forwarding.)
        static inline __attribute__((always_inline)) double
        deviator(const Constants &c, const double *y, VecF &d);

        /**
         * drift_correction() without degradation, in the q^2 form of stage_rates()
         * and starting from its Stage of y: Newton's method on q - sigma_y in
         * dlambda along n = 3/2 d / q, with the slope
         *   n:D:n + H' = (H' q^2 + 9/4 d:D:d) / q^2,
         * i.e. dlambda = (q - sigma_y) q^2 / den and lambda n = phi d,
         * phi = 3/2 (q - sigma_y) q / den, den = H' q^2 + 9/4 d:D:d (= q^2 (H' + 3 mu)
         * in 3D and plane strain, where d:D:d = 4/3 mu q^2 and one step is exact).
         * Sets r.H1 (r.q is left as it is: the caller stores H1 only).
         */
        static inline __attribute__((always_inline)) void
        drift_correction_stage(const Constants &c, VecN &y, const Stage &stage, Rates &r);

        /**
         * The end of an accepted increment: the drift correction if nu_s H1 > 1.
         * With @p full, @p r holds the full Rates of y; else @p r receives q,
         * sigma_y, H1, H2, nu_s and eta from @p stage (the last stage_rates() of y)
         * and the correction starts from the stage (without degradation) or from
         * rates() (with degradation).
         */
        static inline __attribute__((always_inline)) void
        finish(const Constants &c,
               VecN            &y,
               const VecK      &De,
               const Stage     &stage,
               Rates           &r,
               const bool       full);

        /// Per-step error estimate of Bogacki-Shampine 3(2), scaled (error_norm()).
        static double
        bs32_error(const Constants &c,
                   const double     h,
                   const VecN      &k1,
                   const VecN      &k2,
                   const VecN      &k3,
                   const VecN      &k4);

        /**
         * The second error estimate of a step (bogacki_shampine_32() derives it): in the
         * knee the 3(2) difference can be small by accident, while the error of q is about
         * (h lambda)^3 / 24 |q_1 - q_0|, the distance to the yield surface decaying like
         * exp(-lambda s). lambda = n |q'_plastic| / q with
         * the plastic rate of q 3 mu |eps_ps'| at q ~ sigma_y, and |q_1 - q_0| ~ sigma_y
         * |H1_1 - H1_0| / n there (H1 = (q / sigma_y)^n): no false alarm while the stress
         * flows along the surface. @p k1, @p k4: the rates at the two ends.
         */
        static inline double
        stiff_error(const Constants &c,
                    const double     h,
                    const VecN      &y,
                    const VecN      &k1,
                    const VecN      &k4,
                    const double     H1_0,
                    const double     H1_1);

        /**
         * The sub-step loop of adaptive() from s = 0 with the trial step @p h,
         * k1 = f(y) and @p attempts attempts already spent (by a rejected first
         * attempt of adaptive_points()). See adaptive().
         */
        static unsigned int
        substeps(const Constants &c,
                 VecN            &y,
                 const VecK      &De,
                 VecN            &k1,
                 double           H1_now,
                 double           h,
                 unsigned int     attempts,
                 Rates           &r,
                 const bool       full_rates);

        /**
         * Bogacki-Shampine 3(2) with first-same-as-last and error control over the
         * pseudo time s in [0, 1]; r: the rates at the end state. Returns the
         * number of attempted sub-steps. With @p full_rates = false only r.q,
         * r.sigma_y, r.H1, r.H2, r.nu and r.eta are set (enough to store the state;
         * the tangent needs the full Rates).
         */
        static unsigned int
        adaptive(const Constants &c,
                 VecN            &y,
                 const VecK      &deps,
                 Rates           &r,
                 const bool       full_rates = true);

        /**
         * adaptive() without the full Rates for P independent points: the first
         * attempt (the whole increment, h = 1, which most increments accept) runs
         * stage by stage over all points, so that the processor overlaps their
         * dependency chains; a point whose first attempt is rejected continues in
         * substeps() from the step size its error estimate suggests. Same
         * operations per point as adaptive(), hence the same results.
         */
        template <unsigned int P>
        static inline __attribute__((always_inline)) void
        adaptive_points(const Constants &c, VecN *y, const VecK *deps, Rates *r);

        // ---------------------------------------------------------------
        // Backward Euler
        // ---------------------------------------------------------------
        /**
         * Unknowns x = (sigma [K], w, dlambda, e_h), the last two only with
         * degradation; w = H1^(1/n) = q1 / sigma_y1 (the Bouc-Wen relation in
         * "root" form), dlambda = c w^n with c = nu1 H2 lambda1(n1) n1:D:deps / eta1.
         * With alpha1 = alpha0 + kin dlambda n1 the end-state relative stress is
         * xi - kin dlambda n1 (xi = sigma - alpha0), whose deviator is parallel to
         * dev(xi); hence n1 = n(xi) and q1 = q(xi) - (1 - m) H' dlambda. Residuals:
         *   R_sigma   = sigma - sigma0 - D deps / eta1 + dlambda D n1
         *   R_w       = q1 / sigma_y1 - w,   sigma_y1 = sigma_y0 + m H' (eps_ps0 + |dlambda|)
         *   R_dlambda = dlambda - c w^n            (degradation; else dlambda := c w^n)
         *   R_e       = e_h - e_h0 - dlambda sigma : n1
         * The root form is concave in w: Newton from w0 = min(1, q_trial / sigma_y)
         * (right of the root) converges monotonically for every n, also n = 100,
         * where the form dlambda - c H1 needs O(n) iterations.
         */
        static constexpr unsigned int M    = K + 1 + (degrading ? 2 : 0);
        static constexpr unsigned int i_w  = K;
        static constexpr unsigned int i_dl = K + 1;
        static constexpr unsigned int i_eh = K + 2;
        using VecM                         = std::array<double, M>;
        using MatM                         = std::array<double, M * M>;

        struct BEData
        {
          VecK   sigma0, De;
          VecF   alpha0;
          double eps_ps0 = 0, e_h0 = 0, H2 = 1, s_lambda = 1;
          /// Upper bound of w for Newton iterates (see backward_euler()). Backward Euler
          /// solutions have w <= max(1, q_tr / sigma_y) up to the non-radiality of plane
          /// stress; with beta > gamma the equations also have spurious roots in the
          /// run-away regime nu_s H1 (beta - gamma) > 1 (reverse flow pushing the stress
          /// outwards), which the bound keeps Newton away from.
          double w_cap = 2;
        };

        /// End-state quantities of an iterate.
        struct Iterate
        {
          VecF   n;
          VecK   n_K, Dn;
          double q1 = 0, sigma_y1 = 1, eta1 = 1, dlambda = 0, c = 0, wn = 0, gw = 0, lambda1 = 0;
          double nu1 = 1, H2 = 1;
        };

        /// The residual R at x and the end-state quantities @p it; with @p J its
        /// Jacobian dR/dx (unscaled).
        static void
        evaluate(const Constants &c, const BEData &d, const VecM &x, VecM &R, MatM *J, Iterate &it);

        /// The Jacobian dR/dx of evaluate() at x, from the iterate @p it and evaluate()'s
        /// 3 / (2 q), n:D:deps, d eta1 / d dlambda and sigma : n.
        static inline __attribute__((always_inline)) void
        jacobian(const Constants &c,
                 const BEData    &d,
                 const VecM      &x,
                 const Iterate   &it,
                 const double     inv_q,
                 const double     nDe,
                 const double     deta,
                 const double     sn,
                 MatM            &J);

        /// Scale of unknown / residual i: sigma_y0 (stresses), 1 (w), eps_y (dlambda),
        /// sigma_y0 eps_y (e_h). Newton solves the scaled system (unscaled, the
        /// Jacobian entries span some 20 orders of magnitude).
        static double
        unknown_scale(const Constants &c, const unsigned int i);

        static double
        inverse_scale(const Constants &c, const unsigned int i);

        /// J -> S_R^-1 J S_x (the same scales for residuals and unknowns).
        static void
        scale_jacobian(const Constants &c, MatM &J);

        /// Sum of squares of the scaled residual (the merit function of the line search).
        static double
        residual_norm2(const Constants &c, const VecM &R);

        static double
        residual_norm(const Constants &c, const VecM &R);

        /**
         * Backward Euler for 3D and plane strain without degradation while loading
         * (n_tr : D : deps > 0): D n = 2 mu n for deviatoric n, so the end-state
         * direction is the trial one (radial return), n1 = n_tr, and
         *   sigma1 = sigma_tr - 2 mu dlambda n_tr,   q1 = q_tr - b dlambda,
         *   b = 3 mu + (1 - m) H',   sigma_y1 = sigma_y + m H' dlambda,
         *   dlambda = c w^n,   c = H2 n_tr : D : deps / (H' + 3 mu)  (constant).
         * One scalar equation for w = q1 / sigma_y1:
         *   g(w) = q_tr - b c w^n - w (sigma_y + m H' c w^n) = 0,
         * concave and decreasing for n >= 1, so Newton from w0 = min(1, q_tr / sigma_y)
         * (where g <= 0) converges monotonically. Consistent tangent:
         *   T = D - 2 mu n_tr (x) d dlambda / d deps - 4 mu^2 dlambda N,
         *   N = dn/dxi = 3/(2 q_tr) (P_dev - 2/3 n_tr (x) n_tr),
         *   d dlambda = w^n dc + c n w^(n-1) dw,  dw = -(dq_tr + dg/dc dc) / (dg/dw),
         *   dq_tr = 2 mu n_tr,  dc = H2 2 mu (n_tr + N D deps) / (H' + 3 mu).
         */
        static unsigned int
        radial_return(const Constants &c,
                      VecN            &y,
                      const BEData    &d,
                      const VecK      &sigma_tr,
                      const double     q_tr,
                      const VecK      &n_tr,
                      const double     nDe_tr,
                      const double     sigma_y,
                      double          &H1,
                      MatK            *T);

        /// Trial-based initial guess: w0 = min(1, q_tr / sigma_y), dlambda0 = c_tr w0^n,
        /// sigma0 + D deps / eta - dlambda0 D n_tr (n_tr at the trial state of d.De).
        static void
        guess(const Constants &c, const BEData &d, VecM &x);

        /**
         * Newton's method on the scaled system with backtracking (Armijo on the
         * scaled 2-norm, for which the Newton step is a descent direction), keeping
         * w > 0. On return @p R and @p it belong to @p x. Returns whether the scaled
         * max-norm residual reached the tolerance within @p max_iterations (adds the
         * iterations to @p iterations). The Jacobian is evaluated only where a step
         * is taken.
         */
        static bool
        newton(const Constants   &c,
               const BEData      &d,
               VecM              &x,
               VecM              &R,
               Iterate           &it,
               const unsigned int max_iterations,
               unsigned int      &iterations);

        /// The elastic trial state sigma_tr = sigma0 + D deps / eta0 of backward_euler(),
        /// its flow direction n_tr (K components) and n_tr : D : deps.
        struct Trial
        {
          VecK   sigma, n;
          double eta0 = 1, q = 0, nDe = 0, sigma_y = 1;
        };

        /// The data of an increment (start state, D deps, H2 frozen from the trial
        /// direction, the cap of w) and its elastic trial state.
        static inline __attribute__((always_inline)) Trial
        begin_increment(const Constants &c, const VecN &y, const VecK &deps, BEData &d);

        /// The exactly elastic update (lambda' = 0) and its tangent D / eta0.
        static inline __attribute__((always_inline)) void
        elastic_update(const Constants &c, VecN &y, const BEData &d, const Trial &tr, double &H1, MatK *T);

        /// Newton's method from guess() on the whole increment, else continuation in the
        /// increment (d.De = s deps, s -> 1); returns the iterations, @p R and @p it at @p x.
        static inline __attribute__((always_inline)) unsigned int
        solve(const Constants &c, BEData &d, const Trial &tr, VecM &x, VecM &R, Iterate &it);

        /// The converged end state into y, its H1 and H2.
        static inline __attribute__((always_inline)) void
        store_solution(const Constants &c,
                       VecN            &y,
                       const BEData    &d,
                       const VecM      &x,
                       const Iterate   &it,
                       double          &H1,
                       double          &H2);

        /// The consistent tangent d sigma1 / d deps = -J^-1 dR/d deps (implicit function
        /// theorem, on the scaled system).
        static inline __attribute__((always_inline)) void
        consistent_tangent(const Constants &c, const BEData &d, const VecM &x, VecM &R, Iterate &it, MatK &T);

        /**
         * Backward Euler over the increment deps: updates y (same layout as the
         * explicit integrators), writes H1, H2 and, if @p T is given, the
         * consistent tangent d sigma1 / d deps (Mandel). Returns the number of
         * Newton iterations. Throws RuntimeError if Newton does not converge.
         */
        static unsigned int
        backward_euler(const Constants &c,
                       VecN            &y,
                       const VecK      &deps,
                       double          &H1,
                       double          &H2,
                       MatK            *T);
      };
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#include "material/bouc_wen_rates.h"
#include "material/bouc_wen_explicit.h"
#include "material/bouc_wen_backward_euler.h"
#include "material/bouc_wen_radial_return.h"

#endif
