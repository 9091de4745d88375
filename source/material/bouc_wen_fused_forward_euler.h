#ifndef hysteron_source_material_bouc_wen_fused_forward_euler_h
#define hysteron_source_material_bouc_wen_fused_forward_euler_h

// Forward Euler of the triaxial Bouc-Wen law without degradation, fused with the
// conversions at the interface (tensor components read and written in place) for one
// point and for several points interleaved.

#include <deal.II/base/symmetric_tensor.h>

#include <hysteron/material/bouc_wen.h>

#include "material/bouc_wen_kernels.h"

#include <cmath>

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
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
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif
