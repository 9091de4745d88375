#ifndef hysteron_source_material_bouc_wen_radial_return_h
#define hysteron_source_material_bouc_wen_radial_return_h

// Backward Euler of the Bouc-Wen point kernels in 3D and plane strain without degradation
// while loading: the radial return, one scalar Newton equation in w and its consistent
// tangent (BoucWenKernels::Law::radial_return(), declared and derived in
// bouc_wen_kernels.h, which includes this file at its end).

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
      template <StressState S, bool kinematic, bool degrading>
      inline unsigned int
      Law<S, kinematic, degrading>::radial_return(const Constants &c,
                    VecN            &y,
                    const BEData    &d,
                    const VecK      &sigma_tr,
                    const double     q_tr,
                    const VecK      &n_tr,
                    const double     nDe_tr,
                    const double     sigma_y,
                    double          &H1,
                    MatK            *T)
      {
        const double mu      = 0.5 * c.two_mu;
        const double b       = 3.0 * mu + c.kin_q;
        const double lambda1 = 1.0 / (c.H + 3.0 * mu);
        const double cc      = d.H2 * lambda1 * nDe_tr;
        double       w       = std::min(1.0, q_tr / sigma_y);
        double       wn = power(c, w), g = 0, dg = -1;
        unsigned int iterations = 0;
        while (true)
          {
            g  = q_tr - b * cc * wn - w * (sigma_y + c.iso * cc * wn);
            dg = -c.n * (b * cc + c.iso * cc * w) * wn / w - sigma_y - c.iso * cc * wn;
            if (std::abs(g) * c.inv_sigma_y0 <= c.tol)
              break;
            if (iterations == c.max_iterations || !std::isfinite(g))
              {
                std::ostringstream m;
                m << "Bouc-Wen (backward Euler): the radial-return Newton iteration did not "
                     "converge in "
                  << iterations << " iterations (scaled residual " << std::abs(g) / c.sigma_y0
                  << ", tolerance " << c.tol << ", trial q/sigma_y = " << q_tr / sigma_y
                  << "). Reduce the strain increment or raise Material/Bouc-Wen/Tolerance.";
                throw RuntimeError(m.str());
              }
            ++iterations;
            const double w_new = w - g / dg;
            w                  = w_new > 0 ? w_new : 0.5 * w; // safeguard (n < 1)
            wn                 = power(c, w);
          }
        const double dl = cc * wn;
        for (unsigned int a = 0; a < K; ++a)
          y[a] = sigma_tr[a] - c.two_mu * dl * n_tr[a];
        for (unsigned int f = 0; f < F; ++f)
          y[i_epsp + f] += dl * n_tr[f];
        y[i_eps_ps] += dl;
        H1 = H1_of(c, std::max(q_tr - b * dl, 0.0), sigma_y + c.iso * dl);

        if (T)
          {
            // N D deps = 3/(2 q) (dev(De) - 2/3 n (n : De)); N is symmetric.
            VecK         NDe;
            const double p = (d.De[0] + d.De[1] + d.De[2]) / 3.0;
            for (unsigned int a = 0; a < K; ++a)
              NDe[a] = 1.5 / q_tr * (d.De[a] - (a < 3 ? p : 0.0) - 2.0 / 3.0 * n_tr[a] * nDe_tr);
            const double dg_dc = -b * wn - c.iso * w * wn;
            VecK         ddl;
            for (unsigned int a = 0; a < K; ++a)
              {
                const double dc = d.H2 * lambda1 * c.two_mu * (n_tr[a] + NDe[a]);
                const double dw = -(c.two_mu * n_tr[a] + dg_dc * dc) / dg;
                ddl[a]          = wn * dc + cc * c.n * wn / w * dw;
              }
            const double f = 1.5 / q_tr * c.two_mu * c.two_mu * dl;
            for (unsigned int a = 0; a < K; ++a)
              for (unsigned int e = 0; e < K; ++e)
                {
                  const double pdev = (a == e ? 1.0 : 0.0) - (a < 3 && e < 3 ? 1.0 / 3.0 : 0.0);
                  (*T)[a][e]        = D_entry(c, a, e) - c.two_mu * n_tr[a] * ddl[e] -
                               f * (pdev - 2.0 / 3.0 * n_tr[a] * n_tr[e]);
                }
          }
        return iterations;
      }
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif
