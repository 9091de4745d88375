// Unit tests of the coupled Bouc-Wen springs (hysteron::Material::BoucWenInteraction<N>):
// reduction to the uniaxial law, saturation on the ellipse, consistency, the backward
// Euler tangent, convergence of the integrators and elastic unloading. The first part is the
// three-component law of the 2D facet (BoucWenInteraction<3>); the typed tests at the end
// (BoucWenInteractionN) repeat the properties for N = 3 and for the six springs of the 3D
// facet, N = 6.
#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_interaction.h>
#include <hysteron/material/bouc_wen_uniaxial.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace
{
  using hysteron::Material::BoucWenIntegrator;
  using BoucWenInteraction = hysteron::Material::BoucWenInteraction<3>;
  using hysteron::Material::BoucWenParameters;
  using hysteron::Material::BoucWenUniaxial;
  using Vector = BoucWenInteraction::Vector;
  using Matrix = BoucWenInteraction::Matrix;

  // A facet of the single-element scene (l = 0.5 m, t = 0.02 m, S235, plane stress):
  // k_n = E' t l / h, k_t = G t l / h, k_phi = k_n l^2 / 12; F_y,n = sigma_y t l,
  // F_y,t = F_y,n / sqrt(3), M_y = 0.25 sigma_y t l^2.
  constexpr double l = 0.5, t = 0.02, sigma_y = 235e6, E = 210e9, nu = 0.3;
  const Vector     k{{E / (1 - nu * nu) * t, E / (2 * (1 + nu)) * t, E / (1 - nu * nu) * t * l * l / 12}};
  const Vector     F_y{{sigma_y * t * l, sigma_y * t * l / std::sqrt(3.0), 0.25 * sigma_y * t * l * l}};
  const Vector     z_y{{F_y[0] / k[0], F_y[1] / k[1], F_y[2] / k[2]}};

  const std::array<BoucWenIntegrator, 3> all_integrators{{BoucWenIntegrator::forward_euler,
                                                          BoucWenIntegrator::adaptive,
                                                          BoucWenIntegrator::backward_euler}};

  const char *
  name(const BoucWenIntegrator integrator)
  {
    return integrator == BoucWenIntegrator::forward_euler ? "forward euler" :
           integrator == BoucWenIntegrator::adaptive      ? "adaptive" :
                                                            "backward euler";
  }

  BoucWenParameters
  parameters(const double            n,
             const BoucWenIntegrator integrator,
             const double            tolerance = 1e-6,
             const double            a         = 0.0,
             const double            beta      = 0.5)
  {
    BoucWenParameters p;
    p.post_yield_ratio = a;
    p.smoothness       = n;
    p.beta             = beta;
    p.gamma            = 1 - beta;
    p.integrator       = integrator;
    p.tolerance        = tolerance;
    return p;
  }

  double
  phi_of(const Vector &z)
  {
    double s = 0;
    for (unsigned int i = 0; i < 3; ++i)
      s += (z[i] / z_y[i]) * (z[i] / z_y[i]);
    return std::sqrt(s);
  }

  /// A path of deformations: delta(s_j) for s_j = j / n_steps.
  template <typename Path>
  std::vector<Vector>
  sample(const Path &path, const unsigned int n_steps)
  {
    std::vector<Vector> deltas(n_steps + 1);
    for (unsigned int j = 0; j <= n_steps; ++j)
      deltas[j] = path(double(j) / n_steps);
    return deltas;
  }

  struct Response
  {
    std::vector<Vector> z, F;
    unsigned long       work = 0;
  };

  Response
  drive(const BoucWenInteraction &law, const std::vector<Vector> &deltas)
  {
    Response r;
    Vector   z{}, F{};
    law.initialize_state(z.data());
    F = law.forces(deltas[0], z.data());
    r.z.push_back(z);
    r.F.push_back(F);
    for (std::size_t j = 1; j < deltas.size(); ++j)
      {
        Vector dd;
        for (unsigned int i = 0; i < 3; ++i)
          dd[i] = deltas[j][i] - deltas[j - 1][i];
        r.work += law.update(dd, F, z.data(), nullptr);
        r.z.push_back(z);
        r.F.push_back(F);
      }
    return r;
  }

  /// max over the path and the components of |z_i - z_ref,i| / z_y,i.
  double
  path_error(const Response &r, const Response &reference, const unsigned int every)
  {
    double e = 0;
    for (std::size_t j = 0; j < r.z.size(); ++j)
      for (unsigned int i = 0; i < 3; ++i)
        e = std::max(e, std::abs(r.z[j][i] - reference.z[j * every][i]) / z_y[i]);
    return e;
  }

  /// A smooth cyclic curve through all three components (several reversals, 6 z_y).
  Vector
  cyclic(const double s)
  {
    const double x = 2 * M_PI * s;
    return {{6 * z_y[0] * std::sin(x),
             4 * z_y[1] * std::sin(2 * x + 1),
             5 * z_y[2] * std::sin(x + 2) * std::cos(0.5 * x)}};
  }

  /// The polygon through 40 points of cyclic(), each side cut into @p m equal increments.
  /// (The law is path dependent: convergence in the increment needs one fixed path.)
  std::vector<Vector>
  polygon(const unsigned int m)
  {
    constexpr unsigned int n_sides = 40;
    std::vector<Vector>    deltas;
    for (unsigned int side = 0; side < n_sides; ++side)
      {
        const Vector p = cyclic(double(side) / n_sides), q = cyclic(double(side + 1) / n_sides);
        for (unsigned int j = (side == 0 ? 0 : 1); j <= m; ++j)
          {
            Vector x;
            for (unsigned int i = 0; i < 3; ++i)
              x[i] = p[i] + (q[i] - p[i]) * j / m;
            deltas.push_back(x);
          }
      }
    return deltas;
  }
} // namespace



// One component alone: the uniaxial law with k_i and F_y,i, to round-off (the
// explicit integrators) or to the Newton tolerance (backward Euler: the two solve the
// same scalar equation with different unknowns), force, state and tangent; the other
// components stay exactly zero.
TEST(BoucWenInteraction, SingleComponentIsTheUniaxialLaw)
{
  for (const auto integrator : all_integrators)
    for (unsigned int i = 0; i < 3; ++i)
      for (const double beta : {0.5, 0.75})
        {
          const BoucWenParameters  p = parameters(8, integrator, 1e-12, 0.05, beta);
          const BoucWenInteraction coupled(p, k, F_y);
          const BoucWenUniaxial    uniaxial(p, k[i], F_y[i]);
          Vector                   z{}, F{};
          double                   z1[3] = {0, 1, 0}; // (the uniaxial state has 3 slots at most)
          double                   F1 = 0, worst = 0, worst_tangent = 0;
          double                   previous = 0;
          for (unsigned int j = 1; j <= 400; ++j)
            {
              // Two cycles of amplitude 4 z_y in increments up to 0.13 z_y.
              const double delta = 4 * z_y[i] * std::sin(4 * M_PI * j / 400.0);
              Vector       dd{};
              dd[i] = delta - previous;
              previous = delta;
              Matrix T;
              double T1 = 0;
              coupled.update(dd, F, z.data(), &T);
              uniaxial.update(dd[i], F1, z1, &T1);
              worst = std::max(worst, std::abs(F[i] - F1) / F_y[i]);
              worst = std::max(worst, std::abs(z[i] - z1[0]) / z_y[i]);
              worst_tangent = std::max(worst_tangent, std::abs(T[i][i] - T1) / k[i]);
              for (unsigned int m = 0; m < 3; ++m)
                {
                  if (m == i)
                    continue;
                  ASSERT_EQ(z[m], 0.0);
                  ASSERT_EQ(F[m], 0.0);
                  ASSERT_EQ(T[i][m], 0.0);
                  ASSERT_EQ(T[m][i], 0.0);
                }
            }
          const double bound = integrator == BoucWenIntegrator::backward_euler ? 1e-11 : 1e-13;
          EXPECT_LT(worst, bound) << name(integrator) << ", component " << i << ", beta " << beta;
          EXPECT_LT(worst_tangent, 1e3 * bound)
            << name(integrator) << ", component " << i << ", beta " << beta;
          if (i == 0 && beta == 0.5)
            std::cout << "  " << name(integrator) << ": max difference to the uniaxial law "
                      << worst << " (F / F_y, z / z_y), tangent " << worst_tangent << " k"
                      << std::endl;
        }
}



// Consistency: on the surface Phi = 1 with beta + gamma = 1 and loading (H1 H2 = 1),
// Phi' = w . w' / Phi = 0; inside the flow keeps the sign of (1 - H1 H2)(w . d').
TEST(BoucWenInteraction, FlowIsTangentToTheYieldSurface)
{
  const BoucWenInteraction law(parameters(8, BoucWenIntegrator::adaptive), k, F_y);
  double                   worst = 0;
  for (unsigned int m = 0; m < 50; ++m)
    {
      // Points on the unit sphere in w and loading directions.
      const double th = 0.37 * m, ph = 1.3 + 0.91 * m;
      const Vector w{{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)}};
      Vector       z, dd, rate;
      for (unsigned int i = 0; i < 3; ++i)
        {
          z[i]  = w[i] * z_y[i];
          dd[i] = (w[i] + std::sin(2.1 * m + i)) * z_y[i];
        }
      double wd = 0;
      for (unsigned int i = 0; i < 3; ++i)
        wd += w[i] * dd[i] / z_y[i];
      if (wd <= 0)
        for (unsigned int i = 0; i < 3; ++i)
          dd[i] = -dd[i];
      law.rates(z.data(), dd, rate.data());
      double phi_rate = 0, scale = 0;
      for (unsigned int i = 0; i < 3; ++i)
        {
          phi_rate += w[i] * rate[i] / z_y[i];
          scale += std::abs(dd[i] / z_y[i]);
        }
      worst = std::max(worst, std::abs(phi_rate) / scale);
      EXPECT_NEAR(law.yield_function(z.data()), 1.0, 1e-14);
      EXPECT_NEAR(law.h1(z.data()), 1.0, 1e-13);
    }
  std::cout << "  max |Phi'| / |d'| on the surface: " << worst << std::endl;
  EXPECT_LT(worst, 1e-14);

  // The continuum tangent is symmetric; at the surface its E-part annihilates E g.
  const Vector   z{{0.6 * z_y[0], 0.0, 0.8 * z_y[2]}};
  const Matrix   D = law.continuum_tangent(z.data(), Vector{{1, 0, 1}});
  for (unsigned int i = 0; i < 3; ++i)
    for (unsigned int j = 0; j < 3; ++j)
      EXPECT_NEAR(D[i][j], D[j][i], 1e-12 * k[0]);
  // a = 0: D = E - (E g)(E g)^T / (g^T E g), so D delta' is tangent to the ellipse for
  // every delta': g . (D delta') = 0 with g ~ F^h / F_y^2.
  for (const Vector dd : {Vector{{1e-4, 0, 0}}, Vector{{0, 1e-4, 0}}, Vector{{2e-4, 1e-4, -3e-3}}})
    {
      double gDd = 0, scale = 0;
      for (unsigned int i = 0; i < 3; ++i)
        {
          double Dd = 0;
          for (unsigned int j = 0; j < 3; ++j)
            Dd += D[i][j] * dd[j];
          gDd += (k[i] * z[i] / (F_y[i] * F_y[i])) * Dd;
          scale += std::abs(k[i] * dd[i] / F_y[i]);
        }
      EXPECT_LT(std::abs(gDd), 1e-13 * scale);
    }
}



// Proportional deformation in (delta_n, phi): the forces saturate on the ellipse
// (N / F_y)^2 + (M / M_y)^2 = 1 at the point whose normal is the deformation direction
// (associated flow: w ~ C^(-1) d). For delta_n / phi = M_y / F_y,n that is
// N = F_y / sqrt(2), M = M_y / sqrt(2): 1 / sqrt(2) of the uncoupled springs' N and M.
// The adaptive and backward Euler integrators never leave Phi <= 1 + tolerance, even for
// n = 100 and increments of 3 z_y.
TEST(BoucWenInteraction, ProportionalLoadingSaturatesOnTheEllipse)
{
  const double ratio = F_y[2] / F_y[0]; // delta_n / phi
  for (const auto integrator : all_integrators)
    for (const double n : {2.0, 8.0, 100.0})
      for (const double dx : {0.02, 0.5, 3.0})
        {
          if (integrator == BoucWenIntegrator::forward_euler && dx * n > 1)
            continue; // forward Euler: stable only for increments below ~2/n z_y
          const double             tolerance = 1e-8;
          const BoucWenInteraction law(parameters(n, integrator, tolerance), k, F_y);
          const double             phi_end = 30 * z_y[2];
          const unsigned int       steps   = std::lround(30 / dx);
          const auto               deltas  = sample(
            [&](const double s) { return Vector{{ratio * s * phi_end, 0, s * phi_end}}; }, steps);
          const Response r = drive(law, deltas);
          double         phi_max = 0;
          for (const auto &z : r.z)
            phi_max = std::max(phi_max, phi_of(z));
          const Vector &F = r.F.back();
          const double  phi_end_state = std::sqrt(std::pow(F[0] / F_y[0], 2) + std::pow(F[2] / F_y[2], 2));
          if (integrator != BoucWenIntegrator::forward_euler)
            {
              EXPECT_LE(phi_max, 1 + tolerance)
                << name(integrator) << ", n = " << n << ", dx = " << dx;
            }
          EXPECT_NEAR(phi_end_state, 1.0, integrator == BoucWenIntegrator::forward_euler ? 1e-3 : 1e-6)
            << name(integrator) << ", n = " << n << ", dx = " << dx;
          // The saturated point: N / F_y = M / M_y = 1 / sqrt(2).
          const double tol_point = integrator == BoucWenIntegrator::forward_euler ? 2e-3 : 1e-5;
          EXPECT_NEAR(F[0] / F_y[0], M_SQRT1_2, tol_point) << name(integrator) << ", n = " << n << ", dx = " << dx;
          EXPECT_NEAR(F[2] / F_y[2], M_SQRT1_2, tol_point) << name(integrator) << ", n = " << n << ", dx = " << dx;
          EXPECT_EQ(F[1], 0.0);
          if (n == 8 && dx == 0.02)
            std::cout << "  " << name(integrator) << ", n = 8: end N / F_y = " << F[0] / F_y[0]
                      << ", M / M_y = " << F[2] / F_y[2] << ", max Phi = " << phi_max << std::endl;
        }
}



// The consistent tangent of backward Euler agrees with central differences of the
// update, dF1 / d(Delta delta), to 1e-6 (relative to the largest entry): elastic range,
// transition, saturation, unloading (beta > gamma: not elastic), large increments, a
// reversal across w . d = 0 at the end, and a > 0.
TEST(BoucWenInteraction, BackwardEulerTangentMatchesFiniteDifferences)
{
  struct Case
  {
    double n, beta, a;
  };
  const std::vector<Case> cases = {{2, 0.5, 0}, {8, 0.5, 0.05}, {1.5, 0.75, 0.03}, {16, 0.6, 0.02}};
  // (w_n, Delta d) in units of z_y.
  const std::vector<std::pair<Vector, Vector>> points = {
    {{{0.1, 0.0, 0.05}}, {{0.05, 0.02, 0.01}}},
    {{{0.5, 0.3, -0.2}}, {{0.2, 0.1, -0.3}}},
    {{{0.7, 0.1, 0.69}}, {{0.5, -0.2, 0.6}}},
    {{{0.6, 0.5, 0.6}}, {{-0.3, -0.1, -0.2}}},
    {{{0.2, -0.3, 0.1}}, {{3.0, 1.0, -2.0}}},
    {{{0.8, 0.0, 0.55}}, {{-0.9, 0.4, 0.3}}}};
  double worst = 0;
  for (const auto &c : cases)
    for (const auto &point : points)
      {
        BoucWenParameters p = parameters(c.n, BoucWenIntegrator::backward_euler, 1e-13, c.a, c.beta);
        const BoucWenInteraction law(p, k, F_y);
        Vector                   z0, dd;
        for (unsigned int i = 0; i < 3; ++i)
          {
            z0[i] = point.first[i] * z_y[i];
            dd[i] = point.second[i] * z_y[i];
          }
        const auto force_after = [&](const Vector &increment, Matrix *T) {
          Vector z = z0, F{};
          law.update(increment, F, z.data(), T);
          return F;
        };
        Matrix T;
        force_after(dd, &T);
        Matrix fd;
        for (unsigned int j = 0; j < 3; ++j)
          {
            const double h  = 1e-6 * z_y[j];
            Vector       dp = dd, dm = dd;
            dp[j] += h;
            dm[j] -= h;
            const Vector Fp = force_after(dp, nullptr), Fm = force_after(dm, nullptr);
            for (unsigned int i = 0; i < 3; ++i)
              fd[i][j] = (Fp[i] - Fm[i]) / (2 * h);
          }
        // Entries in units of F_y,i / z_y,j (d(F_i / F_y,i) / d(delta_j / z_y,j): the
        // stiffnesses differ by orders of magnitude).
        double diff = 0, size = 0;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            {
              const double s = z_y[j] / F_y[i];
              diff = std::max(diff, std::abs(T[i][j] - fd[i][j]) * s);
              size = std::max(size, std::abs(fd[i][j]) * s);
            }
        worst = std::max(worst, diff / size);
        EXPECT_LT(diff / size, 1e-6) << "n = " << c.n << ", beta = " << c.beta << ", w_n = ("
                                     << point.first[0] << ", " << point.first[1] << ", "
                                     << point.first[2] << ")";
      }
  std::cout << "  worst relative difference tangent vs central differences: " << worst << std::endl;
}



// Forward Euler's tangent is the derivative of its own update, and its increment is
// rates(): z1 - z0 = (I - H1 H2 R) Delta delta at the start state.
TEST(BoucWenInteraction, ForwardEulerTangentAndRates)
{
  const BoucWenInteraction law(parameters(8, BoucWenIntegrator::forward_euler, 1e-6, 0.03), k, F_y);
  const Vector             z0{{0.6 * z_y[0], -0.3 * z_y[1], 0.7 * z_y[2]}};
  const Vector             dd{{0.05 * z_y[0], 0.02 * z_y[1], 0.04 * z_y[2]}};
  Vector                   z = z0, F{}, rate;
  Matrix                   T;
  law.update(dd, F, z.data(), &T);
  law.rates(z0.data(), dd, rate.data());
  for (unsigned int i = 0; i < 3; ++i)
    EXPECT_NEAR(z[i] - z0[i], rate[i], 1e-15 * z_y[i]);
  for (unsigned int j = 0; j < 3; ++j)
    {
      const double h  = 1e-7 * z_y[j];
      Vector       dp = dd, dm = dd, zp = z0, zm = z0, Fp{}, Fm{};
      dp[j] += h;
      dm[j] -= h;
      law.update(dp, Fp, zp.data(), nullptr);
      law.update(dm, Fm, zm.data(), nullptr);
      for (unsigned int i = 0; i < 3; ++i)
        EXPECT_NEAR(T[i][j], (Fp[i] - Fm[i]) / (2 * h), 1e-6 * F_y[i] / z_y[j]);
    }
}



