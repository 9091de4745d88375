#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>

#include "compare/compare.h"

#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace hysteron
{
  namespace Methods
  {
    /**
     * `set Method = compare` (or `hysteron --compare scene.prm`): run the scene
     * with two field methods (default: mpm and fem), each writing into its own
     * subdirectory of `Output/Directory`, then compare the tables both wrote
     * (probes, averages, reactions, energy) side by side in `compare/`: CSV and
     * a summary of the max and relative L2 differences (timer section
     * "compare"), then the PNGs, drawn by gnuplot on rank 0 (timer section
     * "compare plots"; see doc/compare.md). Every parameter of the scene is
     * shared; each method reads its own subsection (`MPM`, `FEM`).
     */
    template <int dim>
    class Compare : public Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.enter_subsection("Compare");
        prm.declare_entry("Methods",
                          "mpm, fem",
                          dealii::Patterns::List(dealii::Patterns::Anything(), 2, 2),
                          "The two methods that run the scene (A, B): registered field methods "
                          "such as mpm and fem. Differences are B - A, relative to A.");
        prm.declare_entry("Plot columns",
                          "",
                          dealii::Patterns::List(dealii::Patterns::Anything()),
                          "Columns drawn in the PNG of every table (those a table has); empty: "
                          "displacements, von Mises stress, stresses and state variables that "
                          "change (at most 12).");
        prm.declare_entry("Plot timeout",
                          "60",
                          dealii::Patterns::Double(),
                          "Seconds gnuplot may take for one PNG, > 0; then it is killed and the "
                          "run goes on without that PNG, with a warning (the tables and "
                          "summary.md are written before the plots).");
        prm.leave_subsection();
      }

      void
      setup() override
      {
        // The methods write into this run's directory: its files, its record.
        for (auto &method : methods)
          {
            method->set_run_context(this->inputs(), this->resume_from(), this->run_record());
            method->setup();
          }
      }

      /// The compared methods are field methods: a material must serve a continuum.
      bool
      takes_continuum_materials() const override
      {
        return true;
      }

      std::string
      check_size() override
      {
        for (auto &method : methods)
          if (std::string problem = method->check_size(); !problem.empty())
            return problem;
        return "";
      }

      void
      run() override
      {
        const Scene<dim> &scene = this->get_scene();
        // Subdirectories first (rank 0), then the runs one after the other.
        on_root([&]() {
          for (const auto &name : names)
            Output::prepare_directory(this->output_file(name), "Output/Directory");
        });
        for (unsigned int m = 0; m < 2; ++m)
          {
            scene.console() << "compare: running '" << names[m] << "' into "
                            << this->output_file(names[m]) << "/" << std::endl;
            try
              {
                methods[m]->run();
              }
            catch (const Interrupted &e)
              {
                // The method's own message offers --resume, which a comparison cannot do
                // (checkpoint_unsupported()): its tables up to here stay, the run starts anew.
                const std::string text = e.what();
                throw Interrupted(text.substr(0, text.find("; the state was written")) + " ('" + names[m] +
                                  "' of a comparison); its tables up to here are written. A comparison "
                                  "cannot be resumed: run the scene again");
              }
            summaries[m] = methods[m]->summary();
          }

        // The tables, the norms and the summaries, then the plots: on rank 0, every rank
        // timing the same sections.
        ::hysteron::Compare::Options options;
        options.plot_columns = plot_columns;
        options.plots        = false;
        options.plot_timeout = plot_timeout;
        options.record       = &this->run_record();
        options.progress     = [&scene](const std::string &line) {
          scene.console() << line << std::endl;
        };
        ::hysteron::Compare::ComparisonReport report;
        {
          dealii::TimerOutput::Scope timing(scene.timer(), "compare");
          on_root([&]() {
            report = ::hysteron::Compare::compare_directories(this->output_file(names[0]),
                                                              labels[0],
                                                              this->output_file(names[1]),
                                                              labels[1],
                                                              table_files(),
                                                              this->output_file("compare"),
                                                              options);
          });
        }
        print_warnings(report, 0);
        if (scene.is_root())
          print_differences(report);

        const std::size_t n_warnings = report.warnings.size();
        {
          dealii::TimerOutput::Scope timing(scene.timer(), "compare plots");
          on_root([&]() { ::hysteron::Compare::write_plots(report, options); });
        }
        print_warnings(report, n_warnings);
        scene.console() << "compare: tables, plots and summary.md in "
                        << this->output_file("compare") << "/" << std::endl;
      }

      std::string
      summary() const override
      {
        return labels[0] + ": " + summaries[0] + "; " + labels[1] + ": " + summaries[1];
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        std::string where;
        {
          Section s(prm, {"Compare"});
          where = s.where("Methods");
          names = s.get_list("Methods");
          require(names.size() == 2 && names[0] != names[1],
                  s.where("Methods"),
                  "needs two different methods (got '" + s.get("Methods") + "')");
          for (const auto &name : names)
            require(name != "compare" && name != "material point" && name != "uniaxial",
                    s.where("Methods"),
                    "'" + name + "' is not a field method that writes probe tables");
          plot_columns = s.get_list("Plot columns");
          plot_timeout = s.get_positive("Plot timeout");
        }
        // Each method reads its own subsections (from the top level).
        for (unsigned int m = 0; m < 2; ++m)
          {
            methods[m] = Registry<dim>::create(names[m], where);
            methods[m]->set_output_subdirectory(names[m]);
            methods[m]->initialize(this->get_scene(), prm);
            labels[m] = names[m] == "mpm"  ? "MPM" :
                        names[m] == "fem"  ? "FEM" :
                        names[m] == "rbsn" ? "RBSN" :
                                             names[m];
          }
      }

    private:
      /// Run @p work on rank 0; an InputError or RuntimeError there is thrown on every rank.
      void
      on_root(const std::function<void()> &work) const
      {
        const Scene<dim> &scene = this->get_scene();
        // kind: 0 none, 1 InputError (where, problem), 2 RuntimeError (problem).
        int         kind = 0;
        std::string where, problem;
        if (scene.is_root())
          try
            {
              work();
            }
          catch (const InputError &e)
            {
              kind    = 1;
              where   = e.where();
              problem = e.problem();
            }
          catch (const RuntimeError &e)
            {
              kind    = 2;
              problem = e.what();
            }
        const MPI_Comm comm = scene.mpi_communicator();
        kind                = dealii::Utilities::MPI::broadcast(comm, kind, 0);
        if (kind == 0)
          return;
        where   = dealii::Utilities::MPI::broadcast(comm, where, 0);
        problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
        if (kind == 1)
          throw InputError(where, problem);
        throw RuntimeError(problem);
      }

      /// The tables every field method writes.
      std::vector<std::string>
      table_files() const
      {
        const auto              &output = this->get_scene().output_control();
        std::vector<std::string> files;
        for (unsigned int i = 0; i < output.probe_points.size(); ++i)
          files.push_back("probe_" + std::to_string(i) + ".csv");
        for (unsigned int i = 0; i < output.average_regions.size(); ++i)
          files.push_back("average_" + std::to_string(i) + ".csv");
        files.push_back("reactions.csv");
        files.push_back("energy.csv");
        return files;
      }

      /// The warnings of @p report from the @p first one on (rank 0 has them).
      static void
      print_warnings(const ::hysteron::Compare::ComparisonReport &report, const std::size_t first)
      {
        for (std::size_t i = first; i < report.warnings.size(); ++i)
          std::cerr << "hysteron: warning: compare: " << report.warnings[i] << std::endl;
      }

      /**
       * On the console, per table: the max relative difference of von Mises and the
       * displacements of the point tables, of every column of the others that is not
       * negligible against the table's largest.
       */
      void
      print_differences(const ::hysteron::Compare::ComparisonReport &report) const
      {
        std::ostringstream out;
        out << "compare: max |" << labels[1] << " - " << labels[0] << "| relative to max |"
            << labels[0] << "| of each column (all columns: summary.md)\n";
        for (const auto &table : report.tables)
          {
            double largest = 0;
            for (const auto &d : table.differences)
              largest = std::max(largest, d.scale);
            const bool point_table =
              table.name.rfind("probe_", 0) == 0 || table.name.rfind("average_", 0) == 0;
            out << "  " << table.name << ":";
            for (const auto &d : table.differences)
              {
                const bool shown = point_table
                                     ? (d.column == "von_mises" || d.column.rfind("u_", 0) == 0)
                                     : d.scale > 1e-6 * largest;
                if (shown && !d.constant)
                  out << " " << d.column << " " << std::setprecision(3)
                      << 100 * d.max_relative_difference << " %";
              }
            out << "\n";
          }
        this->get_scene().console() << out.str() << std::flush;
      }

      std::vector<std::string>        names;
      std::string                     labels[2];
      std::vector<std::string>        plot_columns;
      double                          plot_timeout = 60;
      std::unique_ptr<Interface<dim>> methods[2];
      std::string                     summaries[2];
    };
  } // namespace Methods
} // namespace hysteron

HYSTERON_REGISTER_METHOD(
  hysteron::Methods::Compare,
  "compare",
  "run the scene with two field methods (Compare/Methods, default mpm and "
  "fem) and compare their probe, average, reaction and energy tables side by "
  "side (CSV, PNG, summary); also `hysteron --compare scene.prm`");
