// The shear building: its modes and Rayleigh damping, and Newmark's average
// acceleration with Newton on the storeys' laws.
#include <deal.II/lac/lapack_full_matrix.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include "oscillator/shear_building.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace hysteron
{
  namespace Oscillator
  {
    namespace
    {
      /// Newmark's average acceleration.
      constexpr double newmark_beta = 0.25, newmark_gamma = 0.5;

      /// Solve the symmetric tridiagonal system (diagonal @p d, @p e[i] coupling i and
      /// i + 1; positive definite here) for @p x in place, @p d overwritten (Thomas).
      void
      solve_tridiagonal(std::vector<double> &d, const std::vector<double> &e, std::vector<double> &x)
      {
        const std::size_t n = d.size();
        for (std::size_t i = 1; i < n; ++i)
          {
            const double w = e[i - 1] / d[i - 1];
            d[i] -= w * e[i - 1];
            x[i] -= w * x[i - 1];
          }
        x[n - 1] /= d[n - 1];
        for (std::size_t i = n - 1; i-- > 0;)
          x[i] = (x[i] - e[i] * x[i + 1]) / d[i];
      }
    } // namespace



    ShearBuilding::ShearBuilding(std::vector<double>                          mass_,
                                 std::vector<double>                          stiffness_,
                                 std::vector<double>                          yield_force_,
                                 const double                                 damping_ratio,
                                 std::unique_ptr<Material::UniaxialSpringLaw> law_)
      : mass(std::move(mass_))
      , stiffness(std::move(stiffness_))
      , yield_force(std::move(yield_force_))
      , law(std::move(law_))
    {
      const unsigned int n = mass.size();
      AssertThrow(n > 0 && stiffness.size() == n && (!law || yield_force.size() == n),
                  dealii::ExcMessage("ShearBuilding: one mass, stiffness and yield force per storey"));
      // The elastic modes: omega^2 the eigenvalues of M^-1/2 K_0 M^-1/2.
      dealii::LAPACKFullMatrix<double> A(n, n);
      for (unsigned int i = 0; i < n; ++i)
        {
          A(i, i) = (stiffness[i] + (i + 1 < n ? stiffness[i + 1] : 0.0)) / mass[i];
          if (i + 1 < n)
            A(i, i + 1) = A(i + 1, i) = -stiffness[i + 1] / std::sqrt(mass[i] * mass[i + 1]);
        }
      A.compute_eigenvalues();
      std::vector<double> omega;
      for (unsigned int i = 0; i < n; ++i)
        omega.push_back(std::sqrt(std::max(A.eigenvalue(i).real(), 0.0)));
      std::sort(omega.begin(), omega.end());
      for (const double w : omega)
        mode_periods.push_back(2 * M_PI / w);
      // zeta = alpha / (2 omega) + beta omega / 2 at the first two modes; one storey:
      // mass-proportional, c = 2 zeta omega m.
      if (n == 1)
        alpha = 2 * damping_ratio * omega[0];
      else
        {
          alpha = 2 * damping_ratio * omega[0] * omega[1] / (omega[0] + omega[1]);
          beta  = 2 * damping_ratio / (omega[0] + omega[1]);
        }
      n_state = law ? law->n_state_variables() : 0;
      virgin_state.assign(n * n_state, 0.0);
      if (law)
        for (unsigned int i = 0; i < n; ++i)
          law->add_spring(stiffness[i], yield_force.empty() ? 0.0 : yield_force[i], virgin_state.data() + i * n_state);
      for (auto *w : {&trial.u, &trial.v, &trial.a, &trial.drift, &trial.force, &tangent, &residual, &diagonal,
                      &increment})
        w->assign(n, 0.0);
      off_diagonal.assign(n - 1, 0.0);
    }



    std::vector<double>
    ShearBuilding::modal_damping_ratios() const
    {
      std::vector<double> zeta;
      for (const double T : mode_periods)
        {
          const double omega = 2 * M_PI / T;
          zeta.push_back(alpha / (2 * omega) + beta * omega / 2);
        }
      return zeta;
    }



    double
    ShearBuilding::hysteretic_variable(const State &s, const unsigned int storey) const
    {
      return law && n_state > 0 ? law->hysteretic_variable(storey, &s.spring_state[storey * n_state]) : 0.0;
    }



    double
    ShearBuilding::damping_force(const std::vector<double> &v, const unsigned int i) const
    {
      const unsigned int n     = mass.size();
      const double       below = stiffness[i] * (v[i] - (i > 0 ? v[i - 1] : 0.0));
      const double       above = i + 1 < n ? stiffness[i + 1] * (v[i + 1] - v[i]) : 0.0;
      return alpha * mass[i] * v[i] + beta * (below - above);
    }



    bool
    ShearBuilding::storey_forces(const State &s, std::string &failure)
    {
      const unsigned int n = mass.size();
      for (unsigned int i = 0; i < n; ++i)
        {
          trial.drift[i] = trial.u[i] - (i > 0 ? trial.u[i - 1] : 0.0);
          increment[i]   = trial.drift[i] - s.drift[i];
        }
      if (!law)
        {
          for (unsigned int i = 0; i < n; ++i)
            {
              trial.force[i] = stiffness[i] * trial.drift[i];
              tangent[i]     = stiffness[i];
            }
          return true;
        }
      // The law advances from the converged state by the whole increment.
      std::copy(s.force.begin(), s.force.end(), trial.force.begin());
      std::copy(s.spring_state.begin(), s.spring_state.end(), trial.spring_state.begin());
      return law->update(0, n, increment.data(), trial.force.data(), trial.spring_state.data(), tangent.data(), 1,
                         failure) == n;
    }



    bool
    ShearBuilding::step(State &s, const double dt, const double ground, std::string &failure)
    {
      const unsigned int n  = mass.size();
      const double       c0 = 1 / (newmark_beta * dt * dt), c1 = newmark_gamma / (newmark_beta * dt);
      // The predictor: a_{n+1} = 0.
      for (unsigned int i = 0; i < n; ++i)
        trial.u[i] = s.u[i] + dt * s.v[i] + dt * dt * (0.5 - newmark_beta) * s.a[i];
      for (unsigned int iteration = 0; iteration < 50; ++iteration)
        {
          for (unsigned int i = 0; i < n; ++i)
            {
              trial.a[i] = c0 * (trial.u[i] - s.u[i] - dt * s.v[i]) - (0.5 / newmark_beta - 1) * s.a[i];
              trial.v[i] = s.v[i] + dt * ((1 - newmark_gamma) * s.a[i] + newmark_gamma * trial.a[i]);
            }
          if (!storey_forces(s, failure))
            return false;
          ++n_newton;
          // r = -M 1 a_g - M a - C v - R. Converged at 1e-10 of the forces, or at the
          // round-off of the terms that cancel in it (the inertia c0 m u of a long step
          // is far above the forces), 64 eps of their size.
          double largest = 0, scale = 0, terms = 0;
          for (unsigned int i = 0; i < n; ++i)
            {
              const double restoring = trial.force[i] - (i + 1 < n ? trial.force[i + 1] : 0.0);
              residual[i] = -mass[i] * (ground + trial.a[i]) - damping_force(trial.v, i) - restoring;
              largest     = std::max(largest, std::abs(residual[i]));
              scale = std::max({scale, std::abs(mass[i] * ground), std::abs(trial.force[i]), std::abs(mass[i] * trial.a[i])});
              terms = std::max(terms, mass[i] * (c0 * (std::abs(trial.u[i]) + std::abs(s.u[i]) + dt * std::abs(s.v[i])) +
                                                 std::abs(s.a[i])));
            }
          if (!std::isfinite(largest))
            {
              failure = "the residual is not finite";
              return false;
            }
          if (largest <= std::max(1e-10 * scale, 64 * std::numeric_limits<double>::epsilon() * terms))
            {
              std::swap(s, trial);
              return true;
            }
          // K_eff = c0 M + c1 C + K_t (tridiagonal) times the correction = r.
          for (unsigned int i = 0; i < n; ++i)
            {
              const double k_above = i + 1 < n ? stiffness[i + 1] : 0.0, t_above = i + 1 < n ? tangent[i + 1] : 0.0;
              diagonal[i] = (c0 + c1 * alpha) * mass[i] + c1 * beta * (stiffness[i] + k_above) + tangent[i] + t_above;
              if (i + 1 < n)
                off_diagonal[i] = -c1 * beta * k_above - t_above;
            }
          solve_tridiagonal(diagonal, off_diagonal, residual);
          for (unsigned int i = 0; i < n; ++i)
            trial.u[i] += residual[i];
        }
      failure = "Newton did not converge in 50 iterations";
      return false;
    }



    double
    ShearBuilding::elastic_energy(const State &s) const
    {
      double w = 0;
      for (unsigned int i = 0; i < mass.size(); ++i)
        w += law ? law->strain_energy(i, s.drift[i], s.spring_state.data() + i * n_state) :
                   0.5 * stiffness[i] * s.drift[i] * s.drift[i];
      return w;
    }



    void
    ShearBuilding::integrate(const std::function<double(double)> &ground,
                             const double                         time_step,
                             const double                         duration,
                             const Observer                      &observer)
    {
      const unsigned int n = mass.size();
      // At rest, the springs virgin (the states add_spring() wrote), M a_0 = -M 1 a_g(0).
      State s;
      for (auto *w : {&s.u, &s.v, &s.drift, &s.force})
        w->assign(n, 0.0);
      s.a.assign(n, -ground(0));
      s.spring_state = virgin_state;
      trial          = s;
      Energies    energies;
      double      storey_work = 0;
      State       old         = s;
      std::string failure;
      if (observer)
        observer(0, ground(0), s, energies);
      const unsigned long steps = static_cast<unsigned long>(std::ceil(duration / time_step - 1e-9));
      for (unsigned long k = 0; k < steps; ++k)
        {
          const double t0 = k * time_step, t1 = std::min(duration, (k + 1) * time_step);
          double       t  = t0, dt = t1 - t0, ag0 = ground(t0);
          while (t < t1 - 1e-12 * time_step)
            {
              dt               = std::min(dt, t1 - t);
              const double ag1 = ground(t + dt);
              old              = s;
              if (!step(s, dt, ag1, failure))
                {
                  ++n_cuts;
                  dt /= 2;
                  if (dt < (t1 - t0) / 1024)
                    {
                      std::ostringstream m;
                      m << "oscillator: the step from t = " << t << " s failed after 10 cuts: " << failure;
                      throw RuntimeError(m.str());
                    }
                  continue;
                }
              // The step's works, trapezoidal.
              for (unsigned int i = 0; i < n; ++i)
                {
                  const double du = s.u[i] - old.u[i];
                  energies.input -= du * mass[i] * 0.5 * (ag0 + ag1);
                  energies.damped += du * 0.5 * (damping_force(s.v, i) + damping_force(old.v, i));
                  storey_work += (s.drift[i] - old.drift[i]) * 0.5 * (s.force[i] + old.force[i]);
                }
              t   = t + dt;
              ag0 = ag1;
              ++n_steps;
            }
          if (observer)
            {
              energies.kinetic = 0;
              for (unsigned int i = 0; i < n; ++i)
                energies.kinetic += 0.5 * mass[i] * s.v[i] * s.v[i];
              energies.elastic    = elastic_energy(s);
              energies.hysteretic = storey_work - energies.elastic;
              observer(t1, ag0, s, energies);
            }
        }
    }
  } // namespace Oscillator
} // namespace hysteron
