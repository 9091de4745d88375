#ifndef hysteron_source_material_bouc_wen_explicit_h
#define hysteron_source_material_bouc_wen_explicit_h

// The explicit integrators of the Bouc-Wen point kernels (forward Euler, the adaptive
// embedded pair with its error estimates and sub-stepping, the interleaved first attempt
// of several points, drift correction): members of BoucWenKernels::Law declared in
// bouc_wen_kernels.h, which includes this file at its end, with the equations documented
// there.

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::forward_euler(const Constants &c, VecN &y, const VecK &deps, Rates &r)
      {
        VecK De;
        apply_D(c, deps.data(), De.data());
        VecN dy;
        rates(c, y.data(), De, dy.data(), r);
        for (unsigned int i = 0; i < N; ++i)
          y[i] += dy[i];
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::error_norm(const Constants &c, const VecN &err)
      {
        double e = 0;
        for (unsigned int a = 0; a < K; ++a)
          e = max_nan(e, std::abs(err[a]) * c.inv_sigma_y0);
        for (unsigned int i = K; i <= i_eps_ps; ++i)
          e = max_nan(e, std::abs(err[i]) * c.inv_eps_y);
        if (degrading)
          e = max_nan(e, std::abs(err[i_e_h]) * c.inv_energy);
        if (track_eps_zz)
          e = max_nan(e, std::abs(err[i_eps_zz]) * c.inv_eps_y);
        return e * c.inv_tol;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::plastic_correction(const Constants &c, VecN &y, const Rates &r, const double dlambda)
      {
        double sn = 0;
        for (unsigned int a = 0; a < K; ++a)
          sn += y[a] * r.n[G::full[a]];
        const double s0 = y[0], s1 = y[1];
        for (unsigned int a = 0; a < K; ++a)
          y[a] -= dlambda * r.Dn[a];
        for (unsigned int f = 0; f < F; ++f)
          y[i_epsp + f] += dlambda * r.n[f];
        y[i_eps_ps] += std::abs(dlambda);
        if (degrading)
          y[i_e_h] += dlambda * sn;
        if (track_eps_zz)
          y[i_eps_zz] += r.eta * (-c.nu / c.E * (y[0] - s0 + y[1] - s1) + dlambda * r.n[2]);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::drift_correction(const Constants &c, VecN &y, Rates &r)
      {
        for (unsigned int iteration = 0; iteration < 5; ++iteration)
          {
            const double scale  = degrading ? std::pow(r.nu, -1.0 / c.n) : 1.0;
            const double target = r.sigma_y * scale;
            if (!(r.q > target * (1 + 1e-14)) || r.lambda1 == 0)
              break;
            // d(q - q*)/d dlambda = -(n:D:n + (1 - m) H' + m H' nu^(-1/n))
            //                       + q* / (n nu) c_nu sigma:n / (sigma_y0 eps_y)
            double slope = 1.0 / r.lambda1 - c.H + c.kin_q + c.iso * scale;
            if (degrading)
              {
                double sn = 0;
                for (unsigned int a = 0; a < K; ++a)
                  sn += y[a] * r.n[G::full[a]];
                slope -= target / (c.n * r.nu) * c.c_nu_scaled * sn;
              }
            if (!(slope > 0))
              break;
            plastic_correction(c, y, r, (r.q - target) / slope);
            VecF alpha, dev;
            if (kinematic)
              for (unsigned int f = 0; f < F; ++f)
                alpha[f] = c.kin * y[i_epsp + f];
            r.q       = relative_deviator(y.data(), kinematic ? alpha.data() : nullptr, dev);
            r.sigma_y = c.sigma_y0 + c.iso * y[i_eps_ps];
            if (degrading)
              r.nu = 1.0 + c.c_nu_scaled * y[i_e_h];
            r.H1 = H1_of(c, r.q, r.sigma_y);
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::bs32_error(const Constants &c,
                                               const double     h,
                                               const VecN      &k1,
                                               const VecN      &k2,
                                               const VecN      &k3,
                                               const VecN      &k4)
      {
        VecN err;
        for (unsigned int i = 0; i < N; ++i)
          err[i] = h * (-5.0 / 72.0 * k1[i] + 1.0 / 12.0 * k2[i] + 1.0 / 9.0 * k3[i] -
                        0.125 * k4[i]);
        return error_norm(c, err);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline unsigned int
      Law<S, kinematic, degrading>::substeps(const Constants &c,
                                             VecN            &y,
                                             const VecK      &De,
                                             VecN            &k1,
                                             double           H1_now,
                                             double           h,
                                             unsigned int     attempts,
                                             Rates           &r,
                                             const bool       full_rates)
      {
        VecN   k2, k3, k4, yt, y_new;
        Stage  stage;
        double s = 0;
        while (true)
          {
            if (++attempts > c.max_substeps)
              {
                std::ostringstream m;
                m << "Bouc-Wen (adaptive integrator): more than " << c.max_substeps
                  << " sub-steps for one strain increment (reached s = " << s << ", sub-step "
                  << h << ", H1 = " << H1_now
                  << "). Reduce the strain increment or raise Material/Bouc-Wen/Tolerance.";
                // A unit slip (a yield stress in MPa with E in Pa) looks like this failure.
                if (c.eps_y < 1e-7 || c.eps_y > 0.05)
                  m << " The yield strain sigma_y / E = " << c.eps_y
                    << " is far from that of structural materials (1e-5 to 1e-2): are the yield "
                       "stress and Young's modulus both in Pa?";
                throw RuntimeError(m.str());
              }
            const bool last = (s + h >= 1.0);
            if (last)
              h = 1.0 - s;
            for (unsigned int i = 0; i < N; ++i)
              yt[i] = y[i] + 0.5 * h * k1[i];
            stage_rates(c, yt.data(), De, k2.data());
            for (unsigned int i = 0; i < N; ++i)
              yt[i] = y[i] + 0.75 * h * k2[i];
            stage_rates(c, yt.data(), De, k3.data());
            for (unsigned int i = 0; i < N; ++i)
              y_new[i] = y[i] + h * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i]);
            const bool   full_new = last && full_rates;
            const double H1_new   = full_new ?
                                      (rates(c, y_new.data(), De, k4.data(), r), r.H1) :
                                      stage_rates(c, y_new.data(), De, k4.data(), &stage);
            const double e        = bs32_error(c, h, k1, k2, k3, k4);
            if (!std::isfinite(e))
              {
                // Overflow in a too long trial step (H1 = (q/sigma_y)^n explodes for
                // large n): shorten it; a non-finite start is an error.
                bool finite = true;
                for (unsigned int i = 0; i < N; ++i)
                  finite = finite && std::isfinite(y[i]) && std::isfinite(k1[i]);
                if (!finite)
                  {
                    std::ostringstream m;
                    m << "Bouc-Wen (adaptive integrator): non-finite rates at s = " << s
                      << " of a strain increment (stress, state or increment not finite)";
                    throw RuntimeError(m.str());
                  }
                h *= 0.1;
              }
            else if (const double es =
                       (e <= 1.0 ? stiff_error(c, h, y, k1, k4, H1_now, H1_new) : 0.0);
                     es > 1.0)
              h *= std::max(0.2, 0.9 / std::sqrt(std::sqrt(es)));
            else if (e <= 1.0)
              {
                y      = y_new;
                k1     = k4;
                H1_now = H1_new;
                if (last)
                  {
                    finish(c, y, De, stage, r, full_new);
                    return attempts;
                  }
                s += h;
                h *= (e > 0) ? std::min(5.0, 0.9 / std::cbrt(e)) : 5.0;
              }
            else
              h *= std::max(0.2, 0.9 / std::cbrt(e));
            if (h < 1e-13)
              {
                std::ostringstream m;
                m << "Bouc-Wen (adaptive integrator): the sub-step fell below 1e-13 of the "
                     "increment at s = "
                  << s << " (H1 = " << H1_now
                  << "): the tolerance cannot be met in double precision. Raise "
                     "Material/Bouc-Wen/Tolerance.";
                throw RuntimeError(m.str());
              }
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline unsigned int
      Law<S, kinematic, degrading>::adaptive(const Constants &c,
                                             VecN            &y,
                                             const VecK      &deps,
                                             Rates           &r,
                                             const bool       full_rates)
      {
        VecK De;
        apply_D(c, deps.data(), De.data());
        VecN  k1;
        Stage st;
        stage_rates(c, y.data(), De, k1.data(), &st);
        return substeps(c, y, De, k1, st.H1, 1.0, 0, r, full_rates);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::drift_correction_stage(const Constants &c, VecN &y, const Stage &stage, Rates &r)
      {
        constexpr bool radial = S != StressState::plane_stress;
        VecF           d  = stage.d;
        VecK           Dd = stage.Dd;
        double         q2 = stage.q2, q = stage.q, sy = stage.sigma_y, dDd = stage.dDd;
        for (unsigned int iteration = 0; iteration < 5; ++iteration)
          {
            // dlambda = (q - sigma_y) / slope, phi = 3/2 dlambda / q
            // (The first step in plane stress reuses 1 / den of the stage.)
            const double x = radial ? (q - sy) / (q * c.H_3mu) :
                             (iteration == 0 && stage.inv_den != 0) ?
                                      (q - sy) * q * stage.inv_den :
                                      (q - sy) * q / (c.H * q2 + 2.25 * dDd);
            const double phi = 1.5 * x;
            for (unsigned int a = 0; a < K; ++a)
              y[a] -= phi * Dd[a];
            for (unsigned int f = 0; f < F; ++f)
              y[i_epsp + f] += phi * d[f];
            y[i_eps_ps] += x * q;
            q2 = deviator(c, y.data(), d);
            sy = c.sigma_y0 + c.iso * y[i_eps_ps];
            if (!(q2 > sy * sy * (1 + 2e-14)))
              break;
            q = std::sqrt(q2);
            VecK d_K;
            for (unsigned int a = 0; a < K; ++a)
              d_K[a] = d[G::full[a]];
            if (radial)
              for (unsigned int a = 0; a < K; ++a)
                Dd[a] = c.two_mu * d_K[a];
            else
              {
                apply_D(c, d_K.data(), Dd.data());
                dDd = dot<K>(d_K.data(), Dd.data());
              }
          }
        // t = q^2 / sigma_y^2 without a division: sigma_y moved by the tiny
        // r = (sigma_y - sigma_y,stage) / sigma_y,stage, and 1 / (1 + r)^2 =
        // 1 - 2 r + 3 r^2 + O(r^3) (exact to round-off for |r| < 1e-6).
        const double r_sy = (sy - stage.sigma_y) * stage.sigma_y * stage.inv_sy2;
        const double t    = (stage.inv_sy2 != 0 && std::abs(r_sy) < 1e-6) ?
                              q2 * (stage.inv_sy2 * (1.0 - r_sy * (2.0 - 3.0 * r_sy))) :
                              q2 / (sy * sy);
        r.H1 = c.n_half != 0 ? integer_power(t, c.n_half) : power(c, std::sqrt(t));
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::finish(const Constants &c,
                                           VecN            &y,
                                           const VecK      &De,
                                           const Stage     &stage,
                                           Rates           &r,
                                           const bool       full)
      {
        if (!full)
          {
            r.q       = stage.q;
            r.sigma_y = stage.sigma_y;
            r.H1      = stage.H1;
            r.H2      = stage.H2;
            r.nu      = stage.nu;
            r.eta     = stage.eta;
          }
        // With strength deterioration the exact solution leaves nu_s H1 <= 1 (the
        // saturation stress falls as e_h grows, and q follows it with a lag): no correction.
        if (degrading && c.c_nu_scaled != 0)
          return;
        const double target = r.sigma_y * (degrading ? std::pow(r.nu, -1.0 / c.n) : 1.0);
        if (!(r.q > target * (1 + 1e-14)))
          return;
        if (!full)
          {
            if constexpr (!degrading)
              {
                drift_correction_stage(c, y, stage, r);
                return;
              }
            VecN dy;
            rates(c, y.data(), De, dy.data(), r);
          }
        drift_correction(c, y, r);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::stiff_error(const Constants &c,
                                                const double     h,
                                                const VecN      &y,
                                                const VecN      &k1,
                                                const VecN      &k4,
                                                const double     H1_0,
                                                const double     H1_1)
      {
        const double hl = h * c.n * 1.5 * c.two_mu *
                          std::max(k1[i_eps_ps], k4[i_eps_ps]) /
                          (c.sigma_y0 + c.iso * y[i_eps_ps]);
        return hl * hl * hl / 24 * std::abs(H1_1 - H1_0) / c.n * c.inv_tol;
      }



      template <StressState S, bool kinematic, bool degrading>
      template <unsigned int P>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::adaptive_points(const Constants &c, VecN *y, const VecK *deps, Rates *r)
      {
        VecK  De[P];
        VecN  k1[P], k2[P], k3[P], k4[P], yt[P];
        Stage st[P];
        // One stage for all points: the deviators first, then the powers and
        // divisions, which thus overlap.
        const auto stage = [&](const VecN *x, VecN *k) {
          for (unsigned int p = 0; p < P; ++p)
            stage_begin(c, x[p].data(), De[p], st[p]);
          for (unsigned int p = 0; p < P; ++p)
            stage_end(c, x[p].data(), De[p], st[p], k[p].data());
        };
        for (unsigned int p = 0; p < P; ++p)
          apply_D(c, deps[p].data(), De[p].data());
        stage(y, k1);
        double H1[P];
        for (unsigned int p = 0; p < P; ++p)
          {
            H1[p] = st[p].H1;
            for (unsigned int i = 0; i < N; ++i)
              yt[p][i] = y[p][i] + 0.5 * k1[p][i];
          }
        stage(yt, k2);
        for (unsigned int p = 0; p < P; ++p)
          for (unsigned int i = 0; i < N; ++i)
            yt[p][i] = y[p][i] + 0.75 * k2[p][i];
        stage(yt, k3);
        for (unsigned int p = 0; p < P; ++p)
          for (unsigned int i = 0; i < N; ++i)
            yt[p][i] =
              y[p][i] + (2.0 / 9.0 * k1[p][i] + 1.0 / 3.0 * k2[p][i] + 4.0 / 9.0 * k3[p][i]);
        stage(yt, k4);
        for (unsigned int p = 0; p < P; ++p)
          {
            const double e  = bs32_error(c, 1.0, k1[p], k2[p], k3[p], k4[p]);
            const double es =
              e <= 1.0 ? stiff_error(c, 1.0, y[p], k1[p], k4[p], H1[p], st[p].H1) : 0.0;
            if (es > 1.0)
              substeps(c, y[p], De[p], k1[p], H1[p],
                       std::max(0.2, 0.9 / std::sqrt(std::sqrt(es))), 1, r[p], false);
            else if (e <= 1.0)
              {
                y[p] = yt[p];
                finish(c, y[p], De[p], st[p], r[p], false);
              }
            else if (std::isfinite(e))
              substeps(
                c, y[p], De[p], k1[p], H1[p], std::max(0.2, 0.9 / std::cbrt(e)), 1, r[p], false);
            else // repeat the attempt in substeps(), which shortens or throws
              substeps(c, y[p], De[p], k1[p], H1[p], 1.0, 0, r[p], false);
          }
      }
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif
