// The MPM's outputs: the time tables (probes, averages, energies, reactions), the
// particle table at the end and the particle fields (VTU).
#include <deal.II/base/mpi.h>
#include <deal.II/particles/data_out.h>

#include "mpm/mpm.h"

#include <algorithm>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::open_tables()
    {
      tables.open(this->get_scene(),
                  this->output_directory(),
                  PointData::columns<dim>(state_names, this->get_scene().output_control().additional_columns),
                  this->run_record(),
                  damped());
    }



    template <int dim>
    std::vector<std::string>
    Solver<dim>::point_columns() const
    {
      return PointData::columns<dim>(state_names, this->get_scene().output_control().additional_columns);
    }



    template <int dim>
    void
    Solver<dim>::point_values(const unsigned int s, double *r) const
    {
      const auto &P     = particles;
      const auto *group = &P.groups[0];
      for (const auto &g : P.groups)
        if (s >= g.begin && s < g.end)
          group = &g;
      const double *state = P.current.material_state.data() + group->state_offset +
                            std::size_t(s - group->begin) * group->n_state;
      PointData::values<dim>(P.current.x[s],
                             P.current.x[s] - P.x0[s],
                             P.current.v[s],
                             P.current.stress[s],
                             P.current.strain[s],
                             group->material,
                             view(state, group->n_state),
                             state_names.size(),
                             r,
                             this->get_scene().output_control().additional_columns);
    }



    template <int dim>
    void
    Solver<dim>::write_particle_table() const
    {
      const Scene<dim>  &scene   = this->get_scene();
      const auto         columns = point_columns();
      const unsigned int n       = columns.size() + 2;
      std::vector<double> rows(particles.size() * n);
      for (unsigned int s = 0; s < particles.size(); ++s)
        {
          rows[s * n]     = particles.id[s];
          rows[s * n + 1] = particles.body[s];
          point_values(s, rows.data() + s * n + 2);
        }
      std::vector<std::vector<double>> all{rows};
      if (grid->is_parallel())
        all = dealii::Utilities::MPI::gather(grid->mpi_communicator(), rows, 0);
      if (!scene.is_root())
        return;
      std::vector<std::vector<double>> table;
      for (const auto &part : all)
        for (std::size_t i = 0; i < part.size(); i += n)
          table.emplace_back(part.begin() + i, part.begin() + i + n);
      std::sort(table.begin(), table.end());
      std::vector<std::string> header{"id", "body"};
      header.insert(header.end(), columns.begin(), columns.end());
      Output::CsvWriter out(this->output_file("particles.csv"), header, &this->run_record());
      for (const auto &row : table)
        out.add_row(row);
      out.commit();
    }



    template <int dim>
    void
    Solver<dim>::write_table_rows(const double t)
    {
      using namespace dealii;
      using PI                = PropertiesIndex<dim>;
      const Scene<dim> &scene = this->get_scene();
      const auto       &P     = particles;
      MPI_Comm          comm  = grid->mpi_communicator();

      // Probes: the owner fills its rows, the others contribute zeros.
      const unsigned int  n_values = tables.n_point_values();
      std::vector<double> rows(probes.size() * n_values, 0.0);
      for (unsigned int i = 0; i < probes.size(); ++i)
        if (probes[i].local >= 0)
          point_values(probes[i].local, rows.data() + i * n_values);

      // Mass-weighted averages over the points that started in each region.
      std::vector<double> averages(average_regions.size() * (1 + n_values), 0.0);
      std::vector<double> values(n_values);
      for (unsigned int i = 0; i < average_regions.size(); ++i)
        for (const auto &group : P.groups)
          if (group.material != nullptr)
            for (unsigned int s = group.begin; s < group.end; ++s)
              if (average_regions[i].contains(P.x0[s], 1e-9 * cell_size))
                {
                  double *a = averages.data() + i * (1 + n_values);
                  point_values(s, values.data());
                  a[0] += P.mass[s];
                  for (unsigned int c = 0; c < n_values; ++c)
                    a[1 + c] += P.mass[s] * values[c];
                }

      // Energies of this rank's points: kinetic and elastic strain energy.
      double kinetic = 0, strain_energy = 0;
      for (const auto &group : P.groups)
        for (unsigned int s = group.begin; s < group.end; ++s)
          {
            kinetic += 0.5 * P.mass[s] * P.current.v[s].norm_square();
            if (group.material != nullptr)
              strain_energy +=
                P.current.volume[s] *
                PointData::strain_energy_density(*group.material,
                                                 P.current.stress[s],
                                                 P.current.strain[s],
                                                 view(P.current.material_state.data() +
                                                        group.state_offset +
                                                        std::size_t(s - group.begin) * group.n_state,
                                                      group.n_state));
          }
      // Reactions in the columns of reactions.csv: boundaries, then rigid bodies.
      std::vector<Tensor<1, dim>> r(reactions.begin(), reactions.begin() + boundaries.size());
      const auto                 &bodies = scene.body_descriptions();
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          r.push_back(reactions[boundaries.size() + b]);
      if (!probe_acceleration.empty())
        {
          std::vector<double> a;
          for (const auto &acceleration : probe_acceleration)
            for (unsigned int d = 0; d < dim; ++d)
              a.push_back(acceleration[d]);
          tables.set_probe_accelerations(std::move(a));
        }
      tables.write(t,
                   rows,
                   averages,
                   {{kinetic, strain_energy, internal_work, external_work, boundary_work}},
                   r,
                   comm,
                   {},
                   damping_work);
    }



    template <int dim>
    void
    Solver<dim>::record_probe_accelerations(const double dt)
    {
      // The relative acceleration of each probe's point over the step just taken (before
      // commit()): (v_p' - v_p) / dt, with FLIP sum_i N_ip Delta v_i / dt, the nodes'
      // accelerations after the boundary conditions. A rank that no longer has the point
      // (it migrated after its step) keeps its value until the new owner's next step.
      const auto &P = particles;
      for (unsigned int i = 0; i < probes.size(); ++i)
        probe_acceleration[i] = probes[i].local >= 0 ?
                                  (P.next.v[probes[i].local] - P.current.v[probes[i].local]) / dt :
                                  dealii::Tensor<1, dim>();
    }



    template <int dim>
    void
    Solver<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      to_handler(true); // the points where they are, also on a moving grid
      using PI = PropertiesIndex<dim>;
      std::vector<std::string> names = PI::names(state_names);
      names.resize(n_properties, "unused");
      auto interpretations = PI::interpretations(state_names.size());
      interpretations.resize(n_properties, dealii::DataComponentInterpretation::component_is_scalar);
      dealii::Particles::DataOut<dim> out;
      out.build_patches(*handler, names, interpretations);
      writer.write(out, t);
    }



    template void Solver<2>::open_tables();
    template void Solver<3>::open_tables();
    template std::vector<std::string> Solver<2>::point_columns() const;
    template std::vector<std::string> Solver<3>::point_columns() const;
    template void Solver<2>::point_values(unsigned int, double *) const;
    template void Solver<3>::point_values(unsigned int, double *) const;
    template void Solver<2>::write_particle_table() const;
    template void Solver<3>::write_particle_table() const;
    template void Solver<2>::write_table_rows(double);
    template void Solver<3>::write_table_rows(double);
    template void Solver<2>::record_probe_accelerations(double);
    template void Solver<3>::record_probe_accelerations(double);
    template void Solver<2>::write_fields(double, Output::FieldWriter &);
    template void Solver<3>::write_fields(double, Output::FieldWriter &);
  } // namespace MPM
} // namespace hysteron
