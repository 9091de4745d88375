#ifndef hysteron_source_material_bouc_wen_rates_h
#define hysteron_source_material_bouc_wen_rates_h

// The rate functions of the Bouc-Wen point kernels: the isotropic stiffness D, the
// relative deviator, eta and H1, rates() with the flow direction and lambda1, the continuum
// tangent, and the q^2 form of the stages of the adaptive integrator (stage_rates(),
// deviator()): members of BoucWenKernels::Law declared in bouc_wen_kernels.h, which
// includes this file at its end, with the equations documented there.

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::apply_D(const Constants &c, const double *v, double *out)
      {
        double tr = 0;
        for (unsigned int a = 0; a < n_nor; ++a)
          tr += v[a];
        for (unsigned int a = 0; a < K; ++a)
          out[a] = c.two_mu * v[a] + (a < n_nor ? c.lambda_eff * tr : 0.0);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::D_entry(const Constants &c, const unsigned int a, const unsigned int b)
      {
        return (a == b ? c.two_mu : 0.0) + (a < n_nor && b < n_nor ? c.lambda_eff : 0.0);
      }



      template <StressState S, bool kinematic, bool degrading>
      template <unsigned int L>
      inline double
      Law<S, kinematic, degrading>::dot(const double *a, const double *b)
      {
        double s = 0;
        for (unsigned int i = 0; i < L; ++i)
          s += a[i] * b[i];
        return s;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::relative_deviator(const double *sigma, const double *alpha, VecF &dev)
      {
        VecF xi{};
        for (unsigned int a = 0; a < K; ++a)
          xi[G::full[a]] = sigma[a];
        if (alpha)
          for (unsigned int f = 0; f < F; ++f)
            xi[f] -= alpha[f];
        const double p = (xi[0] + xi[1] + xi[2]) / 3.0;
        dev            = xi;
        dev[0] -= p;
        dev[1] -= p;
        dev[2] -= p;
        return std::sqrt(1.5 * dot<F>(dev.data(), dev.data()));
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::eta_of(const Constants &c, const double eps_ps)
      {
        if (!degrading || c.c_eta == 0)
          return 1.0;
        return std::pow(1.0 + c.c_eta * eps_ps / c.inv_m_u1, c.inv_m_u1);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::H1_of(const Constants &c, const double q, const double sigma_y)
      {
        return q > 0 ? power(c, q / sigma_y) : 0.0;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::continuum_tangent(const Constants &c, const Rates &r, MatK &T)
      {
        const double f = r.nu * r.H1 * r.H2 * r.lambda1;
        for (unsigned int a = 0; a < K; ++a)
          for (unsigned int b = 0; b < K; ++b)
            T[a][b] = (D_entry(c, a, b) - f * r.Dn[a] * r.Dn[b]) / r.eta;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline double
      Law<S, kinematic, degrading>::H1_at(const Constants &c, const double *y)
      {
        VecF alpha, dev;
        if (kinematic)
          for (unsigned int f = 0; f < F; ++f)
            alpha[f] = c.kin * y[i_epsp + f];
        const double q = relative_deviator(y, kinematic ? alpha.data() : nullptr, dev);
        return H1_of(c, q, c.sigma_y0 + c.iso * y[i_eps_ps]);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline void
      Law<S, kinematic, degrading>::rates(const Constants &c, const double *y, const VecK &De, double *dy, Rates &r)
      {
        VecF alpha;
        if (kinematic)
          for (unsigned int f = 0; f < F; ++f)
            alpha[f] = c.kin * y[i_epsp + f];
        VecF dev;
        r.q       = relative_deviator(y, kinematic ? alpha.data() : nullptr, dev);
        r.sigma_y = c.sigma_y0 + c.iso * y[i_eps_ps];
        if (degrading)
          {
            r.eta = eta_of(c, y[i_eps_ps]);
            r.nu  = 1.0 + c.c_nu_scaled * y[i_e_h];
          }
        double lambda_rate = 0;
        if (r.q > 0)
          {
            const double inv_q = 1.5 / r.q;
            for (unsigned int f = 0; f < F; ++f)
              r.n[f] = inv_q * dev[f];
            VecK n_K;
            for (unsigned int a = 0; a < K; ++a)
              n_K[a] = r.n[G::full[a]];
            apply_D(c, n_K.data(), r.Dn.data());
            const double nDn = dot<K>(n_K.data(), r.Dn.data());
            const double nDe = dot<K>(n_K.data(), De.data());
            r.H1             = H1_of(c, r.q, r.sigma_y);
            r.H2             = c.beta + c.gamma * sign(nDe);
            r.lambda1        = 1.0 / (c.H + nDn);
            lambda_rate      = r.nu * r.H1 * r.H2 * r.lambda1 * nDe / r.eta;
          }
        else
          {
            r.n.fill(0.0);
            r.Dn.fill(0.0);
            r.H1      = 0;
            r.H2      = c.beta;
            r.lambda1 = 0;
          }
        const double inv_eta = 1.0 / r.eta;
        for (unsigned int a = 0; a < K; ++a)
          dy[a] = De[a] * inv_eta - lambda_rate * r.Dn[a];
        for (unsigned int f = 0; f < F; ++f)
          dy[i_epsp + f] = lambda_rate * r.n[f];
        dy[i_eps_ps] = std::abs(lambda_rate);
        if (degrading)
          {
            double sn = 0;
            for (unsigned int a = 0; a < K; ++a)
              sn += y[a] * r.n[G::full[a]];
            dy[i_e_h] = lambda_rate * sn;
          }
        if (track_eps_zz)
          dy[i_eps_zz] = r.eta * (-c.nu / c.E * (dy[0] + dy[1]) + dy[i_epsp + 2]);
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) double
      Law<S, kinematic, degrading>::stage_rates(const Constants &c,
                                                const double    *y,
                                                const VecK      &De,
                                                double          *dy,
                                                Stage           *info)
      {
        Stage st;
        stage_begin(c, y, De, st);
        stage_end(c, y, De, st, dy);
        if (info)
          *info = st;
        return st.H1;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::stage_begin(const Constants &c, const double *y, const VecK &De, Stage &st)
      {
        constexpr bool radial = S != StressState::plane_stress && !degrading;
        // d and D d straight into st (a copy of local arrays was assembled on the
        // stack with scalar stores and read back as pairs: store-forwarding stalls).
        VecF        &d  = st.d;
        const double q2 = deviator(c, y, d);
        // D d and the products straight from d (no gathered copy of it).
        VecK  &Dd  = st.Dd;
        double dDd = 0, dDe = 0, tr = 0;
        for (unsigned int a = 0; a < n_nor; ++a)
          tr += d[G::full[a]];
        for (unsigned int a = 0; a < K; ++a)
          {
            const double da = d[G::full[a]];
            Dd[a]           = c.two_mu * da + (!radial && a < n_nor ? c.lambda_eff * tr : 0.0);
            dDd += da * Dd[a];
            dDe += da * De[a];
          }
        if (!radial)
          st.dDd = dDd;
        st.sigma_y = c.sigma_y0 + c.iso * y[i_eps_ps];
        if (degrading)
          {
            st.eta = eta_of(c, y[i_eps_ps]);
            st.nu  = 1.0 + c.c_nu_scaled * y[i_e_h];
          }
        st.dDe = dDe;
        st.H2  = c.beta + c.gamma * sign(dDe);
        st.q2  = q2;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) void
      Law<S, kinematic, degrading>::stage_end(const Constants &c, const double *y, const VecK &De, Stage &st, double *dy)
      {
        constexpr bool radial = S != StressState::plane_stress && !degrading;
        const double   q2 = st.q2, sigma_y = st.sigma_y, eta = st.eta, dDe = st.dDe;
        const double   q  = std::sqrt(q2);
        double         H1 = 0, g = 0;
        if (c.n_half != 0 && radial)
          {
            const double inv_sy2 = 1.0 / (sigma_y * sigma_y);
            double       t_m;
            H1 = power_pair(q2 * inv_sy2, c.n_half, t_m);
            g  = st.H2 * (t_m * inv_sy2) * dDe * c.radial_g; // d = 0: dDe = 0, g = 0
            st.inv_sy2 = inv_sy2;
          }
        else if (c.n_half != 0)
          {
            // One division for 1 / sigma_y^2 and 1 / den: inv = 1 / (sigma_y^2 den).
            const double den = q2 > 0 ? c.H * q2 + 2.25 * st.dDd : 1.0;
            const double sy2 = sigma_y * sigma_y;
            const double inv = 1.0 / (sy2 * den);
            st.inv_sy2       = den * inv;
            st.inv_den       = sy2 * inv;
            H1               = integer_power(q2 * st.inv_sy2, c.n_half);
            g = st.nu * H1 * st.H2 * 2.25 * dDe * st.inv_den / (degrading ? eta : 1.0);
          }
        else if (q2 > 0)
          {
            H1 = power(c, q / sigma_y);
            g  = radial ? st.H2 * (H1 / q2) * dDe * c.radial_g :
                          st.nu * H1 * st.H2 * 2.25 * dDe /
                           ((degrading ? eta : 1.0) * (c.H * q2 + 2.25 * st.dDd));
          }
        for (unsigned int a = 0; a < K; ++a)
          dy[a] = (degrading ? De[a] / eta : De[a]) - g * st.Dd[a];
        for (unsigned int f = 0; f < F; ++f)
          dy[i_epsp + f] = g * st.d[f];
        dy[i_eps_ps] = std::abs(g) * q * (2.0 / 3.0);
        if (degrading)
          {
            double sd = 0;
            for (unsigned int a = 0; a < K; ++a)
              sd += y[a] * st.d[G::full[a]];
            dy[i_e_h] = g * sd;
          }
        if (track_eps_zz)
          dy[i_eps_zz] = eta * (-c.nu / c.E * (dy[0] + dy[1]) + dy[i_epsp + 2]);
        st.q  = q;
        st.H1 = H1;
      }



      template <StressState S, bool kinematic, bool degrading>
      inline __attribute__((always_inline)) double
      Law<S, kinematic, degrading>::deviator(const Constants &c, const double *y, VecF &d)
      {
        VecF x;
        for (unsigned int f = 0; f < F; ++f)
          x[f] = kinematic ? -c.kin * y[i_epsp + f] : 0.0;
        for (unsigned int a = 0; a < K; ++a)
          x[G::full[a]] += y[a];
        const double p  = (x[0] + x[1] + x[2]) * (1.0 / 3.0);
        double       dd = 0;
        for (unsigned int f = 0; f < F; ++f)
          {
            const double v = x[f] - (f < 3 ? p : 0.0);
            d[f]           = v;
            dd += v * v;
          }
        return 1.5 * dd;
      }
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif
