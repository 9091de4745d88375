#include <deal.II/base/exceptions.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/data_out.h>

#include "fem/fem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    Solver<dim>::setup_probes()
    {
      using namespace dealii;
      const Scene<dim>  &scene = this->get_scene();
      MPI_Comm           comm  = scene.mpi_communicator();
      const unsigned int rank  = Utilities::MPI::this_mpi_process(comm);
      probes.clear();
      for (const auto &p : scene.output_control().probe_points)
        {
          Probe probe;
          probe.point = p;
          // The locally owned cell that contains the point (lowest rank wins).
          bool found = false;
          try
            {
              const auto cell_and_point = GridTools::find_active_cell_around_point(*mapping, dof_handler, p);
              if (cell_and_point.first.state() == IteratorState::valid &&
                  cell_and_point.first->is_locally_owned())
                {
                  probe.dof_cell  = cell_and_point.first;
                  probe.reference = GeometryInfo<dim>::project_to_unit_cell(cell_and_point.second);
                  found           = true;
                }
            }
          catch (const dealii::ExceptionBase &)
            {
              // GridTools' "point not found" or the mapping's failed inversion: the point
              // is in none of this rank's cells (another rank may own it; none: below).
            }
          probe.owner = Utilities::MPI::min(found ? rank : numbers::invalid_unsigned_int, comm);
          if (probe.owner == static_cast<int>(numbers::invalid_unsigned_int))
            {
              std::ostringstream s;
              s << p;
              throw InputError("Output/Probe points",
                               "the point (" + s.str() + ") lies outside the fem mesh");
            }
          if (probe.owner != static_cast<int>(rank))
            found = false;
          probe.has_cell = found;

          // The nearest quadrature point (ties: the lowest rank, then the first found).
          double best = std::numeric_limits<double>::max();
          for (const auto &cell : triangulation->active_cell_iterators())
            if (cell->is_locally_owned())
              {
                const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
                for (unsigned int q = 0; q < h.point.size(); ++q)
                  if (h.point[q].distance(p) < best)
                    {
                      best          = h.point[q].distance(p);
                      probe.cell    = cell;
                      probe.q       = q;
                      probe.q_point = h.point[q];
                    }
              }
          const double global_best = Utilities::MPI::min(best, comm);
          const unsigned int q_owner =
            Utilities::MPI::min(best == global_best ? rank : numbers::invalid_unsigned_int, comm);
          probe.has_q = q_owner == rank;
          probes.push_back(probe);
        }
    }



    template <int dim>
    void
    Solver<dim>::open_tables()
    {
      const Scene<dim> &scene = this->get_scene();
      tables.open(scene,
                  this->output_directory(),
                  PointData::columns<dim>(state_names, scene.output_control().additional_columns),
                  this->run_record(),
                  has_rayleigh_damping());
      if (scene.is_root() && analysis != Analysis::explicit_dynamics)
        newton_table = std::make_unique<Output::TimeTable>(this->output_file("newton.csv"),
                                                           newton_columns(),
                                                           this->run_record());
    }



    template <int dim>
    void
    Solver<dim>::log_newton(const double       t1,
                            const double       dt,
                            const unsigned int iteration,
                            const double       residual,
                            const double       alpha)
    {
      if (newton_table)
        newton_table->add_row(newton_row(t1, dt, iteration, residual, force_level(), alpha));
    }



    template <int dim>
    std::vector<dealii::Tensor<1, dim>>
    Solver<dim>::reactions() const
    {
      // The force of each constraint on the body: f_int + M a + C v - f_ext at its DoFs
      // (this rank's part), of the converged state (reaction_old, set by commit()): f_int,
      // f_ext and inertia hold the last evaluation, which is a failed iterate when a run
      // stops because Newton or a material failed.
      std::vector<dealii::Tensor<1, dim>> r(dirichlet.size());
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        {
          const auto dof = constrained_list[k];
          if (owned_dofs.is_element(dof))
            r[constrained_set[k]][constrained_component[k]] += reaction_old(dof);
        }
      for (unsigned int s = 0; s < dirichlet.size() && s < wall_forces.size(); ++s)
        r[s] += wall_forces[s];
      return r;
    }



    template <int dim>
    void
    Solver<dim>::write_table_rows(const double t)
    {
      using namespace dealii;
      const Scene<dim>  &scene     = this->get_scene();
      MPI_Comm           comm      = scene.mpi_communicator();
      const unsigned int n_values  = tables.n_point_values();
      const auto        &regions   = scene.output_control().average_regions;
      const FEValuesExtractors::Vector displacement(0);

      // Probes: the owner of the cell gives position, displacement and velocity at
      // the point; the owner of the nearest quadrature point its stress and state.
      std::vector<double> rows(probes.size() * n_values, 0.0);
      std::vector<double> accelerations(scene.ground_motion().empty() ? 0 : probes.size() * dim, 0.0);
      for (unsigned int i = 0; i < probes.size(); ++i)
        {
          double *row = rows.data() + i * n_values;
          if (probes[i].has_q)
            {
              const CellHistory<dim> &h = *cell_history[probes[i].cell->active_cell_index()];
              const unsigned int      q = probes[i].q;
              PointData::values<dim>(Point<dim>(),
                                     Tensor<1, dim>(),
                                     Tensor<1, dim>(),
                                     h.stress[q],
                                     h.strain[q],
                                     h.material,
                                     make_array_view(h.state.data() + q * h.n_state,
                                                     h.state.data() + (q + 1) * h.n_state),
                                     state_names.size(),
                                     row,
                                     scene.output_control().additional_columns);
            }
          if (probes[i].has_cell)
            {
              const Quadrature<dim> at(probes[i].reference);
              FEValues<dim>         fv(*mapping, *fe, at, update_values);
              fv.reinit(probes[i].dof_cell);
              std::vector<Tensor<1, dim>> uu(1), vv(1), aa(1);
              fv[displacement].get_function_values(u_ghost, uu);
              fv[displacement].get_function_values(v_ghost, vv);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  row[d]           = probes[i].point[d] + uu[0][d];
                  row[dim + d]     = uu[0][d];
                  row[2 * dim + d] = vv[0][d];
                }
              if (!accelerations.empty())
                {
                  fv[displacement].get_function_values(a_ghost, aa);
                  for (unsigned int d = 0; d < dim; ++d)
                    accelerations[i * dim + d] = aa[0][d];
                }
            }
        }

      // Averages, kinetic and strain energy over the quadrature points.
      std::vector<double> averages(regions.size() * (1 + n_values), 0.0), values(n_values);
      double              kinetic = 0, strain_energy = 0;
      const unsigned int  n_q = quadrature->size();
      FEValues<dim>       fv(*mapping, *fe, *quadrature, update_values);
      std::vector<Tensor<1, dim>> uq(n_q), vq(n_q);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            fv.reinit(cell);
            fv[displacement].get_function_values(u_ghost, uq);
            fv[displacement].get_function_values(v_ghost, vq);
            const double rho = h.material->density();
            for (unsigned int q = 0; q < n_q; ++q)
              {
                const ArrayView<const double> state(h.state.data() + q * h.n_state, h.n_state);
                strain_energy +=
                  h.volume[q] * PointData::strain_energy_density(*h.material, h.stress[q], h.strain[q], state);
                if (analysis == Analysis::implicit_dynamics)
                  kinetic += 0.5 * rho * vq[q].norm_square() * h.weight[q];
                for (unsigned int r = 0; r < regions.size(); ++r)
                  if (regions[r].contains(h.point[q], 1e-9 * u_scale))
                    {
                      double      *avg  = averages.data() + r * (1 + n_values);
                      const double mass = rho * h.weight[q];
                      PointData::values<dim>(h.point[q] + uq[q], uq[q], vq[q], h.stress[q], h.strain[q],
                                             h.material, state, state_names.size(), values.data(),
                                             scene.output_control().additional_columns);
                      avg[0] += mass;
                      for (unsigned int c = 0; c < n_values; ++c)
                        avg[1 + c] += mass * values[c];
                    }
              }
          }
      if (analysis == Analysis::explicit_dynamics)
        for (const auto i : owned_dofs)
          kinetic += 0.5 * lumped_mass(i) * v(i) * v(i);

      if (!accelerations.empty())
        tables.set_probe_accelerations(std::move(accelerations));
      tables.write(t, rows, averages, {{kinetic, strain_energy, internal_work, external_work, boundary_work}},
                   reactions(), comm, set_history_values(), damping_work);
    }



    template <int dim>
    void
    Solver<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      using namespace dealii;
      // Cell averages of the quadrature-point values.
      const unsigned int n_cells = triangulation->n_active_cells();
      const unsigned int n_sym   = SymmetricTensor<2, dim>::n_independent_components;
      std::vector<dealii::Vector<float>> stress(n_sym, dealii::Vector<float>(n_cells)),
        strain(n_sym, dealii::Vector<float>(n_cells)),
        state(state_names.size(), dealii::Vector<float>(n_cells));
      dealii::Vector<float> von_mises(n_cells), body(n_cells), subdomain(n_cells);
      const auto           &additional = this->get_scene().output_control().additional_columns;
      std::vector<double>   values(PointData::columns<dim>(state_names, additional).size());
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            const unsigned int      c = cell->active_cell_index();
            double                  volume = 0;
            for (unsigned int q = 0; q < h.weight.size(); ++q)
              volume += h.weight[q];
            for (unsigned int q = 0; q < h.weight.size(); ++q)
              {
                const double w = h.weight[q] / volume;
                PointData::values<dim>(h.point[q], Tensor<1, dim>(), Tensor<1, dim>(), h.stress[q],
                                       h.strain[q], h.material,
                                       make_array_view(h.state.data() + q * h.n_state,
                                                       h.state.data() + (q + 1) * h.n_state),
                                       state_names.size(), values.data(), additional);
                // values: x, u, v (dim each), stress (n_sym), von Mises, strain, state
                for (unsigned int k = 0; k < n_sym; ++k)
                  {
                    stress[k][c] += w * values[3 * dim + k];
                    strain[k][c] += w * values[3 * dim + n_sym + 1 + k];
                  }
                von_mises[c] += w * values[3 * dim + n_sym];
                for (unsigned int k = 0; k < state_names.size(); ++k)
                  state[k][c] += w * values[3 * dim + 2 * n_sym + 1 + k];
              }
            body[c]      = h.body;
            subdomain[c] = triangulation->locally_owned_subdomain();
          }
      DataOut<dim> data_out;
      data_out.attach_dof_handler(dof_handler);
      const std::vector<DataComponentInterpretation::DataComponentInterpretation> vector(
        dim, DataComponentInterpretation::component_is_part_of_vector);
      data_out.add_data_vector(u_ghost, std::vector<std::string>(dim, "displacement"),
                               DataOut<dim>::type_dof_data, vector);
      data_out.add_data_vector(v_ghost, std::vector<std::string>(dim, "velocity"),
                               DataOut<dim>::type_dof_data, vector);
      const auto columns = PointData::columns<dim>(state_names, additional);
      for (unsigned int k = 0; k < n_sym; ++k)
        {
          data_out.add_data_vector(stress[k], columns[3 * dim + k], DataOut<dim>::type_cell_data);
          data_out.add_data_vector(strain[k], columns[3 * dim + n_sym + 1 + k], DataOut<dim>::type_cell_data);
        }
      data_out.add_data_vector(von_mises, "von_mises", DataOut<dim>::type_cell_data);
      for (unsigned int k = 0; k < state_names.size(); ++k)
        data_out.add_data_vector(state[k], state_names[k], DataOut<dim>::type_cell_data);
      data_out.add_data_vector(body, "body", DataOut<dim>::type_cell_data);
      data_out.add_data_vector(subdomain, "subdomain", DataOut<dim>::type_cell_data);
      data_out.build_patches(*mapping, simplex ? 1 : degree);
      writer.write(data_out, t);
    }



    template <int dim>
    void
    Solver<dim>::write_quadrature_table() const
    {
      using namespace dealii;
      const Scene<dim>  &scene   = this->get_scene();
      const auto        &additional = scene.output_control().additional_columns;
      const auto         columns    = PointData::columns<dim>(state_names, additional);
      const unsigned int width   = columns.size() + 1 + dim;
      const unsigned int n_q     = quadrature->size();
      const FEValuesExtractors::Vector displacement(0);
      FEValues<dim>               fv(*mapping, *fe, *quadrature, update_values);
      std::vector<Tensor<1, dim>> uq(n_q), vq(n_q);
      std::vector<double>         rows;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            fv.reinit(cell);
            fv[displacement].get_function_values(u_ghost, uq);
            fv[displacement].get_function_values(v_ghost, vq);
            for (unsigned int q = 0; q < n_q; ++q)
              {
                // Sort key (reference position), then body and the point columns.
                for (unsigned int d = 0; d < dim; ++d)
                  rows.push_back(h.point[q][d]);
                rows.push_back(h.body);
                const std::size_t start = rows.size();
                rows.resize(start + columns.size());
                PointData::values<dim>(h.point[q] + uq[q], uq[q], vq[q], h.stress[q], h.strain[q],
                                       h.material,
                                       make_array_view(h.state.data() + q * h.n_state,
                                                       h.state.data() + (q + 1) * h.n_state),
                                       state_names.size(), rows.data() + start, additional);
              }
          }
      const auto all = Utilities::MPI::gather(scene.mpi_communicator(), rows, 0);
      if (!scene.is_root())
        return;
      std::vector<std::vector<double>> table;
      for (const auto &part : all)
        for (std::size_t i = 0; i < part.size(); i += width)
          table.emplace_back(part.begin() + i, part.begin() + i + width);
      std::sort(table.begin(), table.end());
      std::vector<std::string> header{"body"};
      header.insert(header.end(), columns.begin(), columns.end());
      Output::CsvWriter out(this->output_file("quadrature_points.csv"), header, &this->run_record());
      for (const auto &row : table)
        out.add_row(std::vector<double>(row.begin() + dim, row.end()));
      out.commit();
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron
