#ifndef hysteron_material_bogacki_shampine_h
#define hysteron_material_bogacki_shampine_h

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace hysteron
{
  namespace Material
  {
    /**
     * The sub-step loop shared by the small Bouc-Wen laws (BoucWenUniaxial, BoucWenInteraction):
     * Bogacki-Shampine 3(2) with first-same-as-last over the pseudo time s in [0, 1] of
     * one increment, y(1) = y(0) + int_0^1 f(y) ds.
     *
     * - The whole increment is tried first (h = 1); a step is accepted when
     *   max_i |err_i| inv_scale_i <= 1 (inv_scale_i = 1 / (scale_i tolerance)), err the
     *   difference of the third- and the embedded second-order solution; the third-order
     *   solution is kept. A non-finite error (overflow of |z/z_y|^n in a too long trial
     *   step) counts as err = 1e10, i.e. the step is shortened.
     * - The 3(2) difference estimates the error of the embedded second-order solution, and
     *   in the knee of a Bouc-Wen law it can be far smaller than the error of the kept
     *   third-order solution (found: 450 times the tolerance at n = 2, h lambda ~ 1). There
     *   z' ~ -lambda (z - z_s) with the stiffness lambda = n |plastic rate| / |z|, and the
     *   error of the third-order solution is that of exp(-h lambda) by its cubic Taylor
     *   polynomial, (h lambda)^4 / 24 |z - z_s|, i.e. (h lambda)^3 / 24 |y_1 - y_0|. A step
     *   must pass that second estimate too (step factor 0.9 err^(-1/4) if it fails).
     *   @p stiffness(y, f(y)) returns lambda (0: no such estimate), taken at both ends.
     * - Step factor 0.9 err^(-1/3) in [0.2, 5] (5 after an exact step).
     * - After each accepted step @p project(y) may move y into the set the exact solution
     *   never leaves (|z| <= z_s, Phi <= Phi_s); if it returns true, f(y) is evaluated again.
     * - At most @p max_substeps attempts, then @p too_many() (which must throw).
     *
     * @p rates(y) returns f(y) as a std::array<double, N>. Returns the accepted sub-steps.
     * (The triaxial law has its own, fused variant of this loop in bouc_wen_kernels.h.)
     */
    template <std::size_t N, typename Rates, typename Stiffness, typename Project, typename Fail>
    inline unsigned int
    bogacki_shampine_32(std::array<double, N>       &v,
                        const std::array<double, N> &inv_scale,
                        const unsigned int           max_substeps,
                        Rates                      &&rates,
                        Stiffness                  &&stiffness,
                        Project                    &&project,
                        Fail                       &&too_many)
    {
      using V             = std::array<double, N>;
      double       s      = 0, h = 1;
      unsigned int accepted = 0;
      V            k1       = rates(v);
      double       lambda1  = stiffness(v, k1);
      for (unsigned int attempt = 0;; ++attempt)
        {
          if (attempt == max_substeps)
            too_many();
          const bool last = (h >= 1 - s);
          if (last)
            h = 1 - s;

          V y2, y3, y4;
          for (std::size_t i = 0; i < N; ++i)
            y2[i] = v[i] + 0.5 * h * k1[i];
          const V k2 = rates(y2);
          for (std::size_t i = 0; i < N; ++i)
            y3[i] = v[i] + 0.75 * h * k2[i];
          const V k3 = rates(y3);
          for (std::size_t i = 0; i < N; ++i)
            y4[i] = v[i] + h * (2. / 9. * k1[i] + 1. / 3. * k2[i] + 4. / 9. * k3[i]);
          const V k4 = rates(y4);

          // Difference of the third- and the embedded second-order solution.
          double err = 0;
          for (std::size_t i = 0; i < N; ++i)
            {
              const double e = std::abs(h * (-5. / 72. * k1[i] + 1. / 12. * k2[i] +
                                             1. / 9. * k3[i] - 1. / 8. * k4[i])) *
                               inv_scale[i];
              if (!(e <= err)) // also catches NaN
                err = e;
            }
          if (!std::isfinite(err))
            err = 1e10; // overflow of |z/z_y|^n in a trial stage: shrink the step

          // The second estimate (see above).
          const double hl = h * std::max(lambda1, stiffness(y4, k4));
          if (err <= 1 && hl > 0)
            {
              double change = 0;
              for (std::size_t i = 0; i < N; ++i)
                change = std::max(change, std::abs(y4[i] - v[i]) * inv_scale[i]);
              const double stiff_err = hl * hl * hl / 24 * change;
              if (stiff_err > 1)
                {
                  h *= std::max(0.2, 0.9 / std::sqrt(std::sqrt(stiff_err)));
                  continue;
                }
            }

          if (err <= 1)
            {
              v  = y4;
              k1 = k4;
              if (project(v))
                k1 = rates(v);
              lambda1 = stiffness(v, k1);
              ++accepted;
              if (last)
                return accepted;
              s += h;
            }
          h *= (err == 0 ? 5.0 : std::min(5.0, std::max(0.2, 0.9 / std::cbrt(err))));
        }
    }
  } // namespace Material
} // namespace hysteron

#endif
