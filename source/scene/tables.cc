#include <deal.II/base/mpi.h>

#include <hysteron/scene/scene.h>
#include <hysteron/scene/tables.h>

#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace PointData
  {
    template <int dim>
    void
    Tables<dim>::open(const Scene<dim>               &scene,
                      const std::string              &directory,
                      const std::vector<std::string> &point)
    {
      n_values         = point.size();
      point_names      = point;
      reaction_names   = reaction_columns(scene);
      if (!scene.is_root())
        return;
      const auto file = [&](const std::string &name) { return directory + "/" + name; };
      for (unsigned int i = 0; i < scene.output_control().probe_points.size(); ++i)
        {
          std::vector<std::string> c{"time"};
          c.insert(c.end(), point.begin(), point.end());
          probe_tables.push_back(
            std::make_unique<Output::TimeTable>(file("probe_" + std::to_string(i) + ".csv"), c));
        }
      for (unsigned int i = 0; i < scene.output_control().average_regions.size(); ++i)
        {
          std::vector<std::string> c{"time", "mass"};
          c.insert(c.end(), point.begin(), point.end());
          average_tables.push_back(
            std::make_unique<Output::TimeTable>(file("average_" + std::to_string(i) + ".csv"), c));
        }
      energy_table   = std::make_unique<Output::TimeTable>(file("energy.csv"), energy_columns());
      reaction_table = std::make_unique<Output::TimeTable>(file("reactions.csv"), reaction_columns(scene));
    }



    template <int dim>
    void
    Tables<dim>::write(const double                        t,
                       std::vector<double>                &probes,
                       std::vector<double>                &averages,
                       std::array<double, 5>               energies,
                       std::vector<dealii::Tensor<1, dim>> reactions,
                       const MPI_Comm                      comm)
    {
      if (has_written && t == last_time)
        return;
      has_written = true;
      last_time   = t;
      // One reduction of everything, and none on one rank.
      if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
        {
          std::vector<double> all(probes);
          all.insert(all.end(), averages.begin(), averages.end());
          all.insert(all.end(), energies.begin(), energies.end());
          for (const auto &r : reactions)
            for (unsigned int d = 0; d < dim; ++d)
              all.push_back(r[d]);
          MPI_Allreduce(MPI_IN_PLACE, all.data(), all.size(), MPI_DOUBLE, MPI_SUM, comm);
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
        }
      // The rows on every rank (the values are the same after the reduction), so that
      // a non-finite value stops every rank.
      std::vector<std::vector<double>> probe_rows, average_rows;
      std::vector<std::string>         names{"time"};
      names.insert(names.end(), point_names.begin(), point_names.end());
      for (unsigned int i = 0; i < probes.size() / std::max(1u, n_values); ++i)
        {
          std::vector<double> row{t};
          row.insert(row.end(), probes.begin() + i * n_values, probes.begin() + (i + 1) * n_values);
          check_finite(t, row, "probe_" + std::to_string(i) + ".csv", names);
          probe_rows.push_back(std::move(row));
        }
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
      const std::vector<double> energy_row =
        energy_log.row(t, energies[0], energies[1], energies[2], energies[3], energies[4]);
      check_finite(t, energy_row, "energy.csv", energy_columns());
      std::vector<double> reaction_row{t};
      for (const auto &r : reactions)
        for (unsigned int d = 0; d < dim; ++d)
          reaction_row.push_back(r[d]);
      check_finite(t, reaction_row, "reactions.csv", reaction_names);

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
      for (auto *table : {energy_table.get(), reaction_table.get()})
        if (table)
          table->flush();
    }



    template <int dim>
    void
    Tables<dim>::save(CheckpointWriter &out) const
    {
      out.section("tables");
      out.put(has_written);
      out.put(last_time);
      out.put(energy_log.state());
    }



    template <int dim>
    void
    Tables<dim>::load(CheckpointReader &in)
    {
      in.section("tables");
      in.get(has_written);
      in.get(last_time);
      energy_log.restore(in.get<std::array<double, 3>>());
    }



    template class Tables<2>;
    template class Tables<3>;
  } // namespace PointData
} // namespace hysteron
