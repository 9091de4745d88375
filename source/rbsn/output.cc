// The network's tables: the probes (located once) and the point tables with averages,
// energies, reactions and set histories at every output, and springs.csv and cells.csv.
#include <deal.II/base/mpi.h>

#include <hysteron/base/output.h>
#include "rbsn/model.h"

#include "rbsn/collective.h"
#include "rbsn/rigid_motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    std::vector<std::string>
    Model<dim>::point_columns() const
    {
      std::vector<std::string> columns;
      if constexpr (dim == 2)
        columns = {"x_x", "x_y", "u_x", "u_y", "v_x", "v_y", "theta", "omega",
                   "f_n", "f_t", "m", "s_n", "s_t", "H1_n", "H1_t", "H1_m", "broken"};
      else
        columns = {"x_x",     "x_y",     "x_z",     "u_x",     "u_y",     "u_z",   "v_x",  "v_y",
                   "v_z",     "theta_x", "theta_y", "theta_z", "omega_x", "omega_y", "omega_z",
                   "f_n",     "f_1",     "f_2",     "m_1",     "m_2",     "m_t",   "s_n",  "s_t",
                   "H1_n",    "H1_1",    "H1_2",    "H1_b1",   "H1_b2",   "H1_t",  "broken"};
      // The cell's output column plugins last (cell_tensors.cc).
      const std::vector<std::string> additional = scene().output_control().additional_columns.names();
      columns.insert(columns.end(), additional.begin(), additional.end());
      return columns;
    }



    template <int dim>
    void
    Model<dim>::point_values(const int c, const int e, const dealii::Point<dim> &p, double *out) const
    {
      const unsigned int n_values = point_columns().size();
      std::fill(out, out + n_values, 0.0);
      if (c >= 0)
        {
          // The rigid motion of cell c at p: u(p) = u_c + theta x (p - x_c).
          const dealii::Tensor<1, dim>  r = p - local_nuclei[c];
          std::array<double, n_dofs>    U, V;
          for (unsigned int k = 0; k < n_dofs; ++k)
            {
              U[k] = u.local_element(n_dofs * c + k);
              V[k] = v.local_element(n_dofs * c + k);
            }
          if constexpr (dim == 2)
            {
              const double th = U[2], om = V[2];
              const double ux = U[0] - th * r[1], uy = U[1] + th * r[0];
              const double vx = V[0] - om * r[1], vy = V[1] + om * r[0];
              const double cell_values[8] = {p[0] + ux, p[1] + uy, ux, uy, vx, vy, th, om};
              std::copy(cell_values, cell_values + 8, out);
            }
          else
            {
              const dealii::Tensor<1, 3> w = rigid_motion<3>(U, r), vw = rigid_motion<3>(V, r);
              for (unsigned int d = 0; d < 3; ++d)
                {
                  out[d]      = p[d] + w[d];
                  out[3 + d]  = w[d];
                  out[6 + d]  = vw[d];
                  out[9 + d]  = U[3 + d];
                  out[12 + d] = V[3 + d];
                }
            }
        }
      if (e < 0)
        return;
      double            *facet = out + n_cell_columns;
      const Springs<dim> &sp   = springs[e];
      if (sp.broken)
        {
          facet[n_dofs + 2 + n_dofs] = 1; // no force, no state
          return;
        }
      const auto ratio = fracture_ratio(e);
      for (unsigned int i = 0; i < n_dofs; ++i)
        facet[i] = sp.force[i];
      if constexpr (dim == 2)
        {
          // The converged forces' stresses (as 2D always wrote them).
          const double area = sp.thickness * network.facets[e].length;
          facet[3]          = sp.force[0] / area;
          facet[4]          = sp.force[1] / area;
        }
      else
        {
          facet[n_dofs]     = sp.force[0] / sp.area;
          facet[n_dofs + 1] = std::hypot(sp.force[1], sp.force[2]) / sp.area;
        }
      (void)ratio;
      for (unsigned int i = 0; i < n_dofs; ++i)
        facet[n_dofs + 2 + i] = h1(e, i); // the coupled law: Phi^n of the facet in all
    }



    template <int dim>
    std::vector<double>
    Model<dim>::probe_accelerations() const
    {
      // Differentiated twice in time, u(p) = u_c + theta x r gives a(p) = a_c + alpha x r
      // with the cell's translational and angular accelerations: Newmark's (HHT's)
      // acceleration vector, or the variable-order integrator's derivative of the
      // velocities (to_model()). Relative to the ground, as u and v.
      const auto         &probes = scene().output_control().probe_points;
      std::vector<double> out(scene().ground_motion().empty() ? 0 : probes.size() * dim, 0.0);
      for (unsigned int i = 0; i < probes.size() && !out.empty(); ++i)
        if (const int c = probe_cell[i]; c >= 0)
          {
            std::array<double, n_dofs> A;
            for (unsigned int k = 0; k < n_dofs; ++k)
              A[k] = a.local_element(n_dofs * c + k);
            const dealii::Tensor<1, dim> w = rigid_motion<dim>(A, probes[i] - local_nuclei[c]);
            for (unsigned int d = 0; d < dim; ++d)
              out[i * dim + d] = w[d];
          }
      return out;
    }



    template <int dim>
    void
    Model<dim>::locate_probes()
    {
      // Each probe: the cell whose nucleus is nearest (the Voronoi cell holding the
      // point) and the facet whose midpoint is nearest (the lowest number of equals).
      const MPI_Comm comm = network_communicator();
      probe_global_cell.clear();
      probe_global_facet.clear();
      probe_cell.clear();
      probe_facet.clear();
      for (const auto &p : scene().output_control().probe_points)
        {
          // A probe outside every body would silently report its nearest cell.
          const double tolerance = 1e-6 * d_m;
          if (std::none_of(body_shapes.begin(), body_shapes.end(),
                           [&](const auto *shape) { return shape->contains(p, tolerance); }))
            {
              std::ostringstream what;
              what << "the point (" << p << ") lies outside the bodies of the network";
              throw InputError("Output/Probe points", what.str());
            }
          // The nearest nucleus of each rank's own cells (ascending numbers: the lowest of
          // equals), then over the ranks the nearest, and the lowest number of equals.
          int    cell     = -1;
          double distance = std::numeric_limits<double>::max();
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (local_nuclei[c].distance(p) < distance)
              {
                distance = local_nuclei[c].distance(p);
                cell     = c;
              }
          // (MPI_UNSIGNED_LONG_LONG: Debian 12's Open MPI takes MPI_MIN of MPI_UNSIGNED_LONG
          // values above 2^63 for negative ones.)
          const double                    closest = dealii::Utilities::MPI::min(distance, comm);
          std::vector<unsigned long long> best{cell >= 0 && distance == closest ?
                                                 cell_id[cell] :
                                                 std::numeric_limits<unsigned long long>::max()};
          dealii::Utilities::MPI::min(best, comm, best);
          probe_global_cell.push_back(best[0]);
          probe_cell.push_back(cell >= 0 && cell_id[cell] == best[0] ? cell : -1);
          int facet = -1;
          for (unsigned int e = 0; e < network.facets.size(); ++e)
            if (facet < 0 || network.facets[e].midpoint.distance(p) < network.facets[facet].midpoint.distance(p))
              facet = e;
          struct
          {
            double distance;
            int    id;
          } mine{facet < 0 ? std::numeric_limits<double>::max() : network.facets[facet].midpoint.distance(p),
                 facet < 0 ? std::numeric_limits<int>::max() : static_cast<int>(facet_id[facet])},
            nearest{};
          const int ierr = MPI_Allreduce(&mine, &nearest, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm);
          AssertThrowMPI(ierr);
          probe_global_facet.push_back(nearest.id == std::numeric_limits<int>::max() ? -1 : nearest.id);
          probe_facet.push_back(facet >= 0 && static_cast<int>(facet_id[facet]) == nearest.id ? facet : -1);
        }
    }



    template <int dim>
    void
    Model<dim>::open_tables()
    {
      tables.open(scene(), this->output_directory(), point_columns(), this->run_record(), damped());
      if (!scene().is_root())
        return;
      if (analysis == Analysis::variable_order)
        newton_table = std::make_unique<Output::TimeTable>(
          this->output_file("ida.csv"),
          std::vector<std::string>{"time", "steps", "order", "step", "residuals", "jacobians",
                                   "nonlinear_iterations", "error_test_failures",
                                   "convergence_failures"},
          this->run_record());
      else if (analysis != Analysis::linear_static)
        newton_table =
          std::make_unique<Output::TimeTable>(this->output_file("newton.csv"), newton_columns(), this->run_record());
      if (fracture.enabled)
        {
          std::vector<std::string> columns{"time", "facet", "x", "y"};
          if (dim == 3)
            columns.push_back("z");
          columns.insert(columns.end(), {"s_n", "s_t", "R", "fragments", "separated_cells", "separated_x", "separated_y"});
          if (dim == 3)
            columns.push_back("separated_z");
          columns.push_back("released_cells");
          fracture_table =
            std::make_unique<Output::TimeTable>(this->output_file("fracture.csv"), columns, this->run_record());
        }
    }



    template <int dim>
    void
    Model<dim>::write_rows(const double t)
    {
      const MPI_Comm      comm     = network_communicator();
      const unsigned int  n_values = point_columns().size();
      const auto         &probes   = scene().output_control().probe_points;
      // Each value from the rank that owns its cell or facet (zeros elsewhere): the
      // tables sum the ranks' rows.
      std::vector<double> rows(probes.size() * n_values);
      for (unsigned int i = 0; i < probes.size(); ++i)
        point_values(probe_cell[i], probe_facet[i], probes[i], rows.data() + i * n_values);
      // The output column plugins: of the probe's cell, and mass-weighted in the averages.
      std::vector<dealii::SymmetricTensor<2, dim>> cell_stress, cell_strain;
      std::vector<const Material::Interface<dim> *> materials;
      const bool additional = n_values > n_base_columns;
      if (additional)
        {
          cell_tensors(cell_stress, cell_strain);
          materials = body_materials();
          for (unsigned int i = 0; i < probes.size(); ++i)
            if (const int c = probe_cell[i]; c >= 0)
              additional_values(rows.data() + i * n_values, cell_stress[c], cell_strain[c],
                                *materials[cell_body[c]], rows.data() + i * n_values + n_base_columns);
        }

      // Averages: cell columns mass-weighted over the cells whose nucleus is in the
      // region; facet columns the mean over the facets whose midpoint is in it.
      const auto         &regions = scene().output_control().average_regions;
      std::vector<double> averages(regions.size() * (1 + n_values), 0.0), values(n_values);
      std::vector<double> totals(2 * regions.size(), 0.0); // mass and facets of each region
      std::vector<std::vector<unsigned int>> inside(regions.size());
      for (unsigned int r = 0; r < regions.size(); ++r)
        {
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (regions[r].contains(local_nuclei[c], 1e-9 * scale))
              totals[2 * r] += cell_mass[c];
          for (unsigned int e = 0; e < network.facets.size(); ++e)
            if (regions[r].contains(network.facets[e].midpoint, 1e-9 * scale))
              inside[r].push_back(e);
          totals[2 * r + 1] = inside[r].size();
        }
      if (distributed() && !regions.empty())
        dealii::Utilities::MPI::sum(totals, comm, totals);
      for (unsigned int r = 0; r < regions.size(); ++r)
        {
          double *avg = averages.data() + r * (1 + n_values);
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (regions[r].contains(local_nuclei[c], 1e-9 * scale))
              {
                point_values(c, -1, local_nuclei[c], values.data());
                if (additional)
                  additional_values(values.data(), cell_stress[c], cell_strain[c], *materials[cell_body[c]],
                                    values.data() + n_base_columns);
                avg[0] += cell_mass[c];
                for (unsigned int k = 0; k < n_values; ++k)
                  if (k < n_cell_columns || k >= n_base_columns)
                    avg[1 + k] += cell_mass[c] * values[k];
              }
          for (const unsigned int e : inside[r])
            {
              point_values(-1, e, network.facets[e].midpoint, values.data());
              for (unsigned int k = n_cell_columns; k < n_base_columns; ++k)
                avg[1 + k] += totals[2 * r] / totals[2 * r + 1] * values[k];
            }
        }

      // Energies: kinetic 1/2 v^T M v, the springs' recoverable energy
      // 1/2 a k delta^2 + 1/2 (1 - a) k z^2 (elastic: 1/2 k delta^2), and the works.
      double kinetic = 0, strain_energy = 0;
      for (unsigned int c = 0; c < n_owned_cells && dynamic(); ++c)
        {
          const double m = cell_mass[c];
          if constexpr (dim == 2)
            {
              const double vx = v.local_element(3 * c), vy = v.local_element(3 * c + 1), om = v.local_element(3 * c + 2);
              kinetic += 0.5 * (m * (vx * vx + vy * vy) + cell_inertia[c][0][0] * om * om) +
                         om * m * (-cell_offset[c][1] * vx + cell_offset[c][0] * vy);
            }
          else
            {
              // 1/2 m |v|^2 + m v . (omega x o) + 1/2 omega . J omega.
              dealii::Tensor<1, 3> w, om;
              for (unsigned int d = 0; d < 3; ++d)
                {
                  w[d]  = v.local_element(6 * c + d);
                  om[d] = v.local_element(6 * c + 3 + d);
                }
              kinetic += 0.5 * m * w.norm_square() + m * (w * dealii::cross_product_3d(om, cell_offset[c])) +
                         0.5 * (om * (cell_inertia[c] * om));
            }
        }
      for (unsigned int e = 0; e < springs.size(); ++e)
        if (const Springs<dim> &sp = springs[e]; !sp.broken)
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              if (!sp.hysteretic)
                strain_energy += 0.5 * sp.k[i] * sp.delta[i] * sp.delta[i];
              else
                strain_energy += spring_law->strain_energy(e, i, sp.delta[i], sp.state.data());
            }
      // The works are the network's sums: each rank's share of the row's sum.
      const double share = distributed() && !scene().is_root() ? 0.0 : 1.0;

      // The reactions f_int + inertia - f_ext of the converged state (reaction_old, set by
      // commit()): f_int and inertia hold the last evaluation, a failed iterate when the
      // run stops.
      std::vector<dealii::Tensor<1, dim>> reactions(dirichlet.size());
      for (unsigned int i = 0; i < u.locally_owned_size(); ++i)
        if (dof_set[i] >= 0 && i % n_dofs < dim)
          reactions[dof_set[i]][i % n_dofs] += reaction_old.local_element(i);
      // History sets: the mean displacement of the cells' nuclei, the reaction and the
      // external force on them (translations).
      std::vector<double> histories;
      for (unsigned int h = 0; h < history_cells.size(); ++h)
        {
          std::array<double, 3 * dim> row{};
          for (const unsigned int c : history_cells[h])
            for (unsigned int k = 0; k < dim; ++k)
              {
                row[k] += u.local_element(n_dofs * c + k) / history_size[h];
                row[dim + k] += reaction_old.local_element(n_dofs * c + k);
                row[2 * dim + k] += f_ext_old.local_element(n_dofs * c + k);
              }
          histories.insert(histories.end(), row.begin(), row.end());
        }
      if (!scene().ground_motion().empty())
        tables.set_probe_accelerations(probe_accelerations());
      tables.write(t, rows, averages,
                   {{kinetic, strain_energy, share * internal_work, share * external_work, share * boundary_work}},
                   reactions, comm, histories, share * damping_work);
    }



    template <int dim>
    void
    Model<dim>::write_spring_table() const
    {
      // Every rank's facets (global number first) to rank 0, which writes them in order.
      std::vector<std::string> columns;
      if constexpr (dim == 2)
        columns = {"a", "b", "x", "y", "n_x", "n_y", "length", "distance", "thickness",
                   "k_n", "k_t", "k_phi",
                   "delta_n", "delta_t", "phi", "f_n", "f_t", "m", "H1_n", "H1_t", "H1_m",
                   "broken"};
      else
        columns = {"a",       "b",       "x",       "y",       "z",       "n_x",    "n_y",    "n_z",
                   "s1_x",    "s1_y",    "s1_z",    "s2_x",    "s2_y",    "s2_z",   "area",   "I_1",
                   "I_2",     "distance", "k_n",    "k_1",     "k_2",     "k_b1",   "k_b2",   "k_t",
                   "delta_n", "delta_1", "delta_2", "phi_1",   "phi_2",   "phi_n",  "f_n",    "f_1",
                   "f_2",     "m_1",     "m_2",     "m_t",     "H1_n",    "H1_1",   "H1_2",   "H1_b1",
                   "H1_b2",   "H1_t",    "broken"};
      std::vector<double> rows;
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const Facet<dim>   &f  = network.facets[e];
          const Springs<dim> &sp = springs[e];
          rows.push_back(facet_id[e]);
          rows.push_back(cell_id[f.a]);
          rows.push_back(cell_id[f.b]);
          for (unsigned int d = 0; d < dim; ++d)
            rows.push_back(f.midpoint[d]);
          for (unsigned int d = 0; d < dim; ++d)
            rows.push_back(f.normal[d]);
          if constexpr (dim == 2)
            rows.insert(rows.end(), {f.length, f.distance, sp.thickness});
          else
            {
              for (const auto &axis : {f.axis_1, f.axis_2})
                for (unsigned int d = 0; d < 3; ++d)
                  rows.push_back(axis[d]);
              rows.insert(rows.end(), {f.area, f.second_moment_1, f.second_moment_2, f.distance});
            }
          rows.insert(rows.end(), sp.k.begin(), sp.k.end());
          // A broken facet (a crack) carries no force, as in the VTU and the probes; its
          // deformations are the cells' relative motion now (the crack's opening), not
          // those of the last state before it broke.
          SpringVector delta = sp.delta, force = sp.force;
          if (sp.broken)
            {
              const auto                     ld = facet_local_dofs(e);
              std::array<double, 2 * n_dofs> U;
              for (unsigned int k = 0; k < 2 * n_dofs; ++k)
                U[k] = u.local_element(ld[k]);
              for (unsigned int i = 0; i < n_dofs; ++i)
                delta[i] = sp.deformation(i, U);
              force.fill(0.0);
            }
          rows.insert(rows.end(), delta.begin(), delta.end());
          rows.insert(rows.end(), force.begin(), force.end());
          for (unsigned int i = 0; i < n_dofs; ++i)
            rows.push_back(h1(e, i));
          rows.push_back(sp.broken ? 1 : 0);
        }
      const unsigned int width = columns.size() + 1;
      const std::vector<double> all = distributed() ? Collective::gather(rows, network_communicator(), 0) : rows;
      if (!scene().is_root())
        return;
      std::vector<std::vector<double>> ordered(n_global_facets);
      for (std::size_t k = 0; k + width <= all.size(); k += width)
        ordered[static_cast<std::size_t>(all[k])].assign(all.begin() + k + 1, all.begin() + k + width);
      Output::CsvWriter out(this->output_file("springs.csv"), columns, &this->run_record());
      for (const auto &row : ordered)
        out.add_row(row);
      out.commit();
    }



    template <int dim>
    void
    Model<dim>::write_cell_table() const
    {
      // Every rank's cells (number first) to rank 0, which writes them in order.
      std::vector<std::string> columns{"cell", "x", "y"};
      if (dim == 3)
        columns.push_back("z");
      columns.insert(columns.end(), {"body", dim == 2 ? "area" : "volume", "u_x", "u_y"});
      if constexpr (dim == 2)
        columns.push_back("theta");
      else
        columns.insert(columns.end(), {"u_z", "theta_x", "theta_y", "theta_z"});
      // The output column plugins of each cell at its nucleus (cell_tensors.cc).
      const auto &additional = scene().output_control().additional_columns;
      std::vector<dealii::SymmetricTensor<2, dim>> cell_stress, cell_strain;
      std::vector<const Material::Interface<dim> *> materials;
      std::vector<double> values;
      if (!additional.empty())
        {
          const std::vector<std::string> names = additional.names();
          columns.insert(columns.end(), names.begin(), names.end());
          cell_tensors(cell_stress, cell_strain);
          materials = body_materials();
          values.resize(n_base_columns + names.size());
        }
      std::vector<double> rows;
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          rows.push_back(cell_id[c]);
          for (unsigned int d = 0; d < dim; ++d)
            rows.push_back(local_nuclei[c][d]);
          rows.push_back(cell_body[c]);
          rows.push_back(cell_measure(c));
          for (unsigned int k = 0; k < n_dofs; ++k)
            rows.push_back(u.local_element(n_dofs * c + k));
          if (!additional.empty())
            {
              point_values(c, -1, local_nuclei[c], values.data());
              additional_values(values.data(), cell_stress[c], cell_strain[c], *materials[cell_body[c]],
                                values.data() + n_base_columns);
              rows.insert(rows.end(), values.begin() + n_base_columns, values.end());
            }
        }
      const std::vector<double> all = distributed() ? Collective::gather(rows, network_communicator(), 0) : rows;
      if (!scene().is_root())
        return;
      std::vector<std::vector<double>> ordered(n_cells);
      for (std::size_t k = 0; k + columns.size() <= all.size(); k += columns.size())
        ordered[static_cast<std::size_t>(all[k])].assign(all.begin() + k, all.begin() + k + columns.size());
      Output::CsvWriter out(this->output_file("cells.csv"), columns, &this->run_record());
      for (const auto &row : ordered)
        out.add_row(row);
      out.commit();
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