// Convergence on a cyclic path through all three components, a polygon of 40 sides
// (reference: adaptive, tolerance 1e-12, 256 increments per side): the Euler schemes are
// first order, the adaptive integrator stays within a few tolerances over the whole path
// with one increment per side.
TEST(BoucWenInteraction, ConvergenceOnACyclicPath)
{
  const unsigned int       m_ref = 256;
  const BoucWenInteraction reference_law(parameters(4, BoucWenIntegrator::adaptive, 1e-12, 0.05, 0.6), k, F_y);
  const Response           reference = drive(reference_law, polygon(m_ref));
  double                   phi_max   = 0;
  for (const auto &z : reference.z)
    phi_max = std::max(phi_max, phi_of(z));
  EXPECT_GT(phi_max, 0.99); // the path does yield

  for (const auto integrator : {BoucWenIntegrator::forward_euler, BoucWenIntegrator::backward_euler})
    {
      const BoucWenInteraction law(parameters(4, integrator, 1e-12, 0.05, 0.6), k, F_y);
      double                   previous = 0;
      for (const unsigned int m : {8u, 16u, 32u, 64u})
        {
          const double err = path_error(drive(law, polygon(m)), reference, m_ref / m);
          if (previous > 0)
            {
              std::cout << "  " << name(integrator) << ": " << m << " increments per side, error "
                        << err << " z_y, ratio " << previous / err << std::endl;
              EXPECT_NEAR(previous / err, 2.0, 0.25) << name(integrator) << ", " << m;
            }
          previous = err;
        }
    }
  for (const double tolerance : {1e-4, 1e-6, 1e-8})
    {
      const BoucWenInteraction law(parameters(4, BoucWenIntegrator::adaptive, tolerance, 0.05, 0.6), k, F_y);
      const Response           r   = drive(law, polygon(1));
      const double             err = path_error(r, reference, m_ref);
      std::cout << "  adaptive, tolerance " << tolerance << ", one increment per side (" << r.work
                << " sub-steps): error / tolerance = " << err / tolerance << std::endl;
      EXPECT_LT(err, 10 * tolerance);
    }
}



// beta = gamma = 1/2: H2 = 0 when w . d < 0, so unloading from a yielded state is
// exactly elastic in every direction that decreases Phi: Delta F = K Delta delta, the
// tangent is K (a = 0.05: K, not a K).
TEST(BoucWenInteraction, UnloadingIsElasticForBetaEqualsGamma)
{
  for (const auto integrator : all_integrators)
    {
      const BoucWenInteraction law(parameters(8, integrator, 1e-10, 0.05), k, F_y);
      Vector                   z{}, F{};
      for (unsigned int j = 0; j < 200; ++j)
        law.update(Vector{{0.02 * z_y[0], 0.01 * z_y[1], 0.015 * z_y[2]}}, F, z.data(), nullptr);
      ASSERT_GT(phi_of(z), 0.99);
      unsigned int n_unloading = 0;
      // Unload along a direction that is not the reverse of the loading one.
      const Vector dd{{-0.03 * z_y[0], 0.004 * z_y[1], -0.02 * z_y[2]}};
      // While the whole step decreases Phi (w . d < 0 at its start and its end).
      const auto unloading = [&]() {
        double P = 0;
        for (unsigned int i = 0; i < 3; ++i)
          P += (z[i] + dd[i]) / z_y[i] * dd[i] / z_y[i];
        return P < 0;
      };
      while (unloading())
        {
          const Vector before = F;
          Matrix       T;
          law.update(dd, F, z.data(), &T);
          for (unsigned int i = 0; i < 3; ++i)
            {
              ASSERT_NEAR(F[i] - before[i], k[i] * dd[i], 1e-12 * F_y[i]) << name(integrator);
              for (unsigned int m = 0; m < 3; ++m)
                ASSERT_NEAR(T[i][m], i == m ? k[i] : 0.0, 1e-12 * k[i]) << name(integrator);
            }
          ++n_unloading;
        }
      EXPECT_GT(n_unloading, 10u) << name(integrator);
    }
}



// Degradation is not part of the coupled law: unsupported() says why, reinit() refuses;
// a non-finite increment is a RuntimeError, never a silent NaN.
TEST(BoucWenInteraction, UnsupportedParametersAndFailures)
{
  BoucWenParameters p = parameters(8, BoucWenIntegrator::backward_euler);
  EXPECT_EQ(BoucWenInteraction::unsupported(p), "");
  p.stiffness_degradation_c_eta = 1;
  EXPECT_NE(BoucWenInteraction::unsupported(p).find("degradation"), std::string::npos);
  EXPECT_THROW(BoucWenInteraction(p, k, F_y), std::invalid_argument);
  EXPECT_THROW(BoucWenInteraction(parameters(8, BoucWenIntegrator::adaptive), k, Vector{{1, 0, 1}}),
               std::invalid_argument);
  for (const auto integrator : all_integrators)
    {
      const BoucWenInteraction law(parameters(8, integrator), k, F_y);
      Vector                   z{{0.5 * z_y[0], 0, 0}}, F{};
      EXPECT_THROW(law.update(Vector{{std::numeric_limits<double>::quiet_NaN(), 0, 0}}, F, z.data(), nullptr),
                   hysteron::RuntimeError);
      EXPECT_THROW(law.update(Vector{{0, std::numeric_limits<double>::infinity(), 0}}, F, z.data(), nullptr),
                   hysteron::RuntimeError);
    }
}




// ---------------------------------------------------------------------------------------
// N components: the 2D facet (N = 3, the constants above) and the 3D facet (N = 6).
// ---------------------------------------------------------------------------------------

