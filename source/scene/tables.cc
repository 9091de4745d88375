#include <deal.II/base/mpi.h>

#include "base/plotter.h"
#include <hysteron/scene/scene.h>
#include <hysteron/scene/tables.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace hysteron
{
  namespace PointData
  {
    template <int dim>
    void
    Tables<dim>::open(const Scene<dim>               &scene,
                      const std::string              &directory,
                      const std::vector<std::string> &point,
                      Output::RunRecord              &run_record,
                      const bool                      with_damping_work)
    {
      record           = &run_record;
      damping_column   = with_damping_work;
      n_values         = point.size();
      point_names      = point;
      reaction_names   = reaction_columns(scene);
      ground           = scene.ground_motion().empty() ? nullptr : &scene.ground_motion();
      n_boundaries     = scene.boundary_descriptions().size();
      history_names.clear();
      for (const unsigned int k : scene.output_control().history_sets)
        history_names.push_back(scene.set_descriptions()[k].name);
      if (!scene.is_root())
        return;
      const auto file = [&](const std::string &name) { return directory + "/" + name; };
      for (unsigned int i = 0; i < scene.output_control().probe_points.size(); ++i)
        {
          std::vector<std::string> c{"time"};
          c.insert(c.end(), point.begin(), point.end());
          if (ground)
            for (unsigned int d = 0; d < dim; ++d)
              c.push_back(std::string("a_") + component_names[d]);
          probe_tables.push_back(
            std::make_unique<Output::TimeTable>(file("probe_" + std::to_string(i) + ".csv"), c, run_record));
        }
      for (unsigned int i = 0; i < scene.output_control().average_regions.size(); ++i)
        {
          std::vector<std::string> c{"time", "mass"};
          c.insert(c.end(), point.begin(), point.end());
          average_tables.push_back(
            std::make_unique<Output::TimeTable>(file("average_" + std::to_string(i) + ".csv"), c, run_record));
        }
      energy_table   = std::make_unique<Output::TimeTable>(file("energy.csv"), energy_columns(damping_column), run_record);
      reaction_table =
        std::make_unique<Output::TimeTable>(file("reactions.csv"), reaction_columns(scene), run_record);
      if (ground)
        {
          std::vector<std::string> c{"time", "a_g", "v_g", "d_g"};
          for (unsigned int d = 0; d < dim; ++d)
            c.push_back(std::string("base_") + component_names[d]);
          ground_table = std::make_unique<Output::TimeTable>(file("ground.csv"), c, run_record);
        }
      std::vector<std::string> c{"time"};
      for (const auto &name : history_columns())
        c.push_back(name);
      for (const auto &name : history_names)
        {
          history_paths.push_back(file("history_" + name + ".csv"));
          history_tables.push_back(std::make_unique<Output::TimeTable>(history_paths.back(), c, run_record));
        }
    }



    template <int dim>
    std::vector<std::string>
    Tables<dim>::history_columns()
    {
      std::vector<std::string> c;
      for (const std::string quantity : {"u", "reaction", "load"})
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back(quantity + "_" + "xyz"[d]);
      return c;
    }



    template <int dim>
    std::vector<std::string>
    Tables<dim>::draw_histories(const double timeout) const
    {
      namespace fs = std::filesystem;
      std::vector<std::string> warnings;
      for (unsigned int i = 0; i < history_paths.size(); ++i)
        {
          const auto &range = history_ranges[i];
          if (range.empty())
            continue; // no row
          const auto span = [&](const unsigned int column) {
            return range[column].second - range[column].first;
          };
          // The direction where force times displacement varies most, and its force; a set
          // that does not move (a support): the force that varies most against time.
          unsigned int c = 0;
          double       best = -1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double work = span(d) * std::max(span(dim + d), span(2 * dim + d));
              if (work > best)
                {
                  best = work;
                  c    = d;
                }
            }
          const bool against_time = best <= 0;
          if (against_time)
            for (unsigned int d = 0; d < dim; ++d)
              if (std::max(span(dim + d), span(2 * dim + d)) > std::max(span(dim + c), span(2 * dim + c)))
                c = d;
          const bool         reaction = span(dim + c) >= span(2 * dim + c);
          const unsigned int force    = (reaction ? dim : 2 * dim) + c;
          const fs::path     csv(history_paths[i]);
          const std::string  stem = csv.stem().string();
          const std::string  axis = std::string(1, "xyz"[c]);
          const std::string  name = reaction ? "reaction_" + axis : "load_" + axis;
          // Columns of the CSV: 1 time, then history_columns().
          std::ofstream gp(csv.parent_path() / (stem + ".gp"));
          gp << "# The load-displacement curve of " << csv.filename().string() << " (gnuplot " << stem << ".gp)\n"
             << "set terminal pngcairo noenhanced size 800,600\n"
             << "set output '" << stem << ".png.tmp'\n"
             << "set datafile separator ','\n"
             << "set grid\n"
             << "set key top left\n"
             << "set title 'set " << history_names[i] << ": " << name << " against "
             << (against_time ? "time" : "u_" + axis) << "'\n"
             << "set xlabel '" << (against_time ? "time [s]" : "u_" + axis + " (mean over the set) [m]") << "'\n"
             << "set ylabel '" << name << " [N]'\n"
             << "plot '" << csv.filename().string() << "' skip 1 using " << (against_time ? 1 : 2 + c) << ":"
             << 2 + force
             << " with linespoints pointtype 7 pointsize 0.5 title '" << name << "'\n"
             << "set output\n";
          gp.close();
          const std::string warning =
            Plot::run_gnuplot((csv.parent_path() / (stem + ".gp")).string(), stem + ".png", timeout, record);
          if (!warning.empty())
            warnings.push_back(warning);
        }
      return warnings;
    }



    template <int dim>
    void
    Tables<dim>::write(const double                        t,
                       std::vector<double>                &probes,
                       std::vector<double>                &averages,
                       std::array<double, 5>               energies,
                       std::vector<dealii::Tensor<1, dim>> reactions,
                       const MPI_Comm                      comm,
                       std::vector<double>                 histories,
                       double                              damping_work)
    {
      const unsigned int n_history = 3 * dim;
      AssertThrow(histories.size() == history_names.size() * n_history,
                  dealii::ExcMessage("history rows of " + std::to_string(histories.size()) +
                                     " values for " + std::to_string(history_names.size()) + " sets"));
      if (has_written && t == last_time)
        return;
      has_written = true;
      last_time   = t;
      const std::size_t n_probes = probes.size() / std::max(1u, n_values);
      if (!ground)
        probe_accelerations.clear();
      AssertThrow(!ground || probe_accelerations.size() == n_probes * dim,
                  dealii::ExcMessage("a run with a ground motion needs the probes' accelerations "
                                     "(set_probe_accelerations()) before each row"));
      // One reduction of everything, and none on one rank.
      if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
        {
          std::vector<double> all(probes);
          all.insert(all.end(), averages.begin(), averages.end());
          all.insert(all.end(), energies.begin(), energies.end());
          for (const auto &r : reactions)
            for (unsigned int d = 0; d < dim; ++d)
              all.push_back(r[d]);
          all.insert(all.end(), histories.begin(), histories.end());
          all.insert(all.end(), probe_accelerations.begin(), probe_accelerations.end());
          all.push_back(damping_work);
          dealii::Utilities::MPI::sum(all, comm, all);
          auto p = all.begin();
          std::copy(p, p + probes.size(), probes.begin());
          p += probes.size();
          std::copy(p, p + averages.size(), averages.begin());
          p += averages.size();
          std::copy(p, p + 5, energies.begin());
          p += 5;
          for (auto &r : reactions)
            for (unsigned int d = 0; d < dim; ++d)
              r[d] = *p++;
          std::copy(p, p + histories.size(), histories.begin());
          p += histories.size();
          std::copy(p, p + probe_accelerations.size(), probe_accelerations.begin());
          damping_work = p[probe_accelerations.size()];
        }
      // The rows on every rank (the values are the same after the reduction), so that
      // a non-finite value stops every rank.
      std::vector<std::vector<double>> probe_rows, average_rows;
      std::vector<std::string>         names{"time"};
      names.insert(names.end(), point_names.begin(), point_names.end());
      // The ground's motion along Direction, the absolute accelerations a + a_g d.
      const double a_g = ground ? ground->acceleration(t) : 0.0;
      if (ground)
        names.insert(names.end(), {"a_x", "a_y", "a_z"});
      for (unsigned int i = 0; i < n_probes; ++i)
        {
          std::vector<double> row{t};
          row.insert(row.end(), probes.begin() + i * n_values, probes.begin() + (i + 1) * n_values);
          if (ground)
            for (unsigned int d = 0; d < dim; ++d)
              row.push_back(probe_accelerations[i * dim + d] + a_g * ground->direction()[d]);
          check_finite(t, row, "probe_" + std::to_string(i) + ".csv", names);
          probe_rows.push_back(std::move(row));
        }
      if (ground)
        names.resize(names.size() - 3);
      names.insert(names.begin() + 1, "mass");
      for (unsigned int i = 0; i < averages.size() / (1 + n_values); ++i)
        {
          const double       *a = averages.data() + i * (1 + n_values);
          std::vector<double> row{t, a[0]};
          for (unsigned int c = 0; c < n_values; ++c)
            row.push_back(a[0] > 0 ? a[1 + c] / a[0] : 0.0);
          check_finite(t, row, "average_" + std::to_string(i) + ".csv", names);
          average_rows.push_back(std::move(row));
        }
      std::vector<double> energy_row =
        energy_log.row(t, energies[0], energies[1], energies[2], energies[3], energies[4], damping_work);
      if (damping_column)
        energy_row.insert(energy_row.end() - 1, damping_work);
      check_finite(t, energy_row, "energy.csv", energy_columns(damping_column));
      std::vector<double> reaction_row{t};
      for (const auto &r : reactions)
        for (unsigned int d = 0; d < dim; ++d)
          reaction_row.push_back(r[d]);
      check_finite(t, reaction_row, "reactions.csv", reaction_names);
      std::vector<double> ground_row;
      if (ground)
        {
          ground_row = {t, a_g, ground->velocity(t), ground->displacement(t)};
          for (unsigned int d = 0; d < dim; ++d)
            {
              double base = 0;
              for (unsigned int b = 0; b < n_boundaries; ++b)
                base += reactions[b][d];
              ground_row.push_back(base);
            }
          probe_accelerations.clear(); // each row needs its own
        }
      std::vector<std::vector<double>> history_rows;
      std::vector<std::string>         history_header{"time"};
      for (const auto &name : history_columns())
        history_header.push_back(name);
      for (unsigned int i = 0; i < history_names.size(); ++i)
        {
          std::vector<double> row{t};
          row.insert(row.end(), histories.begin() + i * n_history, histories.begin() + (i + 1) * n_history);
          check_finite(t, row, "history_" + history_names[i] + ".csv", history_header);
          history_rows.push_back(std::move(row));
        }

      // Only the scene's root opened the tables (comm may be a method's own, e.g.
      // MPI_COMM_SELF for a method that every rank runs whole).
      if (energy_table == nullptr)
        return;
      for (unsigned int i = 0; i < probe_tables.size(); ++i)
        probe_tables[i]->add_row(probe_rows[i]);
      for (unsigned int i = 0; i < average_tables.size(); ++i)
        average_tables[i]->add_row(average_rows[i]);
      energy_table->add_row(energy_row);
      reaction_table->add_row(reaction_row);
      if (ground_table)
        ground_table->add_row(ground_row);
      history_ranges.resize(history_tables.size());
      for (unsigned int i = 0; i < history_tables.size(); ++i)
        {
          history_tables[i]->add_row(history_rows[i]);
          auto &range = history_ranges[i];
          if (range.empty())
            for (unsigned int c = 1; c < history_rows[i].size(); ++c)
              range.emplace_back(history_rows[i][c], history_rows[i][c]);
          for (unsigned int c = 1; c < history_rows[i].size(); ++c)
            {
              range[c - 1].first  = std::min(range[c - 1].first, history_rows[i][c]);
              range[c - 1].second = std::max(range[c - 1].second, history_rows[i][c]);
            }
        }
    }



    template <int dim>
    void
    Tables<dim>::check_finite(const double                    t,
                              const std::vector<double>      &row,
                              const std::string              &table,
                              const std::vector<std::string> &names)
    {
      for (unsigned int c = 0; c < row.size(); ++c)
        if (!std::isfinite(row[c]))
          {
            std::ostringstream m;
            m << table << ": " << (c < names.size() ? names[c] : "column " + std::to_string(c)) << " = "
              << row[c] << " at t = " << t
              << " s: the solution overflowed or became NaN (the tables hold every row before). "
                 "Check the magnitudes and units of the scene: material constants, loads, "
                 "prescribed motions";
            throw RuntimeError(m.str());
          }
    }



    template <int dim>
    void
    Tables<dim>::flush()
    {
      for (auto &table : probe_tables)
        table->flush();
      for (auto &table : average_tables)
        table->flush();
      for (auto &table : history_tables)
        table->flush();
      for (auto *table : {energy_table.get(), reaction_table.get(), ground_table.get()})
        if (table)
          table->flush();
    }



    template <int dim>
    template <class Archive>
    void
    Tables<dim>::serialize(Archive &ar)
    {
      ar.section("tables", 2); // raise with every change of what it stores
      auto energy = energy_log.state();
      ar &has_written &last_time &energy;
      if constexpr (Archive::is_loading)
        energy_log.restore(energy);
    }



    template void Tables<2>::serialize(CheckpointWriter &);
    template void Tables<3>::serialize(CheckpointWriter &);
    template void Tables<2>::serialize(CheckpointReader &);
    template void Tables<3>::serialize(CheckpointReader &);
    template class Tables<2>;
    template class Tables<3>;
  } // namespace PointData
} // namespace hysteron
