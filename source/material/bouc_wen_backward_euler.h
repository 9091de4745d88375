#ifndef hysteron_source_material_bouc_wen_backward_euler_h
#define hysteron_source_material_bouc_wen_backward_euler_h

// The backward Euler integrator of the Bouc-Wen point kernels (residual and Jacobian,
// scaling, Newton's method with continuation, the end state and the consistent tangent):
// the members of BoucWenKernels::Law declared in bouc_wen_kernels.h (which includes this
// file at its end) with the equations and scaling documented there.

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::evaluate(const Constants &c, const BEData &d, const VecM &x, VecM &R, MatM *J, Iterate &it)
      {
        const double *sigma = x.data();
        VecF          dev;
        const double  qt = relative_deviator(sigma, kinematic ? d.alpha0.data() : nullptr, dev);
        const double  inv_q = qt > 0 ? 1.5 / qt : 0.0;
        for (unsigned int f = 0; f < F; ++f)
          it.n[f] = inv_q * dev[f];
        for (unsigned int a = 0; a < K; ++a)
          it.n_K[a] = it.n[G::full[a]];
        apply_D(c, it.n_K.data(), it.Dn.data());
        const double nDn = dot<K>(it.n_K.data(), it.Dn.data());
        const double nDe = dot<K>(it.n_K.data(), d.De.data());
        it.lambda1       = 1.0 / (c.H + nDn);
        // H2 of the iterate (fully implicit): H2 n:D:deps = beta n:D:deps +
        // gamma |n:D:deps| is continuous, so the residual is semismooth and its
        // derivative is H2 d(n:D:deps) away from the kink.
        it.H2 = c.beta + c.gamma * sign(nDe);

        const double w = x[i_w];
        it.wn          = power(c, w);
        double deta    = 0; // d eta1 / d dlambda
        double eps_ps1 = 0;
        if (degrading)
          {
            it.dlambda      = x[i_dl];
            eps_ps1         = d.eps_ps0 + std::abs(it.dlambda);
            it.eta1         = eta_of(c, eps_ps1);
            const double sl = it.dlambda != 0 ? sign(it.dlambda) : d.s_lambda;
            if (c.c_eta > 0)
              deta = c.c_eta * std::pow(it.eta1, -c.m_u) * sl;
            it.nu1 = 1.0 + c.c_nu_scaled * x[i_eh];
            it.c   = it.nu1 * it.H2 * it.lambda1 * nDe / it.eta1;
          }
        else
          {
            it.c       = it.H2 * it.lambda1 * nDe;
            it.dlambda = it.c * it.wn;
            eps_ps1    = d.eps_ps0 + std::abs(it.dlambda);
          }
        const double dl = it.dlambda;
        it.sigma_y1     = c.sigma_y0 + c.iso * eps_ps1;
        it.q1           = qt - c.kin_q * dl;

        for (unsigned int a = 0; a < K; ++a)
          R[a] = sigma[a] - d.sigma0[a] - d.De[a] / it.eta1 + dl * it.Dn[a];
        R[i_w]          = it.q1 / it.sigma_y1 - w;
        const double sn = dot<K>(sigma, it.n_K.data());
        if (degrading)
          {
            R[i_dl] = dl - it.c * it.wn;
            R[i_eh] = x[i_eh] - d.e_h0 - dl * sn;
          }

        const double sl = dl != 0 ? sign(dl) : d.s_lambda;
        // d R_w / d dlambda
        it.gw = -c.kin_q / it.sigma_y1 - it.q1 * c.iso * sl / (it.sigma_y1 * it.sigma_y1);
        if (J)
          jacobian(c, d, x, it, inv_q, nDe, deta, sn, *J);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::jacobian(const Constants &c,
                                             const BEData    &d,
                                             const VecM      &x,
                                             const Iterate   &it,
                                             const double     inv_q,
                                             const double     nDe,
                                             const double     deta,
                                             const double     sn,
                                             MatM            &Jm)
      {
        const double *sigma = x.data();
        const double  w     = x[i_w];
        const double  dl    = it.dlambda;
        // dn_K / dsigma = 3/(2 q) (P_dev - 2/3 n n) restricted to K (symmetric).
        MatK Nk;
        for (unsigned int b = 0; b < K; ++b)
          for (unsigned int a = 0; a < K; ++a)
            {
              const unsigned int fb = G::full[b], fa = G::full[a];
              const double pdev = (fa == fb ? 1.0 : 0.0) - (fa < 3 && fb < 3 ? 1.0 / 3.0 : 0.0);
              Nk[b][a]          = inv_q * (pdev - 2.0 / 3.0 * it.n[fb] * it.n[fa]);
            }
        MatK DN; // D Nk, column by column
        for (unsigned int a = 0; a < K; ++a)
          {
            VecK col, dcol;
            for (unsigned int b = 0; b < K; ++b)
              col[b] = Nk[b][a];
            apply_D(c, col.data(), dcol.data());
            for (unsigned int b = 0; b < K; ++b)
              DN[b][a] = dcol[b];
          }
        VecK dc_dsigma, Nsigma;
        for (unsigned int a = 0; a < K; ++a)
          {
            double dnDn = 0, dnDe = 0, ns = 0;
            for (unsigned int b = 0; b < K; ++b)
              {
                dnDn += 2.0 * it.Dn[b] * Nk[b][a];
                dnDe += d.De[b] * Nk[b][a];
                ns += sigma[b] * Nk[b][a];
              }
            const double dlambda1 = -it.lambda1 * it.lambda1 * dnDn;
            dc_dsigma[a] = it.nu1 * it.H2 / it.eta1 * (nDe * dlambda1 + it.lambda1 * dnDe);
            Nsigma[a]    = ns;
          }

        Jm.fill(0.0);
        const double dwn_dw = w > 0 ? c.n * it.wn / w : 0.0;
        if (!degrading)
          {
            // dlambda = c(sigma) w^n eliminated.
            const double ddl_dw = it.c * dwn_dw;
            for (unsigned int a = 0; a < K; ++a)
              {
                for (unsigned int b = 0; b < K; ++b)
                  Jm[a * M + b] =
                    (a == b ? 1.0 : 0.0) + dl * DN[a][b] + it.Dn[a] * it.wn * dc_dsigma[b];
                Jm[a * M + i_w] = it.Dn[a] * ddl_dw;
              }
            for (unsigned int b = 0; b < K; ++b)
              Jm[i_w * M + b] = it.n_K[b] / it.sigma_y1 + it.gw * it.wn * dc_dsigma[b];
            Jm[i_w * M + i_w] = -1.0 + it.gw * ddl_dw;
          }
        else
          {
            const double dc_ddl = -it.c * deta / it.eta1;
            const double dc_deh = it.H2 * it.lambda1 * nDe * c.c_nu_scaled / it.eta1;
            for (unsigned int a = 0; a < K; ++a)
              {
                for (unsigned int b = 0; b < K; ++b)
                  Jm[a * M + b] = (a == b ? 1.0 : 0.0) + dl * DN[a][b];
                Jm[a * M + i_dl] = it.Dn[a] + d.De[a] * deta / (it.eta1 * it.eta1);
              }
            for (unsigned int b = 0; b < K; ++b)
              {
                Jm[i_w * M + b]  = it.n_K[b] / it.sigma_y1;
                Jm[i_dl * M + b] = -it.wn * dc_dsigma[b];
                Jm[i_eh * M + b] = -dl * (it.n_K[b] + Nsigma[b]);
              }
            Jm[i_w * M + i_w]   = -1.0;
            Jm[i_w * M + i_dl]  = it.gw;
            Jm[i_dl * M + i_w]  = -it.c * dwn_dw;
            Jm[i_dl * M + i_dl] = 1.0 - it.wn * dc_ddl;
            Jm[i_dl * M + i_eh] = -it.wn * dc_deh;
            Jm[i_eh * M + i_dl] = -sn;
            Jm[i_eh * M + i_eh] = 1.0;
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::unknown_scale(const Constants &c, const unsigned int i)
      {
        return i < K ? c.sigma_y0 : i == i_w ? 1.0 : i == i_dl ? c.eps_y : c.sigma_y0 * c.eps_y;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::inverse_scale(const Constants &c, const unsigned int i)
      {
        return i < K ? c.inv_sigma_y0 : i == i_w ? 1.0 : i == i_dl ? c.inv_eps_y : c.inv_energy;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::scale_jacobian(const Constants &c, MatM &J)
      {
        for (unsigned int i = 0; i < M; ++i)
          {
            const double inv_i = inverse_scale(c, i);
            for (unsigned int j = 0; j < M; ++j)
              J[i * M + j] *= unknown_scale(c, j) * inv_i;
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::residual_norm2(const Constants &c, const VecM &R)
      {
        double e = 0;
        for (unsigned int i = 0; i < M; ++i)
          e += (R[i] * inverse_scale(c, i)) * (R[i] * inverse_scale(c, i));
        return e;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::residual_norm(const Constants &c, const VecM &R)
      {
        double e = 0;
        for (unsigned int i = 0; i < M; ++i)
          e = max_nan(e, std::abs(R[i]) * inverse_scale(c, i));
        return e;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::guess(const Constants &c, const BEData &d, VecM &x)
      {
        const double eta0 = eta_of(c, d.eps_ps0);
        VecK         sigma_tr, n_tr, Dn_tr;
        for (unsigned int a = 0; a < K; ++a)
          sigma_tr[a] = d.sigma0[a] + d.De[a] / eta0;
        VecF         dev;
        const double q_tr =
          relative_deviator(sigma_tr.data(), kinematic ? d.alpha0.data() : nullptr, dev);
        for (unsigned int a = 0; a < K; ++a)
          n_tr[a] = q_tr > 0 ? 1.5 * dev[G::full[a]] / q_tr : 0.0;
        apply_D(c, n_tr.data(), Dn_tr.data());
        const double nDe  = dot<K>(n_tr.data(), d.De.data());
        const double nu0  = degrading ? 1.0 + c.c_nu_scaled * d.e_h0 : 1.0;
        const double H2   = c.beta + c.gamma * sign(nDe);
        const double c_tr = nu0 * H2 * nDe / ((c.H + dot<K>(n_tr.data(), Dn_tr.data())) * eta0);
        const double sigma_y = c.sigma_y0 + c.iso * d.eps_ps0;
        const double w0      = std::max(std::min(1.0, q_tr / sigma_y), 1e-3);
        const double dl0     = c_tr * power(c, w0);
        const double eta1    = eta_of(c, d.eps_ps0 + std::abs(dl0));
        for (unsigned int a = 0; a < K; ++a)
          x[a] = d.sigma0[a] + d.De[a] / eta1 - dl0 * Dn_tr[a];
        x[i_w] = w0;
        if (degrading)
          {
            x[i_dl] = dl0;
            x[i_eh] = d.e_h0 + dl0 * dot<K>(x.data(), n_tr.data());
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline bool
      Law<S, kinematic, degrading>::newton(const Constants   &c,
             const BEData      &d,
             VecM              &x,
             VecM              &R,
             Iterate           &it,
             const unsigned int max_iterations,
             unsigned int      &iterations)
      {
        VecM                        R_new, x_new, dx;
        MatM                        J;
        std::array<unsigned int, M> pivot;
        Iterate                     it_new;
        evaluate(c, d, x, R, nullptr, it);
        double norm = residual_norm(c, R);
        for (unsigned int k = 0; !(norm <= c.tol); ++k)
          {
            if (k == max_iterations || !std::isfinite(norm))
              return false;
            ++iterations;
            evaluate(c, d, x, R, &J, it);
            scale_jacobian(c, J);
            if (!lu_factorize<M>(J, pivot))
              return false;
            for (unsigned int i = 0; i < M; ++i)
              dx[i] = -R[i] * inverse_scale(c, i);
            lu_solve<M>(J, pivot, dx.data());
            for (unsigned int i = 0; i < M; ++i)
              dx[i] *= unknown_scale(c, i);
            double t = 1.0;
            if (x[i_w] + dx[i_w] <= 0)
              t = 0.9 * x[i_w] / -dx[i_w];
            else if (x[i_w] + dx[i_w] > d.w_cap)
              t = std::max(0.0, (d.w_cap - x[i_w]) / dx[i_w]);
            const double merit = residual_norm2(c, R);
            for (unsigned int ls = 0; ls < 30; ++ls, t *= 0.5)
              {
                for (unsigned int i = 0; i < M; ++i)
                  x_new[i] = x[i] + t * dx[i];
                evaluate(c, d, x_new, R_new, nullptr, it_new);
                if (residual_norm2(c, R_new) <= (1.0 - 1e-4 * t) * merit)
                  break;
              }
            x    = x_new;
            R    = R_new;
            it   = it_new;
            norm = residual_norm(c, R);
          }
        return true;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) typename Law<S, kinematic, degrading>::Trial
      Law<S, kinematic, degrading>::begin_increment(const Constants &c,
                                                    const VecN      &y,
                                                    const VecK      &deps,
                                                    BEData          &d)
      {
        for (unsigned int a = 0; a < K; ++a)
          d.sigma0[a] = y[a];
        apply_D(c, deps.data(), d.De.data());
        if (kinematic)
          for (unsigned int f = 0; f < F; ++f)
            d.alpha0[f] = c.kin * y[i_epsp + f];
        d.eps_ps0 = y[i_eps_ps];
        d.e_h0    = degrading ? y[i_e_h] : 0.0;

        // Elastic trial state and the loading direction.
        Trial tr;
        tr.eta0 = eta_of(c, d.eps_ps0);
        for (unsigned int a = 0; a < K; ++a)
          tr.sigma[a] = d.sigma0[a] + d.De[a] / tr.eta0;
        VecF dev;
        tr.q = relative_deviator(tr.sigma.data(), kinematic ? d.alpha0.data() : nullptr, dev);
        for (unsigned int a = 0; a < K; ++a)
          tr.n[a] = tr.q > 0 ? 1.5 * dev[G::full[a]] / tr.q : 0.0;
        tr.nDe     = dot<K>(tr.n.data(), d.De.data());
        tr.sigma_y = c.sigma_y0 + c.iso * d.eps_ps0;
        d.H2       = c.beta + c.gamma * sign(tr.nDe);
        d.s_lambda = sign(tr.nDe);

        VecF         dev0;
        const double q0 =
          relative_deviator(d.sigma0.data(), kinematic ? d.alpha0.data() : nullptr, dev0);
        d.w_cap = 2.0 * std::max(1.0, std::max(tr.q, q0) / tr.sigma_y);
        // With beta > gamma, nu_s H1 (beta - gamma) > 1 is the run-away regime of the
        // law itself (Phi' = n:D:deps (1 - nu_s H1 H2) > 0 while unloading): keep
        // the iterates below it.
        const double nu0 = degrading ? 1.0 + c.c_nu_scaled * d.e_h0 : 1.0;
        if (c.beta > c.gamma && nu0 > 0)
          d.w_cap = std::min(d.w_cap, std::pow(nu0 * (c.beta - c.gamma), -1.0 / c.n));
        return tr;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::elastic_update(const Constants &c,
                                                   VecN            &y,
                                                   const BEData    &d,
                                                   const Trial     &tr,
                                                   double          &H1,
                                                   MatK            *T)
      {
        for (unsigned int a = 0; a < K; ++a)
          y[a] = tr.sigma[a];
        if (track_eps_zz)
          y[i_eps_zz] += tr.eta0 * (-c.nu / c.E * (y[0] - d.sigma0[0] + y[1] - d.sigma0[1]));
        H1 = H1_of(c, tr.q, tr.sigma_y);
        if (T)
          for (unsigned int a = 0; a < K; ++a)
            for (unsigned int b = 0; b < K; ++b)
              (*T)[a][b] = D_entry(c, a, b) / tr.eta0;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) unsigned int
      Law<S, kinematic, degrading>::solve(const Constants &c,
                                          BEData          &d,
                                          const Trial     &tr,
                                          VecM            &x,
                                          VecM            &R,
                                          Iterate         &it)
      {
        const VecK   De         = d.De;
        unsigned int iterations = 0;
        guess(c, d, x);
        if (newton(c, d, x, R, it, c.max_iterations, iterations))
          return iterations;
        VecM   x_done = x;
        bool   have   = false;
        double s_done = 0, ds = 0.25;
        while (s_done < 1)
          {
            if (ds < 1e-6 || iterations > 20 * c.max_iterations)
              {
                std::ostringstream m;
                m << "Bouc-Wen (backward Euler): the local Newton iteration did not "
                     "converge (tolerance "
                  << c.tol << ", trial q/sigma_y = " << tr.q / tr.sigma_y
                  << ", continuation stalled at " << s_done << " of the increment after "
                  << iterations
                  << " iterations). Reduce the strain increment or raise "
                     "Material/Bouc-Wen/Tolerance.";
                throw RuntimeError(m.str());
              }
            const double s_try = std::min(1.0, s_done + ds);
            for (unsigned int a = 0; a < K; ++a)
              d.De[a] = s_try * De[a];
            if (have)
              x = x_done;
            else
              guess(c, d, x);
            if (newton(c, d, x, R, it, c.max_iterations, iterations))
              {
                s_done = s_try;
                x_done = x;
                have   = true;
                ds *= 2;
              }
            else
              ds *= 0.25;
          }
        x = x_done;
        evaluate(c, d, x, R, nullptr, it);
        return iterations;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::store_solution(const Constants &c,
                                                   VecN            &y,
                                                   const BEData    &d,
                                                   const VecM      &x,
                                                   const Iterate   &it,
                                                   double          &H1,
                                                   double          &H2)
      {
        const double dl = it.dlambda;
        for (unsigned int a = 0; a < K; ++a)
          y[a] = x[a];
        for (unsigned int f = 0; f < F; ++f)
          y[i_epsp + f] += dl * it.n[f];
        y[i_eps_ps] += std::abs(dl);
        if (degrading)
          y[i_e_h] = x[i_eh];
        if (track_eps_zz)
          y[i_eps_zz] +=
            it.eta1 * (-c.nu / c.E * (y[0] - d.sigma0[0] + y[1] - d.sigma0[1]) + dl * it.n[2]);
        H1 = H1_of(c, std::max(it.q1, 0.0), it.sigma_y1);
        H2 = it.H2;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::consistent_tangent(const Constants &c,
                                                       const BEData    &d,
                                                       const VecM      &x,
                                                       VecM            &R,
                                                       Iterate         &it,
                                                       MatK            &T)
      {
        // Implicit function theorem: d x / d deps = -J^-1 dR/d deps (scaled).
        std::array<unsigned int, M> pivot;
        MatM                        J;
        evaluate(c, d, x, R, &J, it);
        scale_jacobian(c, J);
        if (!lu_factorize<M>(J, pivot))
          throw RuntimeError("Bouc-Wen (backward Euler): singular local Jacobian");
        VecK dc_de; // d c / d deps = nu1 H2 lambda1 D n / eta1
        for (unsigned int b = 0; b < K; ++b)
          dc_de[b] = it.nu1 * it.H2 * it.lambda1 * it.Dn[b] / it.eta1;
        for (unsigned int b = 0; b < K; ++b)
          {
            VecM col{};
            for (unsigned int a = 0; a < K; ++a)
              col[a] = -D_entry(c, a, b) / it.eta1;
            if (!degrading)
              {
                const double ddl = it.wn * dc_de[b];
                for (unsigned int a = 0; a < K; ++a)
                  col[a] += it.Dn[a] * ddl;
                col[i_w] = it.gw * ddl;
              }
            else
              col[i_dl] = -it.wn * dc_de[b];
            for (unsigned int i = 0; i < M; ++i)
              col[i] = -col[i] * inverse_scale(c, i);
            lu_solve<M>(J, pivot, col.data());
            for (unsigned int a = 0; a < K; ++a)
              T[a][b] = col[a] * c.sigma_y0;
          }
      }



      template <StressState S, bool kinematic, bool degrading>
      inline unsigned int
      Law<S, kinematic, degrading>::backward_euler(const Constants &c,
                                                   VecN            &y,
                                                   const VecK      &deps,
                                                   double          &H1,
                                                   double          &H2,
                                                   MatK            *T)
      {
        BEData      d;
        const Trial tr = begin_increment(c, y, deps, d);
        H2             = d.H2;
        if (tr.q == 0 || d.H2 == 0 || tr.nDe == 0)
          {
            // Exactly elastic: lambda' = 0 (H1 = 0, or H2 = 0, or n:D:deps = 0).
            elastic_update(c, y, d, tr, H1, T);
            return 0;
          }

        if constexpr (S != StressState::plane_stress && !degrading)
          if (tr.nDe > 0)
            return radial_return(c, y, d, tr.sigma, tr.q, tr.n, tr.nDe, tr.sigma_y, H1, T);

        // Newton from the trial-based guess for the whole increment; if it fails,
        // continuation in the increment: solve the backward Euler problem for
        // s deps, s = ds, 2 ds, ... -> 1, each from the previous solution. The result
        // is the backward Euler solution of the whole increment in either case.
        VecM               x, R;
        Iterate            it;
        const unsigned int iterations = solve(c, d, tr, x, R, it);
        store_solution(c, y, d, x, it, H1, H2);
        if (T)
          consistent_tangent(c, d, x, R, it, *T);
        return iterations;
      }

    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif
