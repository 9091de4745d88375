#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/compare.h>
#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>

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
     * (probes, averages, reactions, energy) side by side in `compare/`: CSV,
     * PNG and a summary of the max and relative L2 differences (see
     * doc/compare.md). Every parameter of the scene is shared; each method reads
     * its own subsection (`MPM`, `FEM`).
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
        prm.leave_subsection();
      }

      void
      setup() override
      {
        for (auto &method : methods)
          method->setup();
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
        MPI_Comm          comm  = scene.mpi_communicator();
        // Subdirectories first (rank 0), then the runs one after the other.
        std::string problem;
        if (scene.is_root())
          try
            {
              for (const auto &name : names)
                Output::prepare_directory(this->output_file(name), "Output/Directory");
            }
          catch (const InputError &e)
            {
              problem = e.problem();
            }
        problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
        if (!problem.empty())
          throw InputError("Output/Directory", problem);
        for (unsigned int m = 0; m < 2; ++m)
          {
            scene.console() << "compare: running '" << names[m] << "' into "
                            << this->output_file(names[m]) << "/" << std::endl;
            methods[m]->run();
            summaries[m] = methods[m]->summary();
          }

        std::string message;
        if (scene.is_root())
          {
            ::hysteron::Compare::Options options;
            options.plot_columns = plot_columns;
            // The tables every field method writes.
            std::vector<std::string> files;
            for (unsigned int i = 0; i < scene.output_control().probe_points.size(); ++i)
              files.push_back("probe_" + std::to_string(i) + ".csv");
            for (unsigned int i = 0; i < scene.output_control().average_regions.size(); ++i)
              files.push_back("average_" + std::to_string(i) + ".csv");
            files.push_back("reactions.csv");
            files.push_back("energy.csv");
            const auto report    = ::hysteron::Compare::compare_directories(this->output_file(names[0]),
                                                    labels[0],
                                                    this->output_file(names[1]),
                                                    labels[1],
                                                    files,
                                                    this->output_file("compare"),
                                                    options);
            for (const auto &w : report.warnings)
              std::cerr << "hysteron: warning: compare: " << w << std::endl;
            std::ostringstream s;
            s << "compare: max |" << labels[1] << " - " << labels[0] << "| relative to max |"
              << labels[0] << "| of each column (all columns: summary.md)\n";
            // On the console: von Mises and displacements of the point tables, every
            // column of the others that is not negligible against the table's largest.
            for (const auto &table : report.tables)
              {
                double largest = 0;
                for (const auto &d : table.differences)
                  largest = std::max(largest, d.scale);
                const bool point_table = table.name.rfind("probe_", 0) == 0 ||
                                         table.name.rfind("average_", 0) == 0;
                s << "  " << table.name << ":";
                for (const auto &d : table.differences)
                  {
                    const bool shown = point_table ? (d.column == "von_mises" ||
                                                      d.column.rfind("u_", 0) == 0) :
                                                     d.scale > 1e-6 * largest;
                    if (shown && !d.constant)
                      s << " " << d.column << " " << std::setprecision(3)
                        << 100 * d.max_relative_difference << " %";
                  }
                s << "\n";
              }
            s << "compare: tables, plots and summary.md in " << this->output_file("compare") << "/";
            message = s.str();
            n_tables = report.tables.size();
          }
        scene.console() << message << std::endl;
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
        }
        // Each method reads its own subsections (from the top level).
        for (unsigned int m = 0; m < 2; ++m)
          {
            methods[m] = Registry<dim>::create(names[m], where);
            methods[m]->set_output_subdirectory(names[m]);
            methods[m]->initialize(this->get_scene(), prm);
            labels[m] = names[m] == "mpm" ? "MPM" : names[m] == "fem" ? "FEM" : names[m];
          }
      }

    private:
      std::vector<std::string>      names;
      std::string                   labels[2];
      std::vector<std::string>      plot_columns;
      std::unique_ptr<Interface<dim>> methods[2];
      std::string                   summaries[2];
      unsigned int                  n_tables = 0;
    };
  } // namespace Methods
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::Methods::Compare,
                         "compare",
                         "run the scene with two field methods (Compare/Methods, default mpm and "
                         "fem) and compare their probe, average, reaction and energy tables side by "
                         "side (CSV, PNG, summary); also `hysteron --compare scene.prm`");
