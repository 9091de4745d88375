#include <deal.II/base/mpi.h>

#include <hysteron/base/output.h>
#include <hysteron/rbsn/model.h>

#include "rbsn/collective.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// The VTU's integer cell arrays (Int32), in write_vtu()'s order.
      const std::vector<const char *> vtu_integer_fields{"cell", "facet", "body", "broken", "fragment", "released"};

      /// Its real cell arrays (Float64): the rotation (2D: theta; 3D: the vector), H1 and
      /// the facets' forces and stresses.
      template <int dim>
      std::vector<const char *>
      vtu_real_fields()
      {
        if constexpr (dim == 2)
          return {"rotation", "H1", "f_n", "f_t", "m", "s_n", "s_t"};
        else
          return {"rotation", "H1", "f_n", "f_1", "f_2", "m_1", "m_2", "m_t", "s_n", "s_t"};
      }

      /// The rigid motion u + theta x r of a cell with the DoF values @p U at the offset @p r.
      template <int dim, typename Values>
      dealii::Tensor<1, dim>
      rigid_motion(const Values &U, const dealii::Tensor<1, dim> &r)
      {
        dealii::Tensor<1, dim> w;
        if constexpr (dim == 2)
          {
            w[0] = U[0] - U[2] * r[1];
            w[1] = U[1] + U[2] * r[0];
          }
        else
          {
            const dealii::Tensor<1, 3> theta({U[3], U[4], U[5]});
            const dealii::Tensor<1, 3> turn = dealii::cross_product_3d(theta, r);
            for (unsigned int d = 0; d < 3; ++d)
              w[d] = U[d] + turn[d];
          }
        return w;
      }
    } // namespace



    template <int dim>
    std::vector<std::string>
    Model<dim>::point_columns() const
    {
      if constexpr (dim == 2)
        return {"x_x", "x_y", "u_x", "u_y", "v_x", "v_y", "theta", "omega",
                "f_n", "f_t", "m", "s_n", "s_t", "H1_n", "H1_t", "H1_m", "broken"};
      else
        return {"x_x",     "x_y",     "x_z",     "u_x",     "u_y",     "u_z",   "v_x",  "v_y",
                "v_z",     "theta_x", "theta_y", "theta_z", "omega_x", "omega_y", "omega_z",
                "f_n",     "f_1",     "f_2",     "m_1",     "m_2",     "m_t",   "s_n",  "s_t",
                "H1_n",    "H1_1",    "H1_2",    "H1_b1",   "H1_b2",   "H1_t",  "broken"};
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
      for (const auto &p : scene.output_control().probe_points)
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
          Collective::all_reduce(best, MPI_MIN, comm);
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
      tables.open(scene, method.output_directory(), point_columns(), method.run_record());
      if (!scene.is_root())
        return;
      if (analysis == Analysis::variable_order)
        newton_table = std::make_unique<Output::TimeTable>(
          method.output_file("ida.csv"),
          std::vector<std::string>{"time", "steps", "order", "step", "residuals", "jacobians",
                                   "nonlinear_iterations", "error_test_failures",
                                   "convergence_failures"},
          method.run_record());
      else if (analysis != Analysis::linear_static)
        newton_table =
          std::make_unique<Output::TimeTable>(method.output_file("newton.csv"), newton_columns(), method.run_record());
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
            std::make_unique<Output::TimeTable>(method.output_file("fracture.csv"), columns, method.run_record());
        }
    }



    template <int dim>
    void
    Model<dim>::write_table_rows(const double t)
    {
      const MPI_Comm      comm     = network_communicator();
      const unsigned int  n_values = point_columns().size();
      const auto         &probes   = scene.output_control().probe_points;
      // Each value from the rank that owns its cell or facet (zeros elsewhere): the
      // tables sum the ranks' rows.
      std::vector<double> rows(probes.size() * n_values);
      for (unsigned int i = 0; i < probes.size(); ++i)
        point_values(probe_cell[i], probe_facet[i], probes[i], rows.data() + i * n_values);

      // Averages: cell columns mass-weighted over the cells whose nucleus is in the
      // region; facet columns the mean over the facets whose midpoint is in it.
      const auto         &regions = scene.output_control().average_regions;
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
        {
          const int ierr = MPI_Allreduce(MPI_IN_PLACE, totals.data(), totals.size(), MPI_DOUBLE, MPI_SUM, comm);
          AssertThrowMPI(ierr);
        }
      for (unsigned int r = 0; r < regions.size(); ++r)
        {
          double *avg = averages.data() + r * (1 + n_values);
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (regions[r].contains(local_nuclei[c], 1e-9 * scale))
              {
                point_values(c, -1, local_nuclei[c], values.data());
                avg[0] += cell_mass[c];
                for (unsigned int k = 0; k < n_cell_columns; ++k)
                  avg[1 + k] += cell_mass[c] * values[k];
              }
          for (const unsigned int e : inside[r])
            {
              point_values(-1, e, network.facets[e].midpoint, values.data());
              for (unsigned int k = n_cell_columns; k < n_values; ++k)
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
      const double share = distributed() && !scene.is_root() ? 0.0 : 1.0;

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
      tables.write(t, rows, averages,
                   {{kinetic, strain_energy, share * internal_work, share * external_work, share * boundary_work}},
                   reactions, comm, histories);
    }



    template <int dim>
    void
    Model<dim>::write_vtu(std::ostream &out) const
    {
      // The cells (2D: polygons; 3D: the convex polyhedra of each cell) moved rigidly
      // (point data "displacement") and the facets (2D: lines; 3D: polygons), in one
      // unstructured grid. Each rank writes its own cells and facets.
      std::vector<dealii::Point<dim>>      points;
      std::vector<double>                  displacement;
      std::vector<std::int64_t>            offsets, connectivity, faces, face_offsets;
      std::vector<std::uint8_t>            types;
      std::array<std::vector<int>, 6>      integers; // cell, facet, body, broken, fragment, released
      const std::vector<const char *>      reals_names = vtu_real_fields<dim>();
      std::vector<std::vector<double>>     reals(reals_names.size());
      constexpr unsigned int               n_rotation = dim == 2 ? 1 : 3;
      const auto add_point = [&](const dealii::Point<dim> &p, const unsigned int c) {
        std::array<double, n_dofs> U;
        for (unsigned int k = 0; k < n_dofs; ++k)
          U[k] = u.local_element(n_dofs * c + k);
        const dealii::Tensor<1, dim> w = rigid_motion<dim>(U, p - local_nuclei[c]);
        points.push_back(p);
        for (unsigned int d = 0; d < dim; ++d)
          displacement.push_back(w[d]);
        return static_cast<std::int64_t>(points.size() - 1);
      };
      // H1 of a cell: the largest of its normal springs' (from the facets of every rank).
      std::vector<double> cell_h1(cell_id.size(), 0.0);
      for (unsigned int e = 0; e < springs.size(); ++e)
        if (springs[e].hysteretic && !springs[e].broken)
          for (const unsigned int c : {network.facets[e].a, network.facets[e].b})
            cell_h1[c] = std::max(cell_h1[c], this->h1(e, 0));
      if (distributed())
        {
          Vector h(partitioner);
          for (unsigned int c = 0; c < cell_id.size(); ++c)
            h.local_element(n_dofs * c) = cell_h1[c];
          h.compress(dealii::VectorOperation::max);
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            cell_h1[c] = h.local_element(n_dofs * c);
        }
      // The cell data of one VTK cell: the integer fields, the rotation (2D: theta; 3D:
      // the vector) and the real fields after it.
      std::vector<double> rotations;
      const auto add_data = [&](const int cell, const int facet, const unsigned int body, const int broken,
                                const unsigned int part, const bool loose, const double *rotation,
                                const std::vector<double> &values) {
        const int ints[6] = {cell, facet, int(body), broken, int(part), loose ? 1 : 0};
        for (unsigned int k = 0; k < 6; ++k)
          integers[k].push_back(ints[k]);
        for (unsigned int k = 0; k < n_rotation; ++k)
          rotations.push_back(rotation ? rotation[k] : 0.0);
        for (unsigned int k = 1; k < values.size(); ++k)
          reals[k].push_back(values[k]);
      };
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          std::vector<double> cell_values(reals_names.size(), 0.0);
          double              rotation[n_rotation];
          for (unsigned int k = 0; k < n_rotation; ++k)
            rotation[k] = u.local_element(n_dofs * c + dim + k);
          cell_values[1] = cell_h1[c];
          const auto add_cell = [&]() {
            add_data(cell_id[c], -1, cell_body[c], 0, fragment[c], released[c], rotation, cell_values);
          };
          if constexpr (dim == 2)
            for (const auto &loop : network.cells[c].outline)
              {
                for (const auto &p : loop)
                  connectivity.push_back(add_point(p, c));
                offsets.push_back(connectivity.size());
                types.push_back(7); // VTK_POLYGON
                face_offsets.push_back(-1);
                add_cell();
              }
          else
            for (const auto &piece : network.cells[c].pieces)
              {
                // VTK_POLYHEDRON: its points, each once (its faces share them, so that its
                // surface is closed for VTK: every edge in two faces), and its faces as
                // (count, then per face the number of its points and their ids). The faces
                // of a piece hold the same vertices bit for bit.
                std::map<std::array<double, 3>, std::int64_t> ids;
                faces.push_back(piece.size());
                for (const auto &face : piece)
                  {
                    faces.push_back(face.size());
                    for (const auto &p : face)
                      {
                        const auto [at, added] = ids.try_emplace({{p[0], p[1], p[2]}}, 0);
                        if (added)
                          {
                            at->second = add_point(p, c);
                            connectivity.push_back(at->second);
                          }
                        faces.push_back(at->second);
                      }
                  }
                offsets.push_back(connectivity.size());
                face_offsets.push_back(faces.size());
                types.push_back(42);
                add_cell();
              }
        }
      // Every facet (moved with cell a): its spring forces, stresses and H1 (the largest
      // of its springs'); broken ones have broken = 1 and no force.
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const Springs<dim> &sp = springs[e];
          const Facet<dim>   &f  = network.facets[e];
          std::vector<double> facet_values(reals_names.size(), 0.0);
          double              largest = 0;
          for (unsigned int i = 0; i < n_dofs; ++i)
            largest = std::max(largest, this->h1(e, i));
          facet_values[1] = largest;
          if (!sp.broken)
            {
              for (unsigned int i = 0; i < n_dofs; ++i)
                facet_values[2 + i] = sp.force[i];
              if constexpr (dim == 2)
                {
                  const double area   = sp.thickness * f.length;
                  facet_values[5]     = sp.force[0] / area;
                  facet_values[6]     = sp.force[1] / area;
                }
              else
                {
                  facet_values[8] = sp.force[0] / sp.area;
                  facet_values[9] = std::hypot(sp.force[1], sp.force[2]) / sp.area;
                }
            }
          const auto add_facet = [&]() {
            face_offsets.push_back(-1);
            add_data(-1, facet_id[e], cell_body[f.a], sp.broken ? 1 : 0, fragment[f.a], released[f.a], nullptr,
                     facet_values);
          };
          if constexpr (dim == 2)
            {
              connectivity.push_back(add_point(f.p3, f.a));
              connectivity.push_back(add_point(f.p4, f.a));
              offsets.push_back(connectivity.size());
              types.push_back(3); // VTK_LINE
              add_facet();
            }
          else
            for (const auto &polygon : f.polygons)
              {
                for (const auto &p : polygon)
                  connectivity.push_back(add_point(p, f.a));
                offsets.push_back(connectivity.size());
                types.push_back(7); // VTK_POLYGON
                add_facet();
              }
        }
      // VTK XML with inline binary arrays: base64 of a UInt64 byte count and the raw
      // little-endian values (a 100,000-cell network writes in a fraction of the ASCII time).
      out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
             "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece "
             "NumberOfPoints=\""
          << points.size() << "\" NumberOfCells=\"" << types.size() << "\">\n<Points>\n";
      std::vector<double> xyz, displacement_3d;
      xyz.reserve(3 * points.size());
      displacement_3d.reserve(3 * points.size());
      for (unsigned int k = 0; k < points.size(); ++k)
        for (unsigned int d = 0; d < 3; ++d)
          {
            xyz.push_back(d < dim ? points[k][d] : 0.0);
            displacement_3d.push_back(d < dim ? displacement[dim * k + d] : 0.0);
          }
      const auto array = [&](const char *type, const char *name, const unsigned int components,
                             const auto &data) {
        out << "<DataArray type=\"" << type << "\"" << (name[0] ? " Name=\"" : "") << name
            << (name[0] ? "\"" : "") << " NumberOfComponents=\"" << components
            << "\" format=\"binary\">\n";
        Output::write_base64_array(out, data);
        out << "\n</DataArray>\n";
      };
      array("Float64", "", 3, xyz);
      out << "</Points>\n<Cells>\n";
      array("Int64", "connectivity", 1, connectivity);
      array("Int64", "offsets", 1, offsets);
      array("UInt8", "types", 1, types);
      if (dim == 3)
        {
          array("Int64", "faces", 1, faces);
          array("Int64", "faceoffsets", 1, face_offsets);
        }
      out << "</Cells>\n<PointData Vectors=\"displacement\">\n";
      array("Float64", "displacement", 3, displacement_3d);
      out << "</PointData>\n<CellData>\n";
      for (unsigned int k = 0; k < vtu_integer_fields.size(); ++k)
        array("Int32", vtu_integer_fields[k], 1, std::vector<std::int32_t>(integers[k].begin(), integers[k].end()));
      for (unsigned int k = 0; k < reals_names.size(); ++k)
        if (k == 0)
          array("Float64", reals_names[k], n_rotation, rotations);
        else
          array("Float64", reals_names[k], 1, reals[k]);
      out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    }



    template <int dim>
    void
    Model<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      if (!distributed())
        return writer.write_serial([this](std::ostream &out) { write_vtu(out); }, t); // replicated
      writer.write_pieces([this](std::ostream &out) { write_vtu(out); },
                          [](std::ostream &out, const std::vector<std::string> &pieces) {
                            // The record of the ranks' pieces: the arrays of write_vtu().
                            out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" "
                                   "version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                                   "<PUnstructuredGrid GhostLevel=\"0\">\n<PPointData "
                                   "Vectors=\"displacement\">\n<PDataArray type=\"Float64\" "
                                   "Name=\"displacement\" NumberOfComponents=\"3\"/>\n</PPointData>\n"
                                   "<PCellData>\n";
                            for (const char *name : vtu_integer_fields)
                              out << "<PDataArray type=\"Int32\" Name=\"" << name << "\" NumberOfComponents=\"1\"/>\n";
                            const auto reals = vtu_real_fields<dim>();
                            for (unsigned int k = 0; k < reals.size(); ++k)
                              out << "<PDataArray type=\"Float64\" Name=\"" << reals[k]
                                  << "\" NumberOfComponents=\"" << (dim == 3 && k == 0 ? 3 : 1) << "\"/>\n";
                            out << "</PCellData>\n<PPoints>\n<PDataArray type=\"Float64\" "
                                   "NumberOfComponents=\"3\"/>\n</PPoints>\n";
                            for (const auto &piece : pieces)
                              out << "<Piece Source=\"" << piece << "\"/>\n";
                            out << "</PUnstructuredGrid>\n</VTKFile>\n";
                          },
                          t);
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
      if (!scene.is_root())
        return;
      std::vector<std::vector<double>> ordered(n_global_facets);
      for (std::size_t k = 0; k + width <= all.size(); k += width)
        ordered[static_cast<std::size_t>(all[k])].assign(all.begin() + k + 1, all.begin() + k + width);
      Output::CsvWriter out(method.output_file("springs.csv"), columns, &method.run_record());
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
        }
      const std::vector<double> all = distributed() ? Collective::gather(rows, network_communicator(), 0) : rows;
      if (!scene.is_root())
        return;
      std::vector<std::vector<double>> ordered(n_cells);
      for (std::size_t k = 0; k + columns.size() <= all.size(); k += columns.size())
        ordered[static_cast<std::size_t>(all[k])].assign(all.begin() + k, all.begin() + k + columns.size());
      Output::CsvWriter out(method.output_file("cells.csv"), columns, &method.run_record());
      for (const auto &row : ordered)
        out.add_row(row);
      out.commit();
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