namespace
{
  /**
   * The springs of a facet with N components: N = 3, the 2D facet above; N = 6, a
   * rectangular 3D facet b x h = 0.1 m x 0.05 m (s_1 along b, s_2 along h) between nuclei
   * L = 0.1 m apart, S235 steel: k_n = E A / L, k_s = G A / L, bending k_b,i = E I_i / L,
   * torsion k_t = G J / L; the yield values of FacetSprings<3>::yield_values with f = 1/4:
   * N_y = sigma_y A, V_y = sigma_y A / sqrt(3), M_y,i = f sigma_y A sqrt(12 I_i / A),
   * T_y = f sigma_y / sqrt(3) A sqrt(12 J / A). The stiffnesses span 8 orders of magnitude,
   * the c_i of the law 5.
   */
  template <unsigned int N>
  struct FacetOf;

  template <>
  struct FacetOf<3>
  {
    using Vector = std::array<double, 3>;
    static Vector
    stiffness()
    {
      return k;
    }
    static Vector
    yield_values()
    {
      return F_y;
    }
  };

  template <>
  struct FacetOf<6>
  {
    using Vector = std::array<double, 6>;
    static constexpr double b = 0.1, h = 0.05, L = 0.1, A = b * h;
    static constexpr double I_1 = b * h * h * h / 12, I_2 = h * b * b * b / 12, J = I_1 + I_2;
    static Vector
    stiffness()
    {
      const double G = E / (2 * (1 + nu));
      return {{E * A / L, G * A / L, G * A / L, E * I_1 / L, E * I_2 / L, G * J / L}};
    }
    static Vector
    yield_values()
    {
      const double tau_y = sigma_y / std::sqrt(3.0);
      return {{sigma_y * A,
               tau_y * A,
               tau_y * A,
               0.25 * sigma_y * A * std::sqrt(12 * I_1 / A),
               0.25 * sigma_y * A * std::sqrt(12 * I_2 / A),
               0.25 * tau_y * A * std::sqrt(12 * J / A)}};
    }
  };

  template <typename T>
  class BoucWenInteractionN : public ::testing::Test
  {
  public:
    static constexpr unsigned int N = T::value;
    using Law                       = hysteron::Material::BoucWenInteraction<N>;
    using Vector                    = typename Law::Vector;
    using Matrix                    = typename Law::Matrix;

    const Vector k   = FacetOf<N>::stiffness();
    const Vector F_y = FacetOf<N>::yield_values();
    Vector       z_y;

    BoucWenInteractionN()
    {
      for (unsigned int i = 0; i < N; ++i)
        z_y[i] = F_y[i] / k[i];
    }

    /// Phi = |z / z_y|.
    double
    phi(const Vector &z) const
    {
      double s = 0;
      for (unsigned int i = 0; i < N; ++i)
        s += (z[i] / z_y[i]) * (z[i] / z_y[i]);
      return std::sqrt(s);
    }

    /// From w = z / z_y (or d = delta / z_y) to physical units.
    Vector
    physical(const Vector &w) const
    {
      Vector x;
      for (unsigned int i = 0; i < N; ++i)
        x[i] = w[i] * z_y[i];
      return x;
    }

    /// The recoverable energy sum_i 1/2 a k_i delta_i^2 + 1/2 (1 - a) k_i z_i^2.
    double
    stored_energy(const double a, const Vector &delta, const Vector &z) const
    {
      double e = 0;
      for (unsigned int i = 0; i < N; ++i)
        e += 0.5 * a * k[i] * delta[i] * delta[i] + 0.5 * (1 - a) * k[i] * z[i] * z[i];
      return e;
    }

    /// A smooth closed path in all N components (w units, amplitudes 3 to 6, random
    /// frequencies 1 to 3 and phases; delta(0) = delta(1) = its value at s = 0).
    std::vector<Vector>
    random_cycle(const unsigned int seed, const unsigned int n_steps) const
    {
      std::mt19937                           random(seed);
      std::uniform_real_distribution<double> amplitude(3, 6), phase(0, 2 * M_PI);
      std::uniform_int_distribution<int>     frequency(1, 3);
      std::array<double, N>                  A, p;
      std::array<int, N>                     f;
      for (unsigned int i = 0; i < N; ++i)
        {
          A[i] = amplitude(random);
          p[i] = phase(random);
          f[i] = frequency(random);
        }
      std::vector<Vector> path(n_steps + 1);
      for (unsigned int j = 0; j <= n_steps; ++j)
        for (unsigned int i = 0; i < N; ++i)
          path[j][i] = A[i] * z_y[i] *
                       (std::sin(2 * M_PI * f[i] * double(j % n_steps) / n_steps + p[i]) -
                        std::sin(p[i]));
      return path;
    }
  };

  using ComponentCounts = ::testing::Types<std::integral_constant<unsigned int, 3>,
                                           std::integral_constant<unsigned int, 6>>;

  class ComponentCountName
  {
  public:
    template <typename T>
    static std::string
    GetName(int)
    {
      return "N" + std::to_string(T::value);
    }
  };
} // namespace

TYPED_TEST_SUITE(BoucWenInteractionN, ComponentCounts, ComponentCountName);



// Each component loaded alone, in turn, is the uniaxial law with its k_i and F_y,i (force,
// state and tangent to 1e-10 of F_y, z_y and k), the other components stay exactly zero;
// two cycles of amplitude 4 z_y, every integrator, beta = 1/2 and 3/4.
TYPED_TEST(BoucWenInteractionN, EachComponentAloneIsTheUniaxialLaw)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  using Matrix             = typename TestFixture::Matrix;
  const auto &k = this->k, &F_y = this->F_y, &z_y = this->z_y;
  double      worst = 0, worst_tangent = 0;
  for (const auto integrator : all_integrators)
    for (unsigned int i = 0; i < N; ++i)
      for (const double beta : {0.5, 0.75})
        {
          const BoucWenParameters         p = parameters(8, integrator, 1e-12, 0.05, beta);
          const typename TestFixture::Law coupled(p, k, F_y);
          const BoucWenUniaxial           uniaxial(p, k[i], F_y[i]);
          Vector                          z{}, F{};
          double                          z1[BoucWenUniaxial::max_n_state_variables] = {0, 1, 0};
          double                          F1 = 0, previous = 0;
          for (unsigned int j = 1; j <= 400; ++j)
            {
              const double delta = 4 * z_y[i] * std::sin(4 * M_PI * j / 400.0);
              Vector       dd{};
              dd[i]    = delta - previous;
              previous = delta;
              Matrix T;
              double T1 = 0;
              coupled.update(dd, F, z.data(), &T);
              uniaxial.update(dd[i], F1, z1, &T1);
              worst = std::max({worst, std::abs(F[i] - F1) / F_y[i], std::abs(z[i] - z1[0]) / z_y[i]});
              worst_tangent = std::max(worst_tangent, std::abs(T[i][i] - T1) / k[i]);
              for (unsigned int m = 0; m < N; ++m)
                if (m != i)
                  {
                    ASSERT_EQ(z[m], 0.0);
                    ASSERT_EQ(F[m], 0.0);
                    ASSERT_EQ(T[i][m], 0.0);
                    ASSERT_EQ(T[m][i], 0.0);
                  }
            }
          EXPECT_LT(worst, 1e-10) << name(integrator) << ", component " << i << ", beta " << beta;
          EXPECT_LT(worst_tangent, 1e-8)
            << name(integrator) << ", component " << i << ", beta " << beta;
        }
  std::cout << "  N = " << N << ": max difference to the uniaxial law " << worst
            << " (F / F_y, z / z_y), tangent " << worst_tangent << " k" << std::endl;
}



// Proportional deformation of all N components, delta = s d_0 z_y with d_0 of mixed signs,
// beta + gamma = 0.9 (beta = 0.6, gamma = 0.3, n = 8): the state saturates at
// Phi_s = (beta + gamma)^(-1/n) = 1.01326, at the point w = Phi_s C^(-1) d_0 / |C^(-1) d_0|
// where the flow direction C w is the loading direction (c_i ~ k_i / F_y,i^2), to 1e-6
// (forward Euler, increments 0.01 z_y: 1e-3); the adaptive and backward Euler integrators
// never exceed Phi_s by more than the tolerance, also with increments of 2 z_y.
TYPED_TEST(BoucWenInteractionN, ProportionalLoadingSaturatesAtPhiS)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  const auto  &k = this->k, &F_y = this->F_y;
  const double n = 8, beta = 0.6, gamma = 0.3, phi_s = std::pow(beta + gamma, -1 / n);
  Vector       d0, expected;
  double       norm = 0;
  for (unsigned int i = 0; i < N; ++i)
    {
      d0[i]       = (i % 2 == 0 ? 1.0 : -0.7) * (1 + 0.3 * i);
      expected[i] = d0[i] * F_y[i] * F_y[i] / k[i]; // C^(-1) d_0, up to a factor
      norm += expected[i] * expected[i];
    }
  for (unsigned int i = 0; i < N; ++i)
    expected[i] *= phi_s / std::sqrt(norm);
  for (const auto integrator : all_integrators)
    for (const double dx : {0.01, 0.3, 2.0})
      {
        if (integrator == BoucWenIntegrator::forward_euler && dx > 0.01)
          continue; // stable only for increments below ~2/n z_y
        const double tolerance = 1e-9;
        BoucWenParameters p = parameters(n, integrator, tolerance, 0.02, beta);
        p.gamma             = gamma;
        const typename TestFixture::Law law(p, k, F_y);
        Vector                          z{}, F{};
        double                          phi_max = 0;
        // 40 z_y along d_0 / |d_0|_inf.
        const unsigned int steps = std::lround(40 / dx);
        for (unsigned int j = 0; j < steps; ++j)
          {
            Vector dd;
            for (unsigned int i = 0; i < N; ++i)
              dd[i] = dx * d0[i] / (1 + 0.3 * (N - 1)) * this->z_y[i];
            law.update(dd, F, z.data(), nullptr);
            phi_max = std::max(phi_max, this->phi(z));
          }
        const double phi_end = this->phi(z), point_tolerance =
                                               integrator == BoucWenIntegrator::forward_euler ? 1e-3 : 1e-6;
        EXPECT_NEAR(phi_end, phi_s, point_tolerance) << name(integrator) << ", dx = " << dx;
        double point_error = 0;
        for (unsigned int i = 0; i < N; ++i)
          point_error = std::max(point_error, std::abs(z[i] / this->z_y[i] - expected[i]));
        EXPECT_LT(point_error, point_tolerance) << name(integrator) << ", dx = " << dx;
        if (integrator != BoucWenIntegrator::forward_euler)
          {
            EXPECT_LE(phi_max, phi_s + tolerance) << name(integrator) << ", dx = " << dx;
          }
        if (dx == 0.01 || dx == 2.0)
          std::cout << "  N = " << N << ", " << name(integrator) << ", increments " << dx
                    << " z_y: Phi_end - Phi_s = " << phi_end - phi_s
                    << ", max |w - w_s| = " << point_error << ", max Phi - Phi_s = " << phi_max - phi_s
                    << std::endl;
      }
}



