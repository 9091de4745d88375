// The spectrum method: elastic response spectra by the exact integration of the
// piecewise-linear record, and inelastic ones of the material's law at a strength
// reduction factor and at a target ductility.
#include <deal.II/base/utilities.h>

#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include "base/plotter.h"
#include "base/progress.h"
#include "oscillator/oscillator.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

namespace hysteron
{
  namespace Oscillator
  {
    /**
     * `set Method = spectrum` (doc/oscillator.md): for every period T of `Periods`,
     * the single-degree-of-freedom oscillator of unit mass, k = omega^2, damping ratio
     * zeta, under the ground motion:
     *
     *  - elastic: the peak |u| = Sd, and the pseudo-spectra Sv = omega Sd and
     *    Sa = omega^2 Sd, by the exact solution of u'' + 2 zeta omega u' + omega^2 u =
     *    -a_g over each step, in which a_g is linear (Nigam and Jennings);
     *  - at `Strength reduction factor` R: storeys of the Material's law with
     *    F_y = m Sa / R (the elastic peak force over R): the peak Sd_R, the ductility
     *    mu_R = Sd_R / u_y (u_y = F_y / k) and the yield pseudo-acceleration
     *    Ay_R = F_y / m;
     *  - at `Target ductility` mu: the largest F_y whose ductility demand is mu (the
     *    demand over F_y / (m Sa) on a grid of 40 values in (0, 1], then bisection to
     *    1e-4): Ay_mu = F_y / m, Sd_mu and R_mu = m Sa / F_y.
     * Both step with the record's step divided into equal parts of at most
     * T / `Steps per period`.
     * Writes spectrum.csv and spectrum.png (gnuplot, when on PATH).
     */
    template <int dim>
    class Spectrum : public Methods::Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      run() override;

      std::string
      summary() const override;

      bool
      takes_ground_motion() const override
      {
        return true;
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

    private:
      /// The step of period @p T: the input's step in equal parts of at most T / `Steps per period`.
      double
      step_for(const double T) const
      {
        return ground.time_step / std::ceil(ground.time_step * steps_per_period / T - 1e-9);
      }
      /// The elastic peak displacement of period @p T (exact between samples).
      double
      elastic_peak(double T) const;
      /// The inelastic oscillator of period @p T and yield force @p yield (unit mass):
      /// its peak displacement.
      double
      inelastic_peak(double T, double yield);
      /// The largest yield force whose ductility demand is the target (period @p T,
      /// elastic peak force @p elastic_force).
      double
      strength_for_ductility(double T, double elastic_force);
      void
      write_plot(const std::vector<std::string> &columns) const;

      std::vector<double> periods;
      double              damping_ratio = 0.05, reduction = 0, ductility = 0;
      unsigned int        steps_per_period = 50;
      GroundInput         ground;
      unsigned long       n_inelastic_runs = 0, n_steps = 0;
      /// During run(): the signals, checked after every period and inelastic step.
      SignalGuard  *signals = nullptr;
      unsigned long n_checks = 0;
    };



    template <int dim>
    void
    Spectrum<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Spectrum");
      {
        prm.declare_entry("Periods",
                          "0.05:0.05:3",
                          Patterns::Anything(),
                          "The oscillators' periods [s]: a comma separated list, or first:step:last.");
        prm.declare_entry("Damping ratio", "0.05", Patterns::Double(), "zeta in [0, 1).");
        prm.declare_entry("Strength reduction factor",
                          "0",
                          Patterns::Double(),
                          "R >= 1: also the inelastic spectrum of oscillators with F_y = m Sa / R "
                          "(columns Sd_R, mu_R, Ay_R); 0: none.");
        prm.declare_entry("Target ductility",
                          "0",
                          Patterns::Double(),
                          "mu > 1: also the constant-ductility spectrum (columns Ay_mu, Sd_mu, "
                          "R_mu); 0: none.");
        prm.declare_entry("Steps per period",
                          "50",
                          Patterns::Integer(),
                          "The oscillators step with the record's step (or Time step) divided into "
                          "equal parts of at most T / this, >= 10: the elastic solution is exact for "
                          "the piecewise-linear record, but its peak is taken at the steps (low by "
                          "up to (pi / this)^2 / 2, 0.2 % at 50).");
        GroundInput::declare_parameters(prm);
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Spectrum<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      ground.parse(prm, this->get_scene(), "Spectrum", false);
      Section           s(prm, {"Spectrum"});
      const std::string text = dealii::Utilities::trim(s.get("Periods"));
      periods.clear();
      const std::vector<std::string> range = dealii::Utilities::split_string_list(text, ':');
      if (range.size() == 3)
        {
          double first = 0, step = 0, last = 0;
          char  *end   = nullptr;
          bool   ok    = true;
          for (auto [value, item] : {std::pair<double *, std::string>{&first, range[0]}, {&step, range[1]}, {&last, range[2]}})
            {
              *value = std::strtod(item.c_str(), &end);
              ok     = ok && end == item.c_str() + item.size() && std::isfinite(*value);
            }
          require(ok && first > 0 && step > 0 && last >= first && (last - first) / step < 1e5,
                  s.where("Periods"),
                  "first:step:last needs 0 < first <= last and step > 0 (at most 100,000 periods)");
          for (double T = first; T <= last * (1 + 1e-12); T = first + step * periods.size())
            periods.push_back(T);
        }
      else
        {
          require(range.size() == 1, s.where("Periods"), "a list, or first:step:last");
          const auto items = s.get_list("Periods");
          periods          = positive_list(s, "Periods", items.size());
        }
      require(!periods.empty(), s.where("Periods"), "needs at least one period");
      damping_ratio = s.get_double("Damping ratio");
      require(damping_ratio >= 0 && damping_ratio < 1, s.where("Damping ratio"), "must be in [0, 1)");
      reduction = s.get_double("Strength reduction factor");
      require(reduction == 0 || reduction >= 1, s.where("Strength reduction factor"), "must be 0 or >= 1");
      ductility = s.get_double("Target ductility");
      require(ductility == 0 || ductility > 1, s.where("Target ductility"), "must be 0 or > 1");
      const long steps = s.get_integer("Steps per period");
      require(steps >= 10 && steps <= 100000, s.where("Steps per period"), "must be from 10 to 100,000");
      steps_per_period = steps;
      if (reduction > 0 || ductility > 0)
        {
          const auto law = this->get_scene().material("", "Material").uniaxial_spring_law();
          require(law != nullptr && !law->linear(),
                  "Material/Model",
                  "inelastic spectra need a hysteretic uniaxial law (e.g. bouc-wen); the material's "
                  "is linear or missing");
          require(law->scales_with_yield_value(),
                  "Material/Bouc-Wen/Uniaxial law",
                  "inelastic spectra set the oscillator's yield force; this law has a yield "
                  "deformation of its own (OpenSees BoucWen: (Ao / (beta + gamma))^(1/n)) and "
                  "ignores it: use OpenSees BoucWenOriginal, smooth, pinching or asymmetric");
        }
    }



    template <int dim>
    double
    Spectrum<dim>::elastic_peak(const double T) const
    {
      // Over a step h with a_g = a0 + (a1 - a0) s / h, u = u_p + u_h: the particular
      // solution of the linear load p = -a_g is c0 + c1 s with c1 = p1 / w^2,
      // c0 = (p0 - 2 zeta w c1) / w^2, and u_h = e^(-zeta w s) (C cos wd s + D sin wd s)
      // takes the initial values (wd = w sqrt(1 - zeta^2)).
      // Steps of the record's (or the input's) step divided into m equal parts, h <= T /
      // `Steps per period`: the load stays linear over each, and the peak between the
      // record's samples is seen (at 10 points per period the sampled peak can be 5 %
      // low).
      const double w = 2 * M_PI / T, z = damping_ratio, wd = w * std::sqrt(1 - z * z);
      const double h = step_for(T);
      const double decay = std::exp(-z * w * h), c = std::cos(wd * h), s = std::sin(wd * h);
      double       u = 0, v = 0, peak = 0, a0 = ground(0);
      const auto   n = static_cast<unsigned long>(std::ceil(ground.duration / h - 1e-9));
      for (unsigned long k = 0; k < n; ++k)
        {
          const double dt = std::min(h, ground.duration - k * h);
          const double a1 = ground(k * h + dt);
          const double p0 = -a0, p1 = -(a1 - a0) / dt;
          const double c1 = p1 / (w * w), c0 = (p0 - 2 * z * w * c1) / (w * w);
          const double C = u - c0, D = (v - c1 + z * w * C) / wd;
          const double e = dt == h ? decay : std::exp(-z * w * dt);
          const double cs = dt == h ? c : std::cos(wd * dt), sn = dt == h ? s : std::sin(wd * dt);
          u = e * (C * cs + D * sn) + c0 + c1 * dt;
          v = e * ((wd * D - z * w * C) * cs - (wd * C + z * w * D) * sn) + c1;
          peak = std::max(peak, std::abs(u));
          a0   = a1;
        }
      return peak;
    }



    template <int dim>
    double
    Spectrum<dim>::inelastic_peak(const double T, const double yield)
    {
      const double  w   = 2 * M_PI / T;
      ShearBuilding sdof({1.0}, {w * w}, {yield}, damping_ratio,
                         this->get_scene().material("", "Material").uniaxial_spring_law());
      double        peak = 0;
      sdof.integrate(std::cref(ground), step_for(T), ground.duration,
                     [&](double t, double, const ShearBuilding::State &s, const ShearBuilding::Energies &) {
                       peak = std::max(peak, std::abs(s.u[0]));
                       if (signals && t > 0)
                         signals->check(++n_checks, t);
                     });
      ++n_inelastic_runs;
      n_steps += sdof.n_steps;
      return peak;
    }



    template <int dim>
    double
    Spectrum<dim>::strength_for_ductility(const double T, const double elastic_force)
    {
      // mu(f) for the normalised strength f = F_y / F_el: search down a grid from 1 for
      // the first f whose demand reaches the target, then bisect between it and the
      // grid point above (the largest such strength; mu(f) need not be monotonic).
      const double k  = std::pow(2 * M_PI / T, 2);
      const auto   mu = [&](const double f) {
        const double yield = f * elastic_force;
        return inelastic_peak(T, yield) * k / yield;
      };
      double above = 1, below = 0;
      for (unsigned int j = 1; j <= 40; ++j)
        {
          const double f = std::pow(0.02, j / 40.0); // 1 ... 0.02, log-spaced
          if (mu(f) >= ductility)
            {
              below = f;
              break;
            }
          above = f;
        }
      if (below == 0)
        return 0; // not reached even at 2 % of the elastic strength
      while (above - below > 1e-4 * above)
        {
          const double f = 0.5 * (above + below);
          (mu(f) >= ductility ? below : above) = f;
        }
      return below * elastic_force;
    }



