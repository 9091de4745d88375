#include <hysteron/base/exceptions.h>
#include <hysteron/material/bogacki_shampine.h>
#include <hysteron/material/bouc_wen_interaction.h>
#include <hysteron/material/integer_power.h>

#include "bouc_wen_kernel_helpers.h"
#include "material/safeguarded_newton.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <utility>
#include <stdexcept>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      // The sums run from the first term on, left to right: for N = 3 they are the
      // expressions x[0] * y[0] + x[1] * y[1] + x[2] * y[2] of the three-component law, to
      // the bit.

      template <std::size_t N>
      double
      dot(const std::array<double, N> &x, const std::array<double, N> &y)
      {
        double s = x[0] * y[0];
        for (std::size_t i = 1; i < N; ++i)
          s += x[i] * y[i];
        return s;
      }

      /// x^T C x for the diagonal C.
      template <std::size_t N>
      double
      weighted_square(const std::array<double, N> &c, const std::array<double, N> &x)
      {
        double s = c[0] * x[0] * x[0];
        for (std::size_t i = 1; i < N; ++i)
          s += c[i] * x[i] * x[i];
        return s;
      }

      template <int N>
      dealii::Tensor<2, N>
      identity()
      {
        dealii::Tensor<2, N> I;
        for (unsigned int i = 0; i < N; ++i)
          I[i][i] = 1;
        return I;
      }

      /**
       * X = J^(-1) B for N x N matrices, or false if J is singular. N = 3: deal.II's
       * closed-form inverse (cofactors over the determinant), the solve of the
       * three-component law, kept so that 2D results do not change; otherwise LU with
       * partial pivoting (BoucWenKernels::lu_factorize()), one solve per column of B.
       */
      template <int N>
      bool
      solve(const dealii::Tensor<2, N> &J, const dealii::Tensor<2, N> &B, dealii::Tensor<2, N> &X)
      {
        if constexpr (N == 3)
          {
            if (!(std::abs(dealii::determinant(J)) > 0))
              return false;
            X = dealii::invert(J) * B;
            return true;
          }
        else
          {
            std::array<double, N * N>    LU;
            std::array<unsigned int, N> pivot;
            for (unsigned int i = 0; i < N; ++i)
              for (unsigned int j = 0; j < N; ++j)
                LU[i * N + j] = J[i][j];
            if (!BoucWenKernels::lu_factorize<N>(LU, pivot))
              return false;
            for (unsigned int j = 0; j < N; ++j)
              {
                double column[N];
                for (unsigned int i = 0; i < N; ++i)
                  column[i] = B[i][j];
                BoucWenKernels::lu_solve<N>(LU, pivot, column);
                for (unsigned int i = 0; i < N; ++i)
                  {
                    if (!std::isfinite(column[i]))
                      return false;
                    X[i][j] = column[i];
                  }
              }
            return true;
          }
      }
    } // namespace



    template <unsigned int N>
    BoucWenInteraction<N>::BoucWenInteraction(const BoucWenParameters &parameters,
                                              const Vector            &stiffness,
                                              const Vector            &yield_values)
    {
      reinit(parameters, stiffness, yield_values);
    }



    template <unsigned int N>
    std::string
    BoucWenInteraction<N>::unsupported(const BoucWenParameters &parameters)
    {
      if (parameters.degradation())
        return "the coupled spring law has no stiffness degradation or strength deterioration "
               "(the uniaxial law's intrinsic time and energy scale belong to one spring; the "
               "facet's plastic deformation (m, m, rad) has no unique norm): set c_eta = c_nu = 0 "
               "or use the uncoupled springs";
      return "";
    }



    template <unsigned int N>
    void
    BoucWenInteraction<N>::reinit(const BoucWenParameters &parameters,
                                  const Vector            &stiffness,
                                  const Vector            &yield_values)
    {
      const std::string why = unsupported(parameters);
      if (!why.empty())
        throw std::invalid_argument("BoucWenInteraction: " + why);
      for (unsigned int i = 0; i < N; ++i)
        if (!(stiffness[i] > 0) || !(yield_values[i] > 0) || !std::isfinite(stiffness[i]) ||
            !std::isfinite(yield_values[i]))
          throw std::invalid_argument("BoucWenInteraction: the stiffnesses and the yield values "
                                      "must be positive and finite");
      prm       = parameters;
      k         = stiffness;
      a         = parameters.post_yield_ratio;
      n         = parameters.smoothness;
      n_integer = (n >= 1 && n <= 64 && n == std::floor(n)) ? static_cast<unsigned int>(n) : 0;
      beta      = parameters.beta;
      gamma     = parameters.gamma;
      tolerance = parameters.tolerance;
      phi_saturation = std::pow(beta + gamma, -1 / n);
      // c_i = 1 / (F^h_y,i z_y,i) = 1 / ((1 - a) k_i z_y,i^2), relative to the largest.
      double c_max = 0;
      for (unsigned int i = 0; i < N; ++i)
        {
          z_y[i]     = yield_values[i] / k[i];
          inv_z_y[i] = 1 / z_y[i];
          c[i]       = 1 / (k[i] * z_y[i] * z_y[i]);
          c_max      = std::max(c_max, c[i]);
        }
      for (unsigned int i = 0; i < N; ++i)
        c[i] /= c_max;
    }



    template <unsigned int N>
    double
    BoucWenInteraction<N>::h1_of_squared(const double phi2) const
    {
      if (n_integer > 0 && n_integer % 2 == 0)
        return integer_power(phi2, n_integer / 2);
      if (n_integer > 0)
        return integer_power(std::sqrt(phi2), n_integer);
      return std::pow(phi2, 0.5 * n);
    }



    template <unsigned int N>
    double
    BoucWenInteraction<N>::yield_function(const double *z, const unsigned int stride) const
    {
      double phi2 = 0;
      for (unsigned int i = 0; i < N; ++i)
        phi2 += (z[i * stride] * inv_z_y[i]) * (z[i * stride] * inv_z_y[i]);
      return std::sqrt(phi2);
    }



    template <unsigned int N>
    double
    BoucWenInteraction<N>::h1(const double *z, const unsigned int stride) const
    {
      const double phi = yield_function(z, stride);
      return h1_of_squared(phi * phi);
    }



    template <unsigned int N>
    typename BoucWenInteraction<N>::Vector
    BoucWenInteraction<N>::forces(const Vector      &delta,
                                  const double      *z,
                                  const unsigned int stride) const
    {
      Vector F;
      for (unsigned int i = 0; i < N; ++i)
        F[i] = a * k[i] * delta[i] + (1 - a) * k[i] * z[i * stride];
      return F;
    }



    template <unsigned int N>
    typename BoucWenInteraction<N>::Vector
    BoucWenInteraction<N>::rates_w(const Vector &w, const Vector &d) const
    {
      // w' = d - H1 H2 (C w)(w . d) / (w^T C w)
      const double phi2 = dot(w, w);
      if (!(phi2 > 0))
        return d;
      const double P  = dot(w, d);
      const double H2 = P > 0 ? beta + gamma : (P < 0 ? beta - gamma : beta);
      const double f  = h1_of_squared(phi2) * H2 * P / weighted_square(c, w);
      Vector       r;
      for (unsigned int i = 0; i < N; ++i)
        r[i] = d[i] - f * c[i] * w[i];
      return r;
    }



    template <unsigned int N>
    typename BoucWenInteraction<N>::Matrix
    BoucWenInteraction<N>::tangent_w(const Vector &w, const Vector &d) const
    {
      // I - H1 H2 (C w) w^T / (w^T C w)
      Matrix       T;
      const double phi2 = dot(w, w);
      const double P    = dot(w, d);
      const double H2   = P > 0 ? beta + gamma : (P < 0 ? beta - gamma : beta);
      const double f    = phi2 > 0 ? h1_of_squared(phi2) * H2 / weighted_square(c, w) : 0.0;
      for (unsigned int i = 0; i < N; ++i)
        for (unsigned int j = 0; j < N; ++j)
          T[i][j] = (i == j ? 1.0 : 0.0) - f * c[i] * w[i] * w[j];
      return T;
    }



    template <unsigned int N>
    void
    BoucWenInteraction<N>::rates(const double      *z,
                                 const Vector      &delta_rate,
                                 double            *z_rate,
                                 const unsigned int stride) const
    {
      Vector w, d;
      for (unsigned int i = 0; i < N; ++i)
        {
          w[i] = z[i * stride] * inv_z_y[i];
          d[i] = delta_rate[i] * inv_z_y[i];
        }
      const Vector f = rates_w(w, d);
      for (unsigned int i = 0; i < N; ++i)
        z_rate[i * stride] = f[i] * z_y[i];
    }



    template <unsigned int N>
    typename BoucWenInteraction<N>::Matrix
    BoucWenInteraction<N>::continuum_tangent(const double      *z,
                                             const Vector      &delta_rate,
                                             const unsigned int stride) const
    {
      Vector w, d;
      for (unsigned int i = 0; i < N; ++i)
        {
          w[i] = z[i * stride] * inv_z_y[i];
          d[i] = delta_rate[i] * inv_z_y[i];
        }
      const Matrix T = tangent_w(w, d);
      Matrix       D;
      for (unsigned int i = 0; i < N; ++i)
        for (unsigned int j = 0; j < N; ++j)
          D[i][j] = (i == j ? a * k[i] : 0.0) + (1 - a) * k[i] * z_y[i] * T[i][j] * inv_z_y[j];
      return D;
    }



    template <unsigned int N>
    typename BoucWenInteraction<N>::Reduced
    BoucWenInteraction<N>::reduced(const Vector &w_tr,
                                   const Vector &d,
                                   const double  s,
                                   const double  H2,
                                   const double  nu) const
    {
      const double mu = s * nu;
      Reduced      v;
      Vector       dw; // dw/dmu
      for (unsigned int i = 0; i < N; ++i)
        {
          const double f = 1 / (1 + mu * c[i]);
          v.w[i]         = w_tr[i] * f;
          dw[i]          = -c[i] * v.w[i] * f;
        }
      v.phi2             = dot(v.w, v.w);
      v.h1               = h1_of_squared(v.phi2);
      v.P                = dot(v.w, d);
      v.A                = weighted_square(c, v.w);
      const double dphi2 = 2 * dot(v.w, dw);
      const double dP    = dot(dw, d);
      double       dA    = 0;
      for (unsigned int i = 0; i < N; ++i)
        dA += 2 * c[i] * v.w[i] * dw[i];
      const double q  = v.h1 * v.P / v.A;
      const double dq = 0.5 * n * v.h1 * dphi2 / v.phi2 * v.P / v.A +
                        v.h1 * (dP * v.A - v.P * dA) / (v.A * v.A);
      v.G  = s * (mu - H2 * q);
      v.dG = 1 - H2 * dq;
      return v;
    }



    template <unsigned int N>
    void
    BoucWenInteraction<N>::implicit_tangent(const Vector  &d,
                                            const Reduced &v,
                                            const double   H2,
                                            Matrix        &dw_dd) const
    {
      // r(w, d) = w - w0 - d + H2 q C w, q = H1 (w . d) / (w^T C w), H1 = Phi^n:
      //   dq/dw_j = H1 (n P / Phi^2 w_j + d_j - 2 P c_j w_j / A) / A,  dq/dd_j = H1 w_j / A,
      //   dr/dw = I + H2 (C w (x) dq/dw + q C),   dr/dd = -I + H2 C w (x) dq/dd.
      const Vector &w = v.w;
      const double  q = v.h1 * v.P / v.A;
      Matrix        J, R;
      for (unsigned int i = 0; i < N; ++i)
        for (unsigned int j = 0; j < N; ++j)
          {
            const double dq_dw =
              v.h1 * (n * v.P / v.phi2 * w[j] + d[j] - 2 * v.P * c[j] * w[j] / v.A) / v.A;
            const double dq_dd = v.h1 * w[j] / v.A;
            J[i][j] = (i == j ? 1 + H2 * q * c[i] : 0.0) + H2 * c[i] * w[i] * dq_dw;
            R[i][j] = (i == j ? -1.0 : 0.0) + H2 * c[i] * w[i] * dq_dd;
          }
      Matrix X;
      if (!solve<N>(J, R, X))
        fail("the local Jacobian is singular", w, d);
      dw_dd = -X;
    }



    template <unsigned int N>
    unsigned int
    BoucWenInteraction<N>::backward_euler(Vector &w, const Vector &d, Matrix *dw_dd) const
    {
      Vector w_tr;
      for (unsigned int i = 0; i < N; ++i)
        w_tr[i] = w[i] + d[i];
      const double P_tr = dot(w_tr, d);
      const double s    = P_tr > 0 ? 1.0 : -1.0;
      const double H2   = beta + gamma * s;
      if (P_tr == 0 || H2 == 0)
        {
          // Exactly elastic: the flow term vanishes (w . d = 0, or H2 = 0 while unloading).
          w = w_tr;
          if (dw_dd)
            *dw_dd = identity<N>();
          return 0;
        }

      // The reduced equation in nu = s mu >= 0: G(nu) = s g(s nu) < 0 at nu = 0, and G > 0
      // on the far side of the root.
      const auto evaluate = [&](const double nu) { return reduced(w_tr, d, s, H2, nu); };

      // The bracket [lo, hi], G(lo) < 0 <= G(hi). Loading: G -> +infinity as nu grows.
      // Unloading: nu < 1 (the pole of w at mu = -1 / max c_i = -1).
      const double nu_max = s > 0 ? std::numeric_limits<double>::infinity() : 1.0;
      double       lo = 0, hi = 0;
      Reduced      v   = evaluate(0);
      // The explicit estimate of the root: nu ~ H2 Phi_tr^n |w_tr . d| / (w_tr^T C w_tr).
      // (capped where Phi_tr^n overflows or the estimate is far beyond the radial return,
      // nu = (Phi_tr - 1) / min c_i, which reaches Phi <= 1).
      const double c_min = *std::min_element(c.begin(), c.end());
      double       step  = H2 * v.h1 * std::abs(v.P) / v.A;
      const double cap   = (1 + std::sqrt(v.phi2)) / c_min;
      step               = std::max(std::isfinite(step) ? std::min(step, cap) : cap, tolerance);
      for (unsigned int e = 0;; ++e)
        {
          double next = lo + step;
          if (next >= nu_max)
            next = 0.5 * (lo + nu_max);
          const Reduced trial = evaluate(next);
          if (std::isnan(trial.G) || e == 200)
            fail("found no bracket of the root", w, d);
          if (trial.G >= 0)
            {
              hi = next;
              v  = trial;
              break;
            }
          lo = next;
          step *= 2;
        }

      // Safeguarded Newton from hi (G >= 0), bisection where Newton leaves the bracket;
      // |r| = |g| |C w| <= |g| Phi: both the step and the residual below the tolerance.
      double             nu         = hi;
      const unsigned int iterations = safeguarded_newton(
        nu, lo, v, evaluate, [](const Reduced &r) { return std::make_pair(r.G, r.dG); },
        [&](const double x) { return tolerance * (1 + x); },
        [](const double h) { return 4 * std::numeric_limits<double>::epsilon() * (1 + h); }, max_iterations,
        [&](const char *what, double, const Reduced &r) { fail(what, r.w, d); });
      w = v.w;

      if (dw_dd)
        implicit_tangent(d, v, H2, *dw_dd);
      return iterations;
    }



    template <unsigned int N>
    unsigned int
    BoucWenInteraction<N>::update(const Vector      &ddelta,
                                  Vector            &force,
                                  double            *z,
                                  Matrix            *tangent,
                                  const unsigned int stride) const
    {
      Vector w0, d;
      for (unsigned int i = 0; i < N; ++i)
        {
          w0[i] = z[i * stride] * inv_z_y[i];
          d[i]  = ddelta[i] * inv_z_y[i];
        }
      // (After the loop, so that the message shows every component.)
      for (unsigned int i = 0; i < N; ++i)
        if (!std::isfinite(d[i]))
          fail("the increment is not finite", w0, d);
      Vector       w    = w0;
      Matrix       T    = identity<N>();
      unsigned int work = 1;
      if (std::all_of(d.begin(), d.end(), [](const double x) { return x == 0; }))
        {
          if (tangent)
            T = tangent_w(w, d);
          work = 0;
        }
      else
        switch (prm.integrator)
          {
            case BoucWenIntegrator::forward_euler:
              {
                if (tangent)
                  T = tangent_w(w, d);
                const Vector f = rates_w(w, d);
                for (unsigned int i = 0; i < N; ++i)
                  w[i] += f[i];
                break;
              }
            case BoucWenIntegrator::adaptive:
              {
                Vector inv_scale;
                inv_scale.fill(1 / tolerance);
                work = bogacki_shampine_32(
                  w,
                  inv_scale,
                  max_substeps,
                  [&](const Vector &x) { return rates_w(x, d); },
                  // lambda = n |plastic rate| / Phi, the plastic rate d - w'.
                  [&](const Vector &x, const Vector &f) {
                    const double phi2 = dot(x, x);
                    if (!(phi2 > 0))
                      return 0.0;
                    Vector p;
                    for (unsigned int i = 0; i < N; ++i)
                      p[i] = d[i] - f[i];
                    return n * std::sqrt(dot(p, p) / phi2);
                  },
                  [&](Vector &x) {
                    // Back into the invariant ball Phi <= Phi_s (radial = closest point).
                    const double phi = std::sqrt(dot(x, x));
                    if (!(phi > phi_saturation))
                      return false;
                    for (unsigned int i = 0; i < N; ++i)
                      x[i] *= phi_saturation / phi;
                    return true;
                  },
                  [&]() {
                    std::ostringstream m;
                    m << "the adaptive integrator needed more than " << max_substeps
                      << " sub-steps (tolerance " << tolerance
                      << "): reduce the increments or raise the Tolerance";
                    fail(m.str(), w, d);
                  });
                if (tangent)
                  T = tangent_w(w, d);
                break;
              }
            case BoucWenIntegrator::backward_euler:
              work = backward_euler(w, d, tangent ? &T : nullptr);
              break;
          }

      for (unsigned int i = 0; i < N; ++i)
        {
          const double z0 = z[i * stride], z1 = w[i] * z_y[i];
          z[i * stride]   = z1;
          force[i] += a * k[i] * ddelta[i] + (1 - a) * k[i] * (z1 - z0);
        }
      if (tangent)
        for (unsigned int i = 0; i < N; ++i)
          for (unsigned int j = 0; j < N; ++j)
            (*tangent)[i][j] =
              (i == j ? a * k[i] : 0.0) + (1 - a) * k[i] * z_y[i] * T[i][j] * inv_z_y[j];
      return work;
    }



    template <unsigned int N>
    void
    BoucWenInteraction<N>::fail(const std::string &what, const Vector &w, const Vector &d) const
    {
      std::ostringstream m;
      m << "Bouc-Wen (coupled springs, "
        << (prm.integrator == BoucWenIntegrator::forward_euler ? "forward euler" :
            prm.integrator == BoucWenIntegrator::adaptive      ? "adaptive" :
                                                                 "backward euler")
        << "): " << what << " (z/z_y = ";
      for (unsigned int i = 0; i < N; ++i)
        m << (i > 0 ? ", " : "") << w[i];
      m << "; increment/z_y = ";
      for (unsigned int i = 0; i < N; ++i)
        m << (i > 0 ? ", " : "") << d[i];
      m << ")";
      throw RuntimeError(m.str());
    }



    template class BoucWenInteraction<3>;
    template class BoucWenInteraction<6>;
  } // namespace Material
} // namespace hysteron
