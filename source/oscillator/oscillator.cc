// The oscillator method: its parameters, the ground input of the oscillator and
// spectrum methods, and the run with its tables.
#include <deal.II/base/utilities.h>

#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include "base/progress.h"
#include "base/run_record.h"
#include "oscillator/oscillator.h"
#include "run/signals.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace hysteron
{
  namespace Oscillator
  {
    SignalGuard::SignalGuard(const RunOptions &options, MPI_Comm comm, Output::RunRecord &record, std::string label)
      : options(options)
      , comm(comm)
      , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
      , record(record)
      , label(std::move(label))
    {
      Run::install_signal_handlers();
    }



    SignalGuard::~SignalGuard()
    {
      Run::restore_signal_handlers();
    }



    void
    SignalGuard::check(const unsigned long step, const double t)
    {
      Run::test_signal_after_step(options.test_signal, step, record);
      bool      due    = false;
      const int signal = Run::received_signal(comm, n_ranks, due);
      if (signal == 0)
        return;
      record.flush_tables();
      std::ostringstream m;
      m << (signal == SIGINT ? "SIGINT" : "SIGTERM") << " received: " << label << " stopped after step " << step
        << " at t = " << t << " s; the tables written so far hold whole rows (this method writes "
        << "no checkpoint: run the scene again)";
      throw Interrupted(m.str());
    }



    std::vector<double>
    positive_list(const Section &s, const std::string &entry, const unsigned int n)
    {
      const std::vector<std::string> items = s.get_list(entry);
      require(items.size() == n || items.size() == 1,
              s.where(entry),
              "needs one value per storey (" + std::to_string(n) + ", as many as Masses) or one for "
              "all; got " + std::to_string(items.size()));
      std::vector<double> values;
      for (const auto &item : items)
        {
          char        *end = nullptr;
          const double x   = std::strtod(item.c_str(), &end);
          require(end == item.c_str() + item.size() && std::isfinite(x) && x > 0,
                  s.where(entry),
                  "'" + item + "' is not a positive number");
          values.push_back(x);
        }
      values.resize(n, values.back());
      return values;
    }



    void
    GroundInput::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.declare_entry("Ground acceleration",
                        "",
                        Patterns::Anything(),
                        "The ground's acceleration a_g(t) [m/s^2] as an expression of t (muParser), "
                        "instead of a record in `Ground motion/File` (e.g. a harmonic or a pulse).");
      prm.declare_entry("Time step",
                        "0",
                        Patterns::Double(),
                        "[s], >= 0; 0: the record's sampling step (needed without a record).");
      prm.declare_entry("Duration",
                        "0",
                        Patterns::Double(),
                        "The analysed time [s], >= 0 (longer than the record: free vibration after "
                        "it); 0: to the record's last sample (needed without a record). The "
                        "top-level `End time` is not read.");
    }



    template <int dim>
    void
    GroundInput::parse(dealii::ParameterHandler &prm,
                       const Scene<dim>         &scene,
                       const std::string        &section,
                       const bool                needs_record)
    {
      record = scene.ground_motion();
      Section           s(prm, {section});
      const std::string text = dealii::Utilities::trim(s.get("Ground acceleration"));
      time_step              = s.get_non_negative("Time step");
      duration               = s.get_non_negative("Duration");
      require(record.empty() || text.empty(),
              s.where("Ground acceleration"),
              "give the ground motion either as a record (Ground motion/File) or as this "
              "expression, not both");
      require(!needs_record || !record.empty(), "Ground motion/File", "the " + section + " method needs a record");
      require(!record.empty() || !text.empty(),
              s.where("Ground acceleration"),
              "needs a ground motion: a record in Ground motion/File, or this expression");
      if (record.empty())
        {
          require(time_step > 0, s.where("Time step"), "must be > 0 without a record");
          require(duration > 0, s.where("Duration"), "must be > 0 without a record");
          expression = parse_function<1>(text, "t", false, s.where("Ground acceleration"));
          check_finite_in_time(*expression, duration);
        }
      else
        {
          if (time_step == 0)
            time_step = record.time_step();
          if (duration == 0)
            duration = record.end_time();
        }
      require(duration >= time_step, s.where("Duration"), "must be at least one Time step");
      require(duration / time_step <= 1e8,
              s.where("Duration"),
              "makes more than 10^8 steps of " + std::to_string(time_step) + " s (every one a row of the "
              "tables)");
    }



    template <int dim>
    void
    Method<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Oscillator");
      {
        prm.declare_entry("Masses",
                          "1",
                          Patterns::Anything(),
                          "The floors' masses [kg], ground up, comma separated: N values make N "
                          "storeys (one value: the single-degree-of-freedom oscillator).");
        prm.declare_entry("Stiffnesses",
                          "1",
                          Patterns::Anything(),
                          "The storeys' elastic stiffnesses k [N/m], ground up: one per storey or one "
                          "for all. A storey follows the uniaxial spring law of `Material` with k in "
                          "place of Young's modulus (the material's own E and yield stress are not "
                          "read).");
        prm.declare_entry("Yield forces",
                          "",
                          Patterns::Anything(),
                          "The storeys' yield forces F_y [N] (in place of the yield stress): one per "
                          "storey or one for all; needed by a hysteretic Material (bouc-wen), "
                          "refused with a linear elastic one and with `Uniaxial law = OpenSees "
                          "BoucWen` (whose yield deformation is its own).");
        prm.declare_entry("Damping ratio",
                          "0.05",
                          Patterns::Double(),
                          "zeta in [0, 1): Rayleigh damping C = alpha M + beta K_0 with the ratio zeta "
                          "in the first two modes of the elastic building; one storey: "
                          "mass-proportional, c = 2 zeta omega m.");
        GroundInput::declare_parameters(prm);
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Method<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      ground.parse(prm, this->get_scene(), "Oscillator", false);
      Section                        s(prm, {"Oscillator"});
      const std::vector<std::string> masses = s.get_list("Masses");
      require(!masses.empty() && masses.size() <= 100000, s.where("Masses"), "needs 1 to 100,000 values");
      mass          = positive_list(s, "Masses", masses.size());
      stiffness     = positive_list(s, "Stiffnesses", mass.size());
      damping_ratio = s.get_double("Damping ratio");
      require(damping_ratio >= 0 && damping_ratio < 1, s.where("Damping ratio"), "must be in [0, 1)");
      const auto law = this->get_scene().material("", "Material").uniaxial_spring_law();
      require(law != nullptr,
              "Material/Model",
              "the oscillator's storeys follow the material's uniaxial spring law, which this model "
              "does not offer (bouc-wen and linear elastic do)");
      if (!law->linear() && law->scales_with_yield_value())
        {
          require(!s.get_list("Yield forces").empty(),
                  s.where("Yield forces"),
                  "a hysteretic Material needs the storeys' yield forces");
          yield_force = positive_list(s, "Yield forces", mass.size());
        }
      else
        require(s.get_list("Yield forces").empty(),
                s.where("Yield forces"),
                "the material's uniaxial law takes no yield force (linear, or OpenSees BoucWen with "
                "its yield deformation (Ao / (beta + gamma))^(1/n)): leave it empty");
    }



    template <int dim>
    void
    Method<dim>::setup()
    {
      auto law = this->get_scene().material("", "Material").uniaxial_spring_law();
      if (law->linear())
        law.reset();
      building = std::make_unique<ShearBuilding>(mass, stiffness, yield_force, damping_ratio, std::move(law));
      // Newmark's average acceleration is stable at any step, but lengthens a period T
      // by about (pi dt / T)^2 / 3: warn where the shortest one is resolved coarsely, and
      // where the step skips samples of the record.
      if (!this->get_scene().is_root())
        return;
      const double shortest = building->periods().back();
      if (ground.time_step > shortest / 10)
        std::cerr << "hysteron: warning: Oscillator/Time step: " << ground.time_step
                  << " s resolves the shortest period, " << shortest << " s, with fewer than 10 steps "
                  << "(its period errs by about " << 100 * std::pow(M_PI * ground.time_step / shortest, 2) / 3
                  << " %); a step of at most " << shortest / 10 << " s resolves it" << std::endl;
      if (ground.record_step() > 0 && ground.time_step > ground.record_step() * (1 + 1e-9))
        std::cerr << "hysteron: warning: Oscillator/Time step: " << ground.time_step
                  << " s is longer than the record's step, " << ground.record_step()
                  << " s: the samples between the steps are skipped" << std::endl;
    }



    template <int dim>
    std::string
    Method<dim>::check_size()
    {
      // The size of history.csv: a row of 5 N + 1 values per step.
      const double steps = std::ceil(ground.duration / ground.time_step - 1e-9);
      if (steps * mass.size() > 1e9)
        return "Oscillator/Duration: " + std::to_string(steps) + " steps of " + std::to_string(mass.size()) +
               " storeys would write " + std::to_string(steps * mass.size()) + " values per column group "
               "to history.csv (more than 10^9)";
      return "";
    }



    template <int dim>
    std::vector<std::string>
    Method<dim>::history_columns() const
    {
      std::vector<std::string> columns{"t"};
      for (const std::string prefix : {"u_", "v_", "a_", "F_", "z_"})
        for (unsigned int i = 1; i <= mass.size(); ++i)
          columns.push_back(prefix + std::to_string(i));
      return columns;
    }



    template <int dim>
    void
    Method<dim>::run()
    {
      const Scene<dim>  &scene = this->get_scene();
      const unsigned int n     = mass.size();
      peak_drift.assign(n, 0.0);
      peak_force.assign(n, 0.0);
      peak_acceleration.assign(n, 0.0);
      std::unique_ptr<Output::TimeTable> history, energy;
      if (scene.is_root())
        {
          history = std::make_unique<Output::TimeTable>(this->output_file("history.csv"), history_columns(),
                                                        this->run_record());
          energy  = std::make_unique<Output::TimeTable>(
            this->output_file("energy.csv"),
            std::vector<std::string>{"t", "input", "kinetic", "damped", "elastic", "hysteretic", "balance"},
            this->run_record());
        }
      Progress            progress(scene.console(), "oscillator", ground.duration,
                        scene.output_control().progress_interval);
      unsigned long       rows = 0;
      std::vector<double> row(1 + 5 * n);
      ShearBuilding::State last;
      SignalGuard          signals(scene.run_options(), scene.mpi_communicator(), this->run_record(), "oscillator");
      const auto observe = [&](const double t, const double ag, const ShearBuilding::State &s,
                               const ShearBuilding::Energies &e) {
        row[0] = t;
        for (unsigned int i = 0; i < n; ++i)
          {
            row[1 + i]         = s.u[i];
            row[1 + n + i]     = s.v[i];
            row[1 + 2 * n + i] = s.a[i] + ag; // absolute
            row[1 + 3 * n + i] = s.force[i];
            row[1 + 4 * n + i] = building->hysteretic_variable(s, i);
            peak_drift[i]        = std::max(peak_drift[i], std::abs(s.drift[i]));
            peak_force[i]        = std::max(peak_force[i], std::abs(s.force[i]));
            peak_acceleration[i] = std::max(peak_acceleration[i], std::abs(s.a[i] + ag));
          }
        input         = e.input;
        worst_balance = std::max(worst_balance, std::abs(e.balance()));
        if (history)
          {
            history->add_row(row);
            energy->add_row({t, e.input, e.kinetic, e.damped, e.elastic, e.hysteretic, e.balance()});
          }
        if (t == ground.duration)
          last = s;
        progress.update(++rows, t);
        if (rows > 1)
          signals.check(rows - 1, t);
      };
      {
        dealii::TimerOutput::Scope timing(scene.timer(), "oscillator steps");
        building->integrate(std::cref(ground), ground.time_step, ground.duration, observe);
      }
      progress.finish(rows, ground.duration);
      dealii::TimerOutput::Scope output_timing(scene.timer(), "output");
      if (history)
        {
          history->flush();
          energy->flush();
          write_summary(last);
        }
    }



    template <int dim>
    void
    Method<dim>::write_summary(const ShearBuilding::State &last) const
    {
      // Per storey: the peaks over the steps, the drift at the end and the ductility
      // demand, peak drift over the yield drift F_y / k (0 for linear storeys).
      Output::CsvWriter storeys(this->output_file("summary.csv"),
                                {"storey", "peak_drift", "residual_drift", "ductility", "peak_force",
                                 "peak_absolute_acceleration"},
                                &this->run_record());
      for (unsigned int i = 0; i < mass.size(); ++i)
        storeys.add_row({double(i + 1), peak_drift[i], last.drift[i],
                         building->hysteretic() ? peak_drift[i] * stiffness[i] / yield_force[i] : 0.0,
                         peak_force[i], peak_acceleration[i]});
      storeys.commit();
      Output::CsvWriter modes(this->output_file("modes.csv"), {"mode", "period", "damping_ratio"},
                              &this->run_record());
      const std::vector<double> zeta = building->modal_damping_ratios();
      for (unsigned int j = 0; j < mass.size(); ++j)
        modes.add_row({double(j + 1), building->periods()[j], zeta[j]});
      modes.commit();
    }



    template <int dim>
    std::string
    Method<dim>::summary() const
    {
      std::ostringstream s;
      s << mass.size() << (mass.size() == 1 ? " storey" : " storeys") << " (T_1 = " << building->periods()[0]
        << " s), " << building->n_steps << " steps, " << building->n_newton << " Newton iterations";
      if (building->n_cuts > 0)
        s << ", " << building->n_cuts << " cuts";
      s << "; input energy " << input << " J, balance within " << worst_balance << " J";
      return s.str();
    }

    template void
    GroundInput::parse<2>(dealii::ParameterHandler &, const Scene<2> &, const std::string &, bool);
    template void
    GroundInput::parse<3>(dealii::ParameterHandler &, const Scene<3> &, const std::string &, bool);
    template class Method<2>;
    template class Method<3>;
  } // namespace Oscillator
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::Oscillator::Method,
                         "oscillator",
                         "a shear building of N storeys (N = 1: the single-degree-of-freedom "
                         "oscillator) under a ground acceleration, its storeys with the uniaxial "
                         "law of Material; writes history.csv, energy.csv, summary.csv and modes.csv")