    template <int dim>
    void
    Spectrum<dim>::run()
    {
      const Scene<dim>        &scene = this->get_scene();
      std::vector<std::string> columns{"T", "Sd", "Sv", "Sa"};
      if (reduction > 0)
        columns.insert(columns.end(), {"Sd_R", "mu_R", "Ay_R"});
      if (ductility > 0)
        columns.insert(columns.end(), {"Ay_mu", "Sd_mu", "R_mu"});
      std::vector<std::vector<double>> rows;
      SignalGuard guard(scene.run_options(), scene.mpi_communicator(), this->run_record(), "spectrum");
      signals = &guard;
      Progress progress(scene.console(), "spectrum (t: the period)", periods.back(),
                        scene.output_control().progress_interval);
      {
        dealii::TimerOutput::Scope timing(scene.timer(), "oscillators");
        for (const double T : periods)
          {
            const double w  = 2 * M_PI / T;
            const double Sd = elastic_peak(T);
            std::vector<double> row{T, Sd, w * Sd, w * w * Sd};
            const double F_el = w * w * Sd; // unit mass
            if (reduction > 0)
              {
                const double yield = F_el / reduction;
                const double peak  = inelastic_peak(T, yield);
                row.insert(row.end(), {peak, peak * w * w / yield, yield});
              }
            if (ductility > 0)
              {
                const double yield = strength_for_ductility(T, F_el);
                row.insert(row.end(), {yield, yield > 0 ? ductility * yield / (w * w) : 0.0,
                                       yield > 0 ? F_el / yield : 0.0});
              }
            rows.push_back(row);
            progress.update(rows.size(), T);
            signals->check(++n_checks, T);
          }
      }
      progress.finish(rows.size(), periods.back());
      signals = nullptr;
      dealii::TimerOutput::Scope output_timing(scene.timer(), "output");
      if (!scene.is_root())
        return;
      Output::CsvWriter out(this->output_file("spectrum.csv"), columns, &this->run_record());
      for (const auto &row : rows)
        out.add_row(row);
      out.commit();
      write_plot(columns);
    }



    template <int dim>
    void
    Spectrum<dim>::write_plot(const std::vector<std::string> &columns) const
    {
      // Sa (and the yield pseudo-accelerations) against T, drawn by gnuplot.
      const std::string script = this->output_file("spectrum.gp");
      {
        Output::AtomicFile file(script, &this->run_record());
        std::ostream      &gp = file.stream();
        gp << "set terminal pngcairo size 900,600 noenhanced\n"
           << "set output 'spectrum.png.tmp'\n"
           << "set datafile separator ','\n"
           << "set key autotitle columnhead\n"
           << "set xlabel 'period T [s]'\nset ylabel 'pseudo-acceleration [m/s^2]'\n"
           << "set title 'Response spectra, damping ratio " << damping_ratio << "'\nset grid\n"
           << (periods.size() == 1 ? "set xrange [" + std::to_string(0.5 * periods[0]) + ":" +
                                          std::to_string(1.5 * periods[0]) + "]\n" :
                                        std::string())
           << "plot 'spectrum.csv' using 1:4 with linespoints lw 2 title 'Sa (elastic)'";
        for (unsigned int c = 4; c < columns.size(); ++c)
          if (columns[c] == "Ay_R" || columns[c] == "Ay_mu")
            gp << ", '' using 1:" << c + 1 << " with linespoints lw 2 title '" << columns[c]
               << (columns[c] == "Ay_R" ? " (R = " : " (mu = ") << (columns[c] == "Ay_R" ? reduction : ductility)
               << ")'";
        gp << "\n";
        file.commit();
      }
      const std::string warning = Plot::run_gnuplot(script, "spectrum.png", 60, &this->run_record());
      if (!warning.empty())
        std::cerr << "hysteron: warning: " << warning << std::endl;
    }



    template <int dim>
    std::string
    Spectrum<dim>::summary() const
    {
      std::ostringstream s;
      s << periods.size() << " periods";
      if (n_inelastic_runs > 0)
        s << ", " << n_inelastic_runs << " inelastic oscillators (" << n_steps << " steps)";
      return s.str();
    }

    template class Spectrum<2>;
    template class Spectrum<3>;
  } // namespace Oscillator
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::Oscillator::Spectrum,
                         "spectrum",
                         "elastic and inelastic response spectra of a ground motion (single "
                         "oscillators of the Material's uniaxial law); writes spectrum.csv and "
                         "spectrum.png")