// A random closed path through all N components (amplitudes 3 to 6 z_y, several reversals,
// three seeds), with beta + gamma = 1 and 0.9: Phi never exceeds Phi_s by more than the
// tolerance (adaptive, backward Euler; 200 and 50 increments per cycle, i.e. increments up
// to ~0.5 and ~2 z_y), and the work of the closed deformation cycle exceeds the change of the
// stored energy: the dissipation is non-negative (for beta = gamma at every increment, too).
TYPED_TEST(BoucWenInteractionN, RandomCyclicPathStaysInsideAndDissipates)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  const auto  &k = this->k, &F_y = this->F_y;
  const double tolerance = 1e-8;
  double       worst_excess = -1, min_dissipation = std::numeric_limits<double>::infinity(),
         worst_step_dissipation = 0;
  for (const auto integrator : all_integrators)
    for (const auto &[beta, gamma] : {std::pair{0.5, 0.5}, std::pair{0.6, 0.3}})
      for (const unsigned int steps : {50u, 200u, 2000u})
        for (const unsigned int seed : {1u, 2u, 3u})
          {
            if (integrator == BoucWenIntegrator::forward_euler && steps < 2000)
              continue;
            const double      a = 0.02, n = 6;
            BoucWenParameters p = parameters(n, integrator, tolerance, a, beta);
            p.gamma             = gamma;
            const typename TestFixture::Law law(p, k, F_y);
            const double                    phi_s = std::pow(beta + gamma, -1 / n);
            const auto                      path  = this->random_cycle(seed, steps);
            Vector                          z{}, F{};
            double work = 0, phi_max = 0, min_step_dissipation = 0;
            for (unsigned int j = 1; j <= steps; ++j)
              {
                Vector dd;
                for (unsigned int i = 0; i < N; ++i)
                  dd[i] = path[j][i] - path[j - 1][i];
                const Vector F0 = F, z0 = z;
                law.update(dd, F, z.data(), nullptr);
                // The work of the increment (trapezoidal rule) less the change of the stored
                // energy: the dissipation of the increment.
                double step_work = 0;
                for (unsigned int i = 0; i < N; ++i)
                  step_work += 0.5 * (F0[i] + F[i]) * dd[i];
                work += step_work;
                min_step_dissipation =
                  std::min(min_step_dissipation,
                           step_work - (this->stored_energy(a, path[j], z) -
                                        this->stored_energy(a, path[j - 1], z0)));
                phi_max = std::max(phi_max, this->phi(z));
              }
            double scale = 0; // the energy of the yield point, sum_i F_y,i z_y,i
            for (unsigned int i = 0; i < N; ++i)
              scale += F_y[i] * this->z_y[i];
            const double dissipation = (work - (this->stored_energy(a, path.back(), z) -
                                                this->stored_energy(a, path.front(), Vector{}))) /
                                       scale;
            const std::string where = std::string(name(integrator)) + ", beta " +
                                      std::to_string(beta) + ", " + std::to_string(steps) +
                                      " steps, seed " + std::to_string(seed);
            EXPECT_GT(phi_max, 0.99 * phi_s) << where; // the path does yield
            if (integrator != BoucWenIntegrator::forward_euler)
              {
                EXPECT_LE(phi_max, phi_s + tolerance) << where;
                worst_excess = std::max(worst_excess, phi_max - phi_s);
              }
            EXPECT_GT(dissipation, 0) << where;
            min_dissipation = std::min(min_dissipation, dissipation);
            if (beta == gamma && steps == 2000)
              {
                EXPECT_GT(min_step_dissipation, -1e-6 * scale) << where;
                worst_step_dissipation = std::min(worst_step_dissipation, min_step_dissipation / scale);
              }
          }
  std::cout << "  N = " << N << ": max (Phi - Phi_s) " << worst_excess
            << " (adaptive, backward Euler), smallest dissipation of a cycle "
            << min_dissipation << " sum_i F_y,i z_y,i, smallest of an increment (beta = gamma, "
            << "2000 increments) " << worst_step_dissipation << std::endl;
}



// The consistent tangent of backward Euler is the derivative of its update: central
// differences of dF1 / d(Delta delta), entries in units of F_y,i / z_y,j, agree to 1e-6 of
// the largest entry, at random states inside the ball and random increments (elastic range,
// yielding, unloading with beta > gamma, large increments).
TYPED_TEST(BoucWenInteractionN, BackwardEulerTangentMatchesFiniteDifferences)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  using Matrix             = typename TestFixture::Matrix;
  const auto        &k = this->k, &F_y = this->F_y, &z_y = this->z_y;
  std::mt19937       random(7);
  std::normal_distribution<double>       normal;
  std::uniform_real_distribution<double> uniform(0, 1);
  double             worst = 0;
  unsigned int       n_cases = 0;
  for (const double n : {1.5, 2.0, 8.0, 16.0})
    for (const double beta : {0.5, 0.75})
      for (unsigned int sample = 0; sample < 12; ++sample)
        {
          const BoucWenParameters p =
            parameters(n, BoucWenIntegrator::backward_euler, 1e-13, 0.03, beta);
          const typename TestFixture::Law law(p, k, F_y);
          // w0 in the ball (radius up to 0.98), Delta d of length 0.01 to 3.
          Vector w0, d;
          double r0 = 0, rd = 0;
          for (unsigned int i = 0; i < N; ++i)
            {
              w0[i] = normal(random);
              d[i]  = normal(random);
              r0 += w0[i] * w0[i];
              rd += d[i] * d[i];
            }
          const double radius = 0.98 * std::cbrt(uniform(random)),
                       length = 0.01 * std::pow(300, uniform(random));
          for (unsigned int i = 0; i < N; ++i)
            {
              w0[i] *= radius / std::sqrt(r0);
              d[i] *= length / std::sqrt(rd);
            }
          const Vector z0 = this->physical(w0), dd = this->physical(d);
          const auto   force_after = [&](const Vector &increment, Matrix *T) {
            Vector z = z0, F{};
            law.update(increment, F, z.data(), T);
            return F;
          };
          Matrix T, fd;
          force_after(dd, &T);
          for (unsigned int j = 0; j < N; ++j)
            {
              const double h  = 1e-6 * z_y[j];
              Vector       dp = dd, dm = dd;
              dp[j] += h;
              dm[j] -= h;
              const Vector Fp = force_after(dp, nullptr), Fm = force_after(dm, nullptr);
              for (unsigned int i = 0; i < N; ++i)
                fd[i][j] = (Fp[i] - Fm[i]) / (2 * h);
            }
          double diff = 0, size = 0;
          for (unsigned int i = 0; i < N; ++i)
            for (unsigned int j = 0; j < N; ++j)
              {
                const double s = z_y[j] / F_y[i];
                diff           = std::max(diff, std::abs(T[i][j] - fd[i][j]) * s);
                size           = std::max(size, std::abs(fd[i][j]) * s);
              }
          worst = std::max(worst, diff / size);
          ++n_cases;
          EXPECT_LT(diff / size, 1e-6) << "n = " << n << ", beta = " << beta << ", sample " << sample;
        }
  std::cout << "  N = " << N << ": worst relative difference tangent vs central differences "
            << worst << " (" << n_cases << " cases)" << std::endl;
}



