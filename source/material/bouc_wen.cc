#include <hysteron/material/bouc_wen.h>

#include "material/bouc_wen_kernels.h"

#include <cmath>
#include <sstream>
#include <type_traits>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      using namespace BoucWenKernels;

      template <StressState S>
      using StressStateTag = std::integral_constant<StressState, S>;

      /**
       * Call fn(stress state tag, kinematic tag, degradation tag) for the
       * configuration of a material: the one runtime branch per batch, after
       * which everything is a compile-time constant.
       */
      template <int dim, typename Function>
      void
      dispatch(const StressState state, const bool kinematic, const bool degrading, Function &&fn)
      {
        const auto with_state = [&](auto s) {
          if (kinematic)
            {
              if (degrading)
                fn(s, std::true_type(), std::true_type());
              else
                fn(s, std::true_type(), std::false_type());
            }
          else
            {
              if (degrading)
                fn(s, std::false_type(), std::true_type());
              else
                fn(s, std::false_type(), std::false_type());
            }
        };
        if constexpr (dim == 3)
          with_state(StressStateTag<StressState::three_dimensional>());
        else if (state == StressState::plane_stress)
          with_state(StressStateTag<StressState::plane_stress>());
        else
          with_state(StressStateTag<StressState::plane_strain>());
      }

      /// Conversions between the interface (SymmetricTensor, tensor components
      /// in the state) and the Mandel vectors of the kernels.
      template <int dim, typename LawType>
      struct Point
      {
        using L     = LawType;
        using G     = typename L::G;
        using Slots = typename L::Slots;
        static_assert(G::dim == dim, "stress state and dimension do not match");

        static void
        load(const dealii::SymmetricTensor<2, dim> &stress, const double *st, typename L::VecN &y)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                y[a] = st[Slots::sigma_zz]; // plane strain
              else
                {
                  const auto ij = tensor_index<dim>(f);
                  y[a]          = stress[ij[0]][ij[1]] * mandel_weight(f);
                }
            }
          for (unsigned int f = 0; f < L::F; ++f)
            y[L::i_epsp + f] = st[Slots::epsp + f] * mandel_weight(f);
          y[L::i_eps_ps] = st[Slots::eps_ps];
          if constexpr (L::is_degrading)
            y[L::i_e_h] = st[Slots::e_h];
          if constexpr (L::track_eps_zz)
            y[L::i_eps_zz] = st[Slots::eps_zz];
        }

        /// The Mandel strain increment; in 2D @p hoop is eps_zz' (0 in plane strain, the
        /// hoop strain increment when axisymmetric).
        static void
        strain(const dealii::SymmetricTensor<2, dim> &e, const double hoop, typename L::VecK &d)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                d[a] = hoop;
              else
                {
                  const auto ij = tensor_index<dim>(f);
                  d[a]          = e[ij[0]][ij[1]] * mandel_weight(f);
                }
            }
        }

        static void
        store(const Constants                 &c,
              const typename L::VecN          &y,
              const double                     H1,
              const double                     H2,
              dealii::SymmetricTensor<2, dim> &stress,
              double                          *st)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                st[Slots::sigma_zz] = y[a];
              else
                {
                  const auto ij        = tensor_index<dim>(f);
                  stress[ij[0]][ij[1]] = y[a] / mandel_weight(f);
                }
            }
          st[Slots::H1]     = H1;
          st[Slots::H2]     = H2;
          st[Slots::eps_ps] = y[L::i_eps_ps];
          for (unsigned int f = 0; f < L::F; ++f)
            {
              const double e      = y[L::i_epsp + f] / mandel_weight(f);
              st[Slots::epsp + f] = e;
              if constexpr (L::is_kinematic)
                st[Slots::alpha + f] = c.kin * e; // alpha = (1 - m) C_p eps_p
            }
          if constexpr (L::is_degrading)
            {
              st[Slots::e_h]  = y[L::i_e_h];
              st[Slots::eta]  = L::eta_of(c, y[L::i_eps_ps]);
              st[Slots::nu_s] = 1.0 + c.c_nu_scaled * y[L::i_e_h];
            }
          if constexpr (L::track_eps_zz)
            st[Slots::eps_zz] = y[L::i_eps_zz];
        }

        /// The interface tangent from the Mandel one: T_ab / (w_a w_b). The zz row and
        /// column (plane strain and axisymmetric: K = F, a = 2) go to @p hoop if given.
        static void
        tangent(const typename L::MatK            &T,
                dealii::SymmetricTensor<4, dim>   &out,
                HoopTangent<dim>                  *hoop)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int fa = G::full[a];
              if (dim == 2 && fa == 2)
                continue; // sigma_zz is not an in-plane component
              const auto ij = tensor_index<dim>(fa);
              for (unsigned int b = 0; b < L::K; ++b)
                {
                  const unsigned int fb = G::full[b];
                  if (dim == 2 && fb == 2)
                    {
                      if (hoop)
                        {
                          hoop->stress_by_hoop[ij[0]][ij[1]] = T[a][b] / mandel_weight(fa);
                          hoop->hoop_by_strain[ij[0]][ij[1]] = T[b][a] / mandel_weight(fa);
                        }
                      continue;
                    }
                  const auto kl = tensor_index<dim>(fb);
                  out[ij[0]][ij[1]][kl[0]][kl[1]] =
                    T[a][b] / (mandel_weight(fa) * mandel_weight(fb));
                }
            }
          if (hoop && dim == 2 && L::K == 4)
            hoop->hoop_by_hoop = T[2][2];
        }
      };

      /**
       * Forward Euler without degradation, fused with the conversions: the same
       * update as Law::forward_euler() followed by Law::H1_at() (and
       * Law::continuum_tangent()), evaluated on tensor (not Mandel) components
       * read from and written to the interface directly. With w_f = 1 (normal) or
       * 2 (shear) as the weight of A : B = sum_f w_f A_f B_f and d = dev(sigma -
       * alpha), q^2 = 3/2 d : d, n = 3/2 d / q, the Mandel kernel's
       *   lambda' D n = g D d,  lambda' n = g d,  |lambda'| = 2/3 q |g|,
       *   g = H1 H2 9/4 (d : D deps) / (H' q^2 + 9/4 d : D d)
       * (lambda1 = q^2 / (H' q^2 + 9/4 d : D d)), and H1 = (q^2 / sigma_y^2)^(n/2)
       * for even integer n. This needs one square root (eps_ps) and three
       * divisions per update instead of four square roots and about ten
       * divisions (sqrt(2) conversions included); the results agree to round-off.
       * The stored H1 is that of the end state, as in the generic path.
       */
      template <int dim, typename L>
      struct FusedForwardEuler
      {
        static_assert(!L::is_degrading, "degradation uses the generic path");
        using G                           = typename L::G;
        using Slots                       = typename L::Slots;
        static constexpr unsigned int F   = L::F;
        static constexpr unsigned int nn  = L::n_nor;
        static constexpr bool         ps  = L::K == 3 && dim == 2; // plane stress
        static constexpr bool         kin = L::is_kinematic;

        /// Whether the full component f is integrated with D (not plane stress zz).
        static constexpr bool
        in_K(const unsigned int f)
        {
          return !(ps && f == 2);
        }

        static constexpr double
        weight(const unsigned int f)
        {
          return f < 3 ? 1.0 : 2.0;
        }

        /// (q^2 / sigma_y^2)^(n/2), i.e. (q / sigma_y)^n; 0 for q = 0. The
        /// reciprocal 1 / sigma_y^2 depends on eps_ps only, so that its division
        /// runs in parallel with the deviator instead of after it.
        static double
        H1_of_q2(const Constants &c, const unsigned int n_half, const double q2, const double sy)
        {
          if (n_half != 0)
            {
              const double inv_sy2 = 1.0 / (sy * sy);
              return q2 > 0 ? integer_power(q2 * inv_sy2, n_half) : 0.0;
            }
          return q2 > 0 ? power(c, std::sqrt(q2) / sy) : 0.0;
        }

        /// dev(sigma - kin eps_p) into d; returns q^2.
        static double
        deviator(const Constants &c, const double *s, const double *ep, double *d)
        {
          for (unsigned int f = 0; f < F; ++f)
            d[f] = kin ? s[f] - c.kin * ep[f] : s[f];
          const double p = (d[0] + d[1] + d[2]) * (1.0 / 3.0);
          d[0] -= p;
          d[1] -= p;
          d[2] -= p;
          double dd = 0;
          for (unsigned int f = 0; f < F; ++f)
            dd += weight(f) * d[f] * d[f];
          return 1.5 * dd;
        }

        /// out = D v on the K components (tensor form; 0 in plane stress zz).
        static void
        apply_D(const Constants &c, const double *v, double *out)
        {
          double tr = 0;
          for (unsigned int f = 0; f < nn; ++f)
            tr += v[f];
          for (unsigned int f = 0; f < F; ++f)
            out[f] = in_K(f) ? c.two_mu * v[f] + (f < nn ? c.lambda_eff * tr : 0.0) : 0.0;
        }

        static inline __attribute__((always_inline)) void
        update(const Constants                       &c,
               const unsigned int                     n_half,
               const dealii::SymmetricTensor<2, dim> &strain_increment,
               const double                           hoop,
               dealii::SymmetricTensor<2, dim>       &stress,
               double                                *st,
               dealii::SymmetricTensor<4, dim>       *tangent,
               HoopTangent<dim>                      *hoop_tangent)
        {
          double s[F], e[F], ep[F], De[F], d[F], Dd[F];
          for (unsigned int f = 0; f < F; ++f)
            {
              if (dim == 2 && f == 2)
                {
                  s[f] = ps ? 0.0 : st[Slots::sigma_zz];
                  e[f] = hoop; // eps_zz': 0 in plane strain and plane stress
                }
              else
                {
                  const auto ij = tensor_index<dim>(f);
                  s[f]          = stress[ij[0]][ij[1]];
                  e[f]          = strain_increment[ij[0]][ij[1]];
                }
              ep[f] = st[Slots::epsp + f];
            }
          double eps_ps = st[Slots::eps_ps];
          apply_D(c, e, De);

          const double q2 = deviator(c, s, ep, d);
          double       H2 = c.beta, gt = 0;
          if (q2 > 0)
            {
              apply_D(c, d, Dd);
              double dDd = 0, dDe = 0;
              for (unsigned int f = 0; f < F; ++f)
                if (in_K(f))
                  {
                    dDd += weight(f) * d[f] * Dd[f];
                    dDe += weight(f) * d[f] * De[f];
                  }
              const double H1 = H1_of_q2(c, n_half, q2, c.sigma_y0 + c.iso * eps_ps);
              H2              = c.beta + c.gamma * sign(dDe);
              const double inv_den = 1.0 / (c.H * q2 + 2.25 * dDd);
              gt                   = H1 * H2 * (2.25 * inv_den);
              const double g  = gt * dDe;
              for (unsigned int f = 0; f < F; ++f)
                {
                  if (in_K(f))
                    s[f] += De[f] - g * Dd[f];
                  ep[f] += g * d[f];
                }
              eps_ps += std::abs(g) * std::sqrt(q2) * (2.0 / 3.0);
            }
          else
            for (unsigned int f = 0; f < F; ++f)
              if (in_K(f))
                s[f] += De[f];

          if (tangent)
            {
              // E_t = D - nu_s H1 H2 lambda1 (D n) (x) (D n) = D - gt (D d) (x) (D d).
              if (!(q2 > 0))
                for (unsigned int f = 0; f < F; ++f)
                  Dd[f] = 0;
              for (unsigned int a = 0; a < F; ++a)
                {
                  if (dim == 2 && a == 2)
                    continue;
                  const auto ij = tensor_index<dim>(a);
                  for (unsigned int b = 0; b < F; ++b)
                    {
                      if (dim == 2 && b == 2)
                        continue;
                      const auto   kl = tensor_index<dim>(b);
                      const double D  = (a == b ? (a < 3 ? c.two_mu : 0.5 * c.two_mu) : 0.0) +
                                       (a < nn && b < nn ? c.lambda_eff : 0.0);
                      (*tangent)[ij[0]][ij[1]][kl[0]][kl[1]] = D - gt * Dd[a] * Dd[b];
                    }
                  if (hoop_tangent && nn == 3)
                    {
                      // The zz row and column (tensor form, D symmetric).
                      const double D = a < nn ? c.lambda_eff : 0.0;
                      hoop_tangent->stress_by_hoop[ij[0]][ij[1]] = D - gt * Dd[a] * Dd[2];
                      hoop_tangent->hoop_by_strain[ij[0]][ij[1]] = D - gt * Dd[2] * Dd[a];
                    }
                }
              if (hoop_tangent && nn == 3)
                hoop_tangent->hoop_by_hoop = c.two_mu + c.lambda_eff - gt * Dd[2] * Dd[2];
            }

          // H1 of the end state.
          double       d1[F];
          const double q2_1 = deviator(c, s, ep, d1);
          st[Slots::H1]     = H1_of_q2(c, n_half, q2_1, c.sigma_y0 + c.iso * eps_ps);
          st[Slots::H2]     = H2;
          st[Slots::eps_ps] = eps_ps;
          for (unsigned int f = 0; f < F; ++f)
            {
              st[Slots::epsp + f] = ep[f];
              if constexpr (kin)
                st[Slots::alpha + f] = c.kin * ep[f];
              if (dim == 2 && f == 2)
                {
                  if constexpr (!ps)
                    st[Slots::sigma_zz] = s[f];
                }
              else
                {
                  const auto ij        = tensor_index<dim>(f);
                  stress[ij[0]][ij[1]] = s[f];
                }
            }
        }

        /**
         * update() without tangent for P points at once (run_batch() uses P = 4), branch-free and with
         * every stage looping over the points: the update of one point is a
         * long dependency chain (deviator, power, correction, deviator, power),
         * and interleaving independent points lets the processor overlap them.
         * Same operations in the same order per point as update() (q = 0 gives
         * H1 = 0, hence g = 0 and the elastic step), so the results are identical.
         */
        template <unsigned int P>
        static inline __attribute__((always_inline)) void
        update_points(const Constants                       &c,
                      const unsigned int                     n_half,
                      const dealii::SymmetricTensor<2, dim> *strain_increment,
                      const double                          *hoop,
                      dealii::SymmetricTensor<2, dim>       *stress,
                      double                                *st0,
                      const unsigned int                     size)
        {
          double s[P][F], e[P][F], ep[P][F], De[P][F], d[P][F], Dd[P][F], eps_ps[P], q2[P], H2[P];
          for (unsigned int k = 0; k < P; ++k)
            {
              const double *st = st0 + k * size;
              for (unsigned int f = 0; f < F; ++f)
                {
                  if (dim == 2 && f == 2)
                    {
                      s[k][f] = ps ? 0.0 : st[Slots::sigma_zz];
                      e[k][f] = hoop ? hoop[k] : 0.0;
                    }
                  else
                    {
                      const auto ij = tensor_index<dim>(f);
                      s[k][f]       = stress[k][ij[0]][ij[1]];
                      e[k][f]       = strain_increment[k][ij[0]][ij[1]];
                    }
                  ep[k][f] = st[Slots::epsp + f];
                }
              eps_ps[k] = st[Slots::eps_ps];
            }
          for (unsigned int k = 0; k < P; ++k)
            {
              apply_D(c, e[k], De[k]);
              q2[k] = deviator(c, s[k], ep[k], d[k]);
              apply_D(c, d[k], Dd[k]);
            }
          for (unsigned int k = 0; k < P; ++k)
            {
              double dDd = 0, dDe = 0;
              for (unsigned int f = 0; f < F; ++f)
                if (in_K(f))
                  {
                    dDd += weight(f) * d[k][f] * Dd[k][f];
                    dDe += weight(f) * d[k][f] * De[k][f];
                  }
              const bool   yielding = q2[k] > 0;
              const double H1       = H1_of_q2(c, n_half, q2[k], c.sigma_y0 + c.iso * eps_ps[k]);
              H2[k]                 = c.beta + c.gamma * sign(dDe);
              const double inv_den  = 1.0 / (yielding ? c.H * q2[k] + 2.25 * dDd : 1.0);
              const double gt       = yielding ? H1 * H2[k] * (2.25 * inv_den) : 0.0;
              const double g        = gt * dDe;
              for (unsigned int f = 0; f < F; ++f)
                {
                  if (in_K(f))
                    s[k][f] += yielding ? De[k][f] - g * Dd[k][f] : De[k][f];
                  if (yielding)
                    ep[k][f] += g * d[k][f];
                }
              if (yielding)
                eps_ps[k] += std::abs(g) * std::sqrt(q2[k]) * (2.0 / 3.0);
            }
          for (unsigned int k = 0; k < P; ++k)
            {
              double      *st = st0 + k * size;
              double       d1[F];
              const double q2_1 = deviator(c, s[k], ep[k], d1);
              st[Slots::H1]     = H1_of_q2(c, n_half, q2_1, c.sigma_y0 + c.iso * eps_ps[k]);
              st[Slots::H2]     = H2[k];
              st[Slots::eps_ps] = eps_ps[k];
              for (unsigned int f = 0; f < F; ++f)
                {
                  st[Slots::epsp + f] = ep[k][f];
                  if constexpr (kin)
                    st[Slots::alpha + f] = c.kin * ep[k][f];
                  if (dim == 2 && f == 2)
                    {
                      if constexpr (!ps)
                        st[Slots::sigma_zz] = s[k][f];
                    }
                  else
                    {
                      const auto ij           = tensor_index<dim>(f);
                      stress[k][ij[0]][ij[1]] = s[k][f];
                    }
                }
            }
        }
      };

      template <int dim>
      bool
      want_hoop_tangent(const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents,
                        const dealii::ArrayView<HoopTangent<dim>>                &hoop_tangents)
      {
        Assert(hoop_tangents.size() == 0 || hoop_tangents.size() == tangents.size(),
               dealii::ExcDimensionMismatch(hoop_tangents.size(), tangents.size()));
        (void)tangents;
        return hoop_tangents.size() > 0;
      }

      /// One batch; @p hoop: null, or the hoop strain increments (axisymmetric), whose
      /// tangent terms go to @p hoop_tangents if that is not empty.
      template <int dim, typename L, BoucWenIntegrator integrator>
      void
      run_batch(const Constants                                                &c,
                const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
                const double                                                   *hoop,
                const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
                const dealii::ArrayView<double>                                &states,
                const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
                const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents)
      {
        const bool want_hoop = want_hoop_tangent(tangents, hoop_tangents);
        using P                             = Point<dim, L>;
        constexpr unsigned int size         = L::Slots::size;
        const bool             want_tangent = tangents.size() > 0;
        AssertDimension(states.size(), strain_increments.size() * size);
        AssertDimension(stresses.size(), strain_increments.size());
        Assert(!want_tangent || tangents.size() == strain_increments.size(),
               dealii::ExcDimensionMismatch(tangents.size(), strain_increments.size()));

        if constexpr (integrator == BoucWenIntegrator::forward_euler && !L::is_degrading)
          {
            using FE                  = FusedForwardEuler<dim, L>;
            const unsigned int n_half = c.n_integer % 2 == 0 ? c.n_integer / 2 : 0;
            double            *st     = states.data();
            std::size_t        p      = 0;
            if (!want_tangent)
              for (; p + 4 <= strain_increments.size(); p += 4, st += 4 * size)
                FE::template update_points<4>(c,
                                              n_half,
                                              &strain_increments[p],
                                              hoop ? hoop + p : nullptr,
                                              &stresses[p],
                                              st,
                                              size);
            for (; p < strain_increments.size(); ++p, st += size)
              FE::update(c,
                         n_half,
                         strain_increments[p],
                         hoop ? hoop[p] : 0.0,
                         stresses[p],
                         st,
                         want_tangent ? &tangents[p] : nullptr,
                         want_hoop ? &hoop_tangents[p] : nullptr);
            return;
          }

        std::size_t p = 0;
        if constexpr (integrator == BoucWenIntegrator::adaptive)
          if (!want_tangent)
            {
              // Interleaved first attempts (Law::adaptive_points()); no tangent, so
              // only the end state's H1 and H2 are needed.
              constexpr unsigned int n_points = 8;
              typename L::VecN       y[n_points];
              typename L::VecK       deps[n_points];
              typename L::Rates      r[n_points];
              for (; p + n_points <= strain_increments.size(); p += n_points)
                {
                  double *st = states.data() + p * size;
                  for (unsigned int k = 0; k < n_points; ++k)
                    {
                      P::load(stresses[p + k], st + k * size, y[k]);
                      P::strain(strain_increments[p + k], hoop ? hoop[p + k] : 0.0, deps[k]);
                    }
                  L::template adaptive_points<n_points>(c, y, deps, r);
                  for (unsigned int k = 0; k < n_points; ++k)
                    P::store(c, y[k], r[k].H1, r[k].H2, stresses[p + k], st + k * size);
                }
            }

        typename L::VecN y;
        typename L::VecK deps;
        typename L::MatK T;
        for (; p < strain_increments.size(); ++p)
          {
            double *st = states.data() + p * size;
            P::load(stresses[p], st, y);
            P::strain(strain_increments[p], hoop ? hoop[p] : 0.0, deps);
            double H1 = 0, H2 = 0;
            if constexpr (integrator == BoucWenIntegrator::forward_euler)
              {
                typename L::Rates r;
                L::forward_euler(c, y, deps, r);
                H1 = L::H1_at(c, y.data());
                H2 = r.H2;
                if (want_tangent)
                  L::continuum_tangent(c, r, T);
              }
            else if constexpr (integrator == BoucWenIntegrator::adaptive)
              {
                typename L::Rates r;
                L::adaptive(c, y, deps, r, want_tangent);
                H1 = r.H1;
                H2 = r.H2;
                if (want_tangent)
                  L::continuum_tangent(c, r, T);
              }
            else
              L::backward_euler(c, y, deps, H1, H2, want_tangent ? &T : nullptr);
            P::store(c, y, H1, H2, stresses[p], st);
            if (want_tangent)
              P::tangent(T, tangents[p], want_hoop ? &hoop_tangents[p] : nullptr);
          }
      }
    } // namespace

    template <int dim>
    void
    BoucWen<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      BoucWenParameters::declare_parameters(prm);
    }

    template <int dim>
    void
    BoucWen<dim>::parse_parameters(const Section &section)
    {
      for (const auto &w : parameters.parse_parameters(section))
        this->add_warning(w);

      const Elasticity &el = this->elasticity();
      stress_state         = dim == 3 ? StressState::three_dimensional : el.stress_state;

      Constants &c   = constants;
      c.E            = el.youngs_modulus;
      c.nu           = el.poissons_ratio;
      c.two_mu       = 2.0 * el.shear_modulus();
      c.lambda_eff   = el.effective_lambda();
      c.sigma_y0     = parameters.yield_stress;
      c.eps_y        = c.sigma_y0 / c.E;
      // (An implausible yield strain sigma_y / E is refused or warned about by the
      // parameters, for every user of the law.)
      const double a = parameters.post_yield_ratio;
      const double m = parameters.isotropic_fraction;
      c.H            = a * c.E / (1.0 - a);
      c.kin          = (1.0 - m) * 2.0 / 3.0 * c.H;
      c.kin_q        = (1.0 - m) * c.H;
      c.iso          = m * c.H;
      c.n            = parameters.smoothness;
      c.n_integer =
        (c.n == std::floor(c.n) && c.n >= 1 && c.n <= 1024) ? static_cast<unsigned int>(c.n) : 0;
      c.n_half       = c.n_integer % 2 == 0 ? c.n_integer / 2 : 0;
      c.radial_g     = 2.25 / (c.H + 1.5 * c.two_mu);
      c.H_3mu        = c.H + 1.5 * c.two_mu;
      c.beta         = parameters.beta;
      c.gamma        = parameters.gamma;
      c.c_eta        = parameters.stiffness_degradation_c_eta;
      c.m_u          = parameters.stiffness_degradation_m_u;
      c.inv_m_u1     = 1.0 / (c.m_u + 1.0);
      c.c_nu_scaled  = parameters.strength_deterioration_c_nu / (c.sigma_y0 * c.eps_y);
      c.tol          = parameters.tolerance;
      c.inv_tol      = 1.0 / c.tol;
      c.inv_sigma_y0 = 1.0 / c.sigma_y0;
      c.inv_eps_y    = 1.0 / c.eps_y;
      c.inv_energy   = 1.0 / (c.sigma_y0 * c.eps_y);

      kinematic = m < 1.0;
      degrading = parameters.degradation();

      dispatch<dim>(stress_state, kinematic, degrading, [&](auto s, auto k, auto d) {
        using L     = Law<decltype(s)::value, decltype(k)::value, decltype(d)::value>;
        using Slots = typename L::Slots;
        const std::array<const char *, 6> components =
          dim == 3 ? std::array<const char *, 6>{{"xx", "yy", "zz", "xy", "yz", "xz"}} :
                     std::array<const char *, 6>{{"xx", "yy", "zz", "xy", "", ""}};
        names.assign(Slots::size, "");
        names[Slots::H1]     = "H1";
        names[Slots::H2]     = "H2";
        names[Slots::eps_ps] = "eps_ps";
        for (unsigned int f = 0; f < L::F; ++f)
          {
            names[Slots::epsp + f] = std::string("epsp_") + components[f];
            if (L::is_kinematic)
              names[Slots::alpha + f] = std::string("alpha_") + components[f];
          }
        slot_epsp_zz = Slots::epsp + 2;
        slot_epsp    = Slots::epsp;
        if (L::is_kinematic)
          slot_alpha = Slots::alpha;
        if (decltype(s)::value == StressState::plane_strain) // and axisymmetric
          {
            names[Slots::sigma_zz] = "sigma_zz";
            slot_sigma_zz          = Slots::sigma_zz;
          }
        if (L::is_degrading)
          {
            names[Slots::e_h]  = "e_h";
            names[Slots::eta]  = "eta";
            names[Slots::nu_s] = "nu_s";
            slot_eta           = Slots::eta;
            slot_nu_s          = Slots::nu_s;
          }
        if (L::track_eps_zz)
          {
            names[Slots::eps_zz] = "epsilon_zz";
            slot_eps_zz          = Slots::eps_zz;
          }
      });
    }

    template <int dim>
    void
    BoucWen<dim>::rotate_state(const dealii::Tensor<2, dim> &R, const dealii::ArrayView<double> &state) const
    {
      // The in-plane (2D) or full (3D) tensor of the slots xx, yy, zz, xy(, yz, xz): turned
      // as R T R^T; zz of a 2D model is normal to the plane of the rotation.
      constexpr unsigned int n_pairs     = dim == 3 ? 6 : 4;
      constexpr unsigned int pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
      for (const unsigned int first : {slot_epsp, slot_alpha})
        if (first != static_cast<unsigned int>(-1))
          {
            dealii::SymmetricTensor<2, dim> t;
            for (unsigned int f = 0; f < n_pairs; ++f)
              if (pairs[f][0] < dim && pairs[f][1] < dim)
                t[pairs[f][0]][pairs[f][1]] = state[first + f];
            const dealii::Tensor<2, dim> turned = R * dealii::Tensor<2, dim>(t) * dealii::transpose(R);
            for (unsigned int f = 0; f < n_pairs; ++f)
              if (pairs[f][0] < dim && pairs[f][1] < dim)
                state[first + f] = 0.5 * (turned[pairs[f][0]][pairs[f][1]] + turned[pairs[f][1]][pairs[f][0]]);
          }
    }



    template <int dim>
    void
    BoucWen<dim>::initialize_state(const dealii::ArrayView<double> &state) const
    {
      AssertDimension(state.size(), names.size());
      std::fill(state.begin(), state.end(), 0.0);
      if (degrading)
        {
          state[slot_eta]  = 1.0;
          state[slot_nu_s] = 1.0;
        }
    }

    template <int dim>
    void
    BoucWen<dim>::update(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents) const
    {
      update_batch(strain_increments, nullptr, stresses, states, tangents, {});
    }

    template <int dim>
    void
    BoucWen<dim>::update_axisymmetric(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<const double>                          &hoop_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
      const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const
    {
      // The plane-strain kernels with eps_zz' = the hoop strain rate: the same 3D law on
      // the components xx, yy, zz, xy, with sigma_zz (= sigma_tt) in the state.
      Assert(dim == 2 && stress_state == StressState::axisymmetric, dealii::ExcInternalError());
      AssertDimension(hoop_increments.size(), strain_increments.size());
      update_batch(
        strain_increments, hoop_increments.data(), stresses, states, tangents, hoop_tangents);
    }

    template <int dim>
    void
    BoucWen<dim>::update_batch(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const double                                                   *hoop_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
      const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const
    {
      dispatch<dim>(stress_state, kinematic, degrading, [&](auto s, auto k, auto d) {
        using L = Law<decltype(s)::value, decltype(k)::value, decltype(d)::value>;
        const auto run = [&](auto integrator) {
          run_batch<dim, L, decltype(integrator)::value>(constants,
                                                        strain_increments,
                                                        hoop_increments,
                                                        stresses,
                                                        states,
                                                        tangents,
                                                        hoop_tangents);
        };
        switch (parameters.integrator)
          {
            case BoucWenIntegrator::forward_euler:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::forward_euler>());
              break;
            case BoucWenIntegrator::adaptive:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::adaptive>());
              break;
            case BoucWenIntegrator::backward_euler:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::backward_euler>());
              break;
          }
      });
    }

    template <int dim>
    void
    BoucWen<dim>::out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                               const dealii::SymmetricTensor<2, dim> &stress,
                               const dealii::ArrayView<const double> &state,
                               double                                &eps_zz,
                               double                                &sigma_zz) const
    {
      if (dim == 2 && (stress_state == StressState::plane_strain ||
                       stress_state == StressState::axisymmetric))
        {
          eps_zz   = 0;
          sigma_zz = state[slot_sigma_zz];
        }
      else if (dim == 2 && degrading)
        {
          sigma_zz = 0;
          eps_zz   = state[slot_eps_zz];
        }
      else
        {
          // The elastic part (sigma_zz = 0) plus the plastic part of eps_zz (zero in 3D).
          Interface<dim>::out_of_plane(strain, stress, state, eps_zz, sigma_zz);
          if (dim == 2)
            eps_zz += state[slot_epsp_zz];
        }
    }

    template class BoucWen<2>;
    template class BoucWen<3>;
  } // namespace Material
} // namespace hysteron

HYSTERON_REGISTER_MATERIAL(
  hysteron::Material::BoucWen,
  "bouc-wen",
  "triaxial smooth Bouc-Wen law: von Mises yield with mixed isotropic/kinematic "
  "hardening (m), smooth switches H1 = |q/sigma_y|^n and H2 = beta + gamma sgn(n:D:deps), "
  "optional stiffness degradation and strength deterioration (eq. 2.46); plane stress, "
  "plane strain or 3D; forward Euler, adaptive Runge-Kutta or backward Euler with a "
  "consistent tangent (subsection Bouc-Wen).")
