#include <hysteron/base/output.h>
#include <hysteron/rbsn/model.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// The VTU's cell arrays, in write_vtu()'s order: six Int32, then Float64.
      const std::vector<const char *> vtu_cell_fields{"cell",     "facet", "body", "broken", "fragment",
                                                      "released", "rotation", "H1", "f_n",    "f_t",
                                                      "m",        "s_n",   "s_t"};
    } // namespace



    std::vector<std::string>
    Model::point_columns() const
    {
      return {"x_x", "x_y", "u_x", "u_y", "v_x", "v_y", "theta", "omega",
              "f_n", "f_t", "m", "s_n", "s_t", "H1_n", "H1_t", "H1_m", "broken"};
    }



    void
    Model::point_values(const unsigned int c, const int e, const dealii::Point<2> &p, double *out) const
    {
      // The rigid motion of cell c at p: u(p) = u_c + theta (-(y - y_c), x - x_c).
      const dealii::Tensor<1, 2> r = p - network.cells[c].nucleus;
      const double               th = u(3 * c + 2), om = v(3 * c + 2);
      const double ux = u(3 * c) - th * r[1], uy = u(3 * c + 1) + th * r[0];
      const double vx = v(3 * c) - om * r[1], vy = v(3 * c + 1) + om * r[0];
      const double cell_values[8] = {p[0] + ux, p[1] + uy, ux, uy, vx, vy, th, om};
      std::copy(cell_values, cell_values + 8, out);
      std::fill(out + 8, out + 17, 0.0);
      if (e < 0)
        return;
      const Springs &sp = springs[e];
      if (sp.broken)
        {
          out[16] = 1; // no force, no state
          return;
        }
      const double   area = sp.thickness * network.facets[e].length;
      out[8]  = sp.force[0];
      out[9]  = sp.force[1];
      out[10] = sp.force[2];
      out[11] = sp.force[0] / area;
      out[12] = sp.force[1] / area;
      for (unsigned int i = 0; i < 3; ++i)
        out[13 + i] = h1(e, i); // the coupled law: Phi^n of the facet in all three
    }



    void
    Model::locate_probes()
    {
      // Each probe: the cell whose nucleus is nearest (the Voronoi cell holding the
      // point) and the facet whose midpoint is nearest.
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
          unsigned int best = 0;
          for (unsigned int c = 1; c < network.cells.size(); ++c)
            if (network.cells[c].nucleus.distance(p) < network.cells[best].nucleus.distance(p))
              best = c;
          probe_cell.push_back(best);
          int facet = -1;
          for (unsigned int e = 0; e < network.facets.size(); ++e)
            if (facet < 0 || network.facets[e].midpoint.distance(p) < network.facets[facet].midpoint.distance(p))
              facet = e;
          probe_facet.push_back(facet);
        }
    }



    void
    Model::open_tables()
    {
      tables.open(scene, method.output_directory(), point_columns());
      if (!scene.is_root())
        return;
      if (analysis == Analysis::variable_order)
        newton_table = std::make_unique<Output::TimeTable>(
          method.output_file("ida.csv"),
          std::vector<std::string>{"time", "steps", "order", "step", "residuals", "jacobians",
                                   "nonlinear_iterations", "error_test_failures",
                                   "convergence_failures"});
      else if (analysis != Analysis::linear_static)
        newton_table =
          std::make_unique<Output::TimeTable>(method.output_file("newton.csv"), newton_columns());
      if (fracture.enabled)
        fracture_table = std::make_unique<Output::TimeTable>(
          method.output_file("fracture.csv"),
          std::vector<std::string>{"time", "facet", "x", "y", "s_n", "s_t", "R", "fragments",
                                   "separated_cells", "separated_x", "separated_y",
                                   "released_cells"});
    }



    std::vector<double>
    Model::break_row(const unsigned int e, const double t, const Separation &separated) const
    {
      const Springs &sp   = springs[e];
      const double   area = sp.thickness * network.facets[e].length;
      const double   s_n = sp.trial_force[0] / area, s_t = sp.trial_force[1] / area;
      const double   R = std::max(s_n / fracture.tensile_strength,
                                (std::abs(s_t) + fracture.friction * s_n) / fracture.cohesion);
      return {t, double(e), network.facets[e].midpoint[0], network.facets[e].midpoint[1], s_n, s_t, R,
              double(n_fragments), double(separated.cells), separated.centroid[0],
              separated.centroid[1], double(separated.released)};
    }



    void
    Model::write_table_rows(const double t)
    {
      const unsigned int  n_values = point_columns().size();
      const auto         &probes   = scene.output_control().probe_points;
      std::vector<double> rows(probes.size() * n_values);
      for (unsigned int i = 0; i < probes.size(); ++i)
        point_values(probe_cell[i], probe_facet[i], probes[i], rows.data() + i * n_values);

      // Averages: cell columns mass-weighted over the cells whose nucleus is in the
      // region; facet columns the mean over the facets whose midpoint is in it.
      const auto         &regions = scene.output_control().average_regions;
      std::vector<double> averages(regions.size() * (1 + n_values), 0.0), values(n_values);
      for (unsigned int r = 0; r < regions.size(); ++r)
        {
          double *avg = averages.data() + r * (1 + n_values);
          for (unsigned int c = 0; c < network.cells.size(); ++c)
            if (regions[r].contains(network.cells[c].nucleus, 1e-9 * scale))
              {
                point_values(c, -1, network.cells[c].nucleus, values.data());
                avg[0] += cell_mass[c];
                for (unsigned int k = 0; k < 8; ++k)
                  avg[1 + k] += cell_mass[c] * values[k];
              }
          std::vector<unsigned int> inside;
          for (unsigned int e = 0; e < network.facets.size(); ++e)
            if (regions[r].contains(network.facets[e].midpoint, 1e-9 * scale))
              inside.push_back(e);
          for (const unsigned int e : inside)
            {
              point_values(network.facets[e].a, e, network.facets[e].midpoint, values.data());
              for (unsigned int k = 8; k < n_values; ++k)
                avg[1 + k] += avg[0] / inside.size() * values[k];
            }
        }

      // Energies: kinetic 1/2 v^T M v, the springs' recoverable energy
      // 1/2 a k delta^2 + 1/2 (1 - a) k z^2 (elastic: 1/2 k delta^2), and the works.
      double kinetic = 0, strain_energy = 0;
      for (unsigned int c = 0; c < network.cells.size() && dynamic(); ++c)
        {
          const double m = cell_mass[c], vx = v(3 * c), vy = v(3 * c + 1), om = v(3 * c + 2);
          kinetic += 0.5 * (m * (vx * vx + vy * vy) + cell_inertia[c] * om * om) +
                     om * m * (-cell_offset[c][1] * vx + cell_offset[c][0] * vy);
        }
      for (unsigned int e = 0; e < springs.size(); ++e)
        if (const Springs &sp = springs[e]; !sp.broken)
          for (unsigned int i = 0; i < 3; ++i)
            {
              if (!sp.hysteretic)
                strain_energy += 0.5 * sp.k[i] * sp.delta[i] * sp.delta[i];
              else
                strain_energy += spring_law->strain_energy(e, i, sp.delta[i], sp.state.data());
            }

      // The reactions f_int + inertia - f_ext of the converged state (reaction_old, set by
      // commit()): f_int and inertia hold the last evaluation, a failed iterate when the
      // run stops.
      std::vector<dealii::Tensor<1, 2>> reactions(dirichlet.size());
      for (unsigned int i = 0; i < u.size(); ++i)
        if (dof_set[i] >= 0 && i % 3 < 2)
          reactions[dof_set[i]][i % 3] += reaction_old(i);
      // History sets: the mean displacement of the cells' nuclei, the reaction and the
      // external force on them (translations; the vectors are whole on every rank).
      std::vector<double> histories;
      for (const auto &cells : history_cells)
        {
          std::array<double, 6> row{};
          for (const unsigned int c : cells)
            for (unsigned int k = 0; k < 2; ++k)
              {
                row[k] += u(3 * c + k) / cells.size();
                row[2 + k] += reaction_old(3 * c + k);
                row[4 + k] += f_ext_old(3 * c + k);
              }
          histories.insert(histories.end(), row.begin(), row.end());
        }
      tables.write(t, rows, averages,
                   {{kinetic, strain_energy, internal_work, external_work, boundary_work}},
                   reactions, MPI_COMM_SELF, histories);
    }



    void
    Model::write_vtu(std::ostream &out) const
    {
      // The cells as polygons (moved rigidly: point data "displacement") and the
      // facets as lines, in one unstructured grid.
      std::vector<dealii::Point<2>> points;
      std::vector<double>           displacement;
      std::vector<unsigned int>     offsets, connectivity;
      std::vector<int>              types, cell_index, facet_index, body, part, loose;
      std::vector<double>           theta, h1;
      std::array<std::vector<double>, 5> forces; // f_n, f_t, m, s_n, s_t of the facet lines
      std::vector<int>              broken;
      const auto add_point = [&](const dealii::Point<2> &p, const unsigned int c) {
        const dealii::Tensor<1, 2> r = p - network.cells[c].nucleus;
        const double               th = u(3 * c + 2);
        points.push_back(p);
        displacement.push_back(u(3 * c) - th * r[1]);
        displacement.push_back(u(3 * c + 1) + th * r[0]);
        connectivity.push_back(points.size() - 1);
      };
      std::vector<double> cell_h1(network.cells.size(), 0.0);
      for (unsigned int e = 0; e < springs.size(); ++e)
        if (springs[e].hysteretic && !springs[e].broken)
          for (const unsigned int c : {network.facets[e].a, network.facets[e].b})
            cell_h1[c] = std::max(cell_h1[c], this->h1(e, 0));
      // Under MPI each rank writes its own cells and facets (a piece of the .pvtu).
      for (unsigned int c = 0; c < network.cells.size(); ++c)
        for (const auto &loop : network.cells[c].outline)
          {
            if (distributed() && cell_owner[c] != rank)
              break;
            for (const auto &p : loop)
              add_point(p, c);
            offsets.push_back(connectivity.size());
            types.push_back(7); // VTK_POLYGON
            cell_index.push_back(c);
            facet_index.push_back(-1);
            body.push_back(cell_body[c]);
            part.push_back(fragment[c]);
            loose.push_back(released[c] ? 1 : 0);
            theta.push_back(u(3 * c + 2));
            h1.push_back(cell_h1[c]);
            for (auto &f : forces)
              f.push_back(0);
            broken.push_back(0);
          }
      // Every facet as a line (moved with cell a): its spring forces, stresses and
      // H1 (the largest of its springs'); broken ones have broken = 1 and no force.
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          if (distributed() && !owned_facet[e])
            continue;
          const Springs &sp = springs[e];
          const Facet<2>   &f  = network.facets[e];
          add_point(f.p3, f.a);
          add_point(f.p4, f.a);
          offsets.push_back(connectivity.size());
          types.push_back(3); // VTK_LINE
          cell_index.push_back(-1);
          facet_index.push_back(e);
          body.push_back(cell_body[f.a]);
          part.push_back(fragment[f.a]);
          loose.push_back(released[f.a] ? 1 : 0);
          theta.push_back(0);
          h1.push_back(std::max({this->h1(e, 0), this->h1(e, 1), this->h1(e, 2)}));
          const double area = sp.thickness * f.length;
          const double values[5] = {sp.force[0], sp.force[1], sp.force[2], sp.force[0] / area, sp.force[1] / area};
          for (unsigned int k = 0; k < 5; ++k)
            forces[k].push_back(sp.broken ? 0.0 : values[k]);
          broken.push_back(sp.broken ? 1 : 0);
        }
      // VTK XML with inline binary arrays: base64 of a UInt64 byte count and the raw
      // little-endian values (a 100,000-cell network writes in a fraction of the ASCII time).
      out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
             "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece "
             "NumberOfPoints=\""
          << points.size() << "\" NumberOfCells=\"" << types.size() << "\">\n<Points>\n";
      std::vector<double> xyz;
      xyz.reserve(3 * points.size());
      for (const auto &p : points)
        xyz.insert(xyz.end(), {p[0], p[1], 0.0});
      const auto array = [&](const char *type, const char *name, const unsigned int components,
                             const auto &values) {
        out << "<DataArray type=\"" << type << "\"" << (name[0] ? " Name=\"" : "") << name
            << (name[0] ? "\"" : "") << " NumberOfComponents=\"" << components
            << "\" format=\"binary\">\n";
        Output::write_base64_array(out, values);
        out << "\n</DataArray>\n";
      };
      array("Float64", "", 3, xyz);
      out << "</Points>\n<Cells>\n";
      array("Int64", "connectivity", 1, std::vector<std::int64_t>(connectivity.begin(), connectivity.end()));
      array("Int64", "offsets", 1, std::vector<std::int64_t>(offsets.begin(), offsets.end()));
      array("UInt8", "types", 1, std::vector<std::uint8_t>(types.begin(), types.end()));
      out << "</Cells>\n<PointData Vectors=\"displacement\">\n";
      std::vector<double> displacement_3d; // (u_x, u_y, 0)
      displacement_3d.reserve(3 * points.size());
      for (unsigned int k = 0; k < points.size(); ++k)
        displacement_3d.insert(displacement_3d.end(), {displacement[2 * k], displacement[2 * k + 1], 0.0});
      array("Float64", "displacement", 3, displacement_3d);
      out << "</PointData>\n<CellData>\n";
      const std::vector<const std::vector<int> *>    integers{&cell_index, &facet_index, &body, &broken, &part, &loose};
      const std::vector<const std::vector<double> *> reals{&theta, &h1, &forces[0], &forces[1], &forces[2], &forces[3], &forces[4]};
      for (unsigned int k = 0; k < vtu_cell_fields.size(); ++k)
        if (k < integers.size())
          array("Int32", vtu_cell_fields[k], 1, std::vector<std::int32_t>(integers[k]->begin(), integers[k]->end()));
        else
          array("Float64", vtu_cell_fields[k], 1, *reals[k - integers.size()]);
      out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    }



    void
    Model::write_fields(const double t, Output::FieldWriter &writer)
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
                            for (unsigned int k = 0; k < vtu_cell_fields.size(); ++k)
                              out << "<PDataArray type=\"" << (k < 6 ? "Int32" : "Float64")
                                  << "\" Name=\"" << vtu_cell_fields[k] << "\" NumberOfComponents=\"1\"/>\n";
                            out << "</PCellData>\n<PPoints>\n<PDataArray type=\"Float64\" "
                                   "NumberOfComponents=\"3\"/>\n</PPoints>\n";
                            for (const auto &piece : pieces)
                              out << "<Piece Source=\"" << piece << "\"/>\n";
                            out << "</PUnstructuredGrid>\n</VTKFile>\n";
                          },
                          t);
    }



    void
    Model::write_spring_table() const
    {
      if (!scene.is_root())
        return;
      Output::CsvWriter out(method.output_file("springs.csv"),
                            {"a", "b", "x", "y", "n_x", "n_y", "length", "distance", "thickness",
                             "k_n", "k_t", "k_phi",
                             "delta_n", "delta_t", "phi", "f_n", "f_t", "m", "H1_n", "H1_t", "H1_m",
                             "broken"});
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const Facet<2>   &f  = network.facets[e];
          const Springs &sp = springs[e];
          std::vector<double> row{double(f.a), double(f.b), f.midpoint[0], f.midpoint[1], f.normal[0],
                                  f.normal[1], f.length, f.distance, sp.thickness, sp.k[0], sp.k[1],
                                  sp.k[2], sp.delta[0], sp.delta[1],
                                  sp.delta[2], sp.force[0], sp.force[1], sp.force[2]};
          for (unsigned int i = 0; i < 3; ++i)
            row.push_back(h1(e, i));
          row.push_back(sp.broken ? 1 : 0);
          out.add_row(row);
        }
      out.commit();
    }
  } // namespace RBSN
} // namespace hysteron