// The continuum tangent D_t = a K + E - H1 H2 (E g)(E g)^T / (g^T E g) is symmetric (to
// 1e-13 of sqrt(k_i k_j)) at random states, on the surface and inside, for loading rates; for
// a = 0 on the surface (H1 H2 = 1) D_t delta' is tangent to it, g . D_t delta' = 0.
TYPED_TEST(BoucWenInteractionN, ContinuumTangentIsSymmetric)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  using Matrix             = typename TestFixture::Matrix;
  const auto                      &k = this->k, &F_y = this->F_y;
  std::mt19937                     random(11);
  std::normal_distribution<double> normal;
  double                           worst_asymmetry = 0, worst_normal = 0;
  for (const double a : {0.0, 0.05})
    {
      const typename TestFixture::Law law(parameters(8, BoucWenIntegrator::adaptive, 1e-6, a), k, F_y);
      for (unsigned int sample = 0; sample < 50; ++sample)
        {
          Vector w, rate;
          double r = 0;
          for (unsigned int i = 0; i < N; ++i)
            {
              w[i]    = normal(random);
              rate[i] = normal(random) * this->z_y[i];
              r += w[i] * w[i];
            }
          // On the surface for half the samples, inside for the others.
          const double radius = sample % 2 == 0 ? 1.0 : 0.9 * (sample + 1) / 50.0;
          double       P      = 0; // w . d', made positive: loading, H2 = beta + gamma = 1
          for (unsigned int i = 0; i < N; ++i)
            {
              w[i] *= radius / std::sqrt(r);
              P += w[i] * rate[i] / this->z_y[i];
            }
          if (P < 0)
            for (unsigned int i = 0; i < N; ++i)
              rate[i] = -rate[i];
          const Vector z = this->physical(w);
          const Matrix D = law.continuum_tangent(z.data(), rate);
          for (unsigned int i = 0; i < N; ++i)
            for (unsigned int j = 0; j < N; ++j)
              {
                const double asymmetry = std::abs(D[i][j] - D[j][i]) / std::sqrt(k[i] * k[j]);
                worst_asymmetry        = std::max(worst_asymmetry, asymmetry);
                EXPECT_LT(asymmetry, 1e-13) << "a = " << a << ", sample " << sample;
              }
          if (a == 0 && radius == 1.0)
            {
              // g_i ~ F^h_i / F_y,i^2 = w_i / F_y,i (a = 0); g . D rate relative to |g| |D| |rate|.
              double g_D_rate = 0, scale = 0;
              for (unsigned int i = 0; i < N; ++i)
                {
                  double D_rate = 0;
                  for (unsigned int j = 0; j < N; ++j)
                    D_rate += D[i][j] * rate[j];
                  g_D_rate += w[i] / F_y[i] * D_rate;
                  scale += std::abs(w[i] / F_y[i] * k[i] * rate[i]);
                }
              worst_normal = std::max(worst_normal, std::abs(g_D_rate) / scale);
              EXPECT_LT(std::abs(g_D_rate), 1e-12 * scale) << "sample " << sample;
            }
        }
    }
  std::cout << "  N = " << N << ": max |D_ij - D_ji| / sqrt(k_i k_j) = " << worst_asymmetry
            << ", on the surface max |g . D delta'| = " << worst_normal << " (relative)" << std::endl;
}



// beta = gamma = 1/2: after loading all N components to yield, every increment that
// decreases Phi over the whole step (w . d < 0 at its start and end) is exactly elastic:
// Delta F = K Delta delta and the tangent is K, for every integrator.
TYPED_TEST(BoucWenInteractionN, UnloadingIsElasticForBetaEqualsGamma)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  using Matrix             = typename TestFixture::Matrix;
  const auto &k = this->k, &F_y = this->F_y, &z_y = this->z_y;
  for (const auto integrator : all_integrators)
    {
      const typename TestFixture::Law law(parameters(8, integrator, 1e-10, 0.05), k, F_y);
      Vector                          z{}, F{}, load, dd;
      for (unsigned int i = 0; i < N; ++i)
        {
          load[i] = (0.01 + 0.002 * i) * (i % 3 == 1 ? -1 : 1) * z_y[i];
          // Unload along a direction that is not the reverse of the loading one.
          dd[i] = -(0.015 + 0.004 * ((i * 7) % N)) * (i % 3 == 1 ? -1 : 1) * z_y[i];
        }
      dd[N - 1] = 0.3 * load[N - 1];
      for (unsigned int j = 0; j < 300; ++j)
        law.update(load, F, z.data(), nullptr);
      ASSERT_GT(this->phi(z), 0.99) << name(integrator);
      const auto unloading = [&]() {
        double P = 0;
        for (unsigned int i = 0; i < N; ++i)
          P += (z[i] + dd[i]) / z_y[i] * dd[i] / z_y[i];
        return P < 0;
      };
      unsigned int n_unloading = 0;
      while (unloading())
        {
          const Vector before = F;
          Matrix       T;
          law.update(dd, F, z.data(), &T);
          for (unsigned int i = 0; i < N; ++i)
            {
              ASSERT_NEAR(F[i] - before[i], k[i] * dd[i], 1e-12 * F_y[i]) << name(integrator);
              for (unsigned int m = 0; m < N; ++m)
                ASSERT_NEAR(T[i][m], i == m ? k[i] : 0.0, 1e-12 * k[i]) << name(integrator);
            }
          ++n_unloading;
        }
      EXPECT_GT(n_unloading, 10u) << name(integrator);
    }
}



// Bad input and failures: zero yield values are refused, a non-finite increment in any
// component is a RuntimeError whose message lists all N components.
TYPED_TEST(BoucWenInteractionN, UnsupportedParametersAndFailures)
{
  constexpr unsigned int N = TestFixture::N;
  using Vector             = typename TestFixture::Vector;
  using Law                = typename TestFixture::Law;
  Vector bad = this->F_y;
  bad[N - 1] = 0;
  EXPECT_THROW(Law(parameters(8, BoucWenIntegrator::adaptive), this->k, bad), std::invalid_argument);
  for (const auto integrator : all_integrators)
    {
      const Law law(parameters(8, integrator), this->k, this->F_y);
      for (unsigned int i = 0; i < N; ++i)
        {
          Vector z{}, F{}, dd{};
          z[0]  = 0.5 * this->z_y[0];
          dd[i] = i % 2 ? std::numeric_limits<double>::infinity() :
                          std::numeric_limits<double>::quiet_NaN();
          try
            {
              law.update(dd, F, z.data(), nullptr);
              ADD_FAILURE() << "no error for a non-finite component " << i;
            }
          catch (const hysteron::RuntimeError &error)
            {
              const std::string what = error.what();
              // z/z_y = 0.5, 0, ..., 0: N - 1 separators in each list.
              EXPECT_EQ(std::count(what.begin(), what.end(), ','), std::ptrdiff_t(2 * (N - 1) + 1))
                << what;
            }
        }
    }
}
