// The network's fields: its cells and facets as one VTK unstructured grid (VTU, written by
// hand with inline binary arrays) per rank, and the PVTU record of the ranks' pieces.
#include <deal.II/base/mpi.h>

#include <hysteron/base/output.h>
#include "rbsn/model.h"

#include "rbsn/rigid_motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

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

      /// VTK's cell types.
      constexpr std::uint8_t vtk_line = 3, vtk_polygon = 7, vtk_polyhedron = 42;

      /// The data of one VTK cell: the integer fields (vtu_integer_fields), the rotation
      /// (facets: 0) and the real fields after it (reals[0], the rotation's place, unused).
      template <int dim>
      struct VtuCellData
      {
        VtuCellData(const std::array<int, 6> &integers, const unsigned int n_reals)
          : integers(integers)
          , reals(n_reals, 0.0)
        {}

        std::array<int, 6>                   integers;
        std::array<double, dim == 2 ? 1 : 3> rotation{};
        std::vector<double>                  reals;
      };

      /**
       * The arrays of one rank's VTU: the points, each with the displacement of the cell
       * it belongs to, the VTK cells (lines, polygons, polyhedra) and their data;
       * write() writes them as VTK XML.
       */
      template <int dim>
      class VtuPiece
      {
      public:
        /// The displacement of point p moved with local cell c.
        using Motion = std::function<dealii::Tensor<1, dim>(const dealii::Point<dim> &p, unsigned int c)>;

        explicit VtuPiece(Motion motion)
          : motion(std::move(motion))
          , reals(vtu_real_fields<dim>().size())
        {}

        /// A line or polygon of the points @p loop, moved with cell @p c.
        template <typename Points>
        void
        add_cell(const Points &loop, const unsigned int c, const std::uint8_t type, const VtuCellData<dim> &data)
        {
          for (const auto &p : loop)
            connectivity.push_back(add_point(p, c));
          offsets.push_back(connectivity.size());
          types.push_back(type);
          face_offsets.push_back(-1);
          add_data(data);
        }

        /**
         * A convex piece of cell @p c (3D): its points, each once (its faces share them, so
         * that its surface is closed for VTK: every edge in two faces), and its faces as
         * (count, then per face the number of its points and their ids). The faces of a
         * piece hold the same vertices bit for bit.
         */
        void
        add_polyhedron(const std::vector<std::vector<dealii::Point<dim>>> &piece,
                       const unsigned int                                  c,
                       const VtuCellData<dim>                             &data)
        {
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
          types.push_back(vtk_polyhedron);
          add_data(data);
        }

        /// VTK XML with inline binary arrays: base64 of a UInt64 byte count and the raw
        /// little-endian values (a 100,000-cell network writes in a fraction of the ASCII
        /// time).
        void
        write(std::ostream &out) const
        {
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
          const std::vector<const char *> reals_names = vtu_real_fields<dim>();
          for (unsigned int k = 0; k < reals_names.size(); ++k)
            if (k == 0)
              array("Float64", reals_names[k], dim == 2 ? 1 : 3, rotations);
            else
              array("Float64", reals_names[k], 1, reals[k]);
          out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
        }

      private:
        /// Point @p p of cell @p c and its displacement; returns its number.
        std::int64_t
        add_point(const dealii::Point<dim> &p, const unsigned int c)
        {
          const dealii::Tensor<1, dim> w = motion(p, c);
          points.push_back(p);
          for (unsigned int d = 0; d < dim; ++d)
            displacement.push_back(w[d]);
          return static_cast<std::int64_t>(points.size() - 1);
        }

        void
        add_data(const VtuCellData<dim> &data)
        {
          for (unsigned int k = 0; k < data.integers.size(); ++k)
            integers[k].push_back(data.integers[k]);
          rotations.insert(rotations.end(), data.rotation.begin(), data.rotation.end());
          for (unsigned int k = 1; k < data.reals.size(); ++k)
            reals[k].push_back(data.reals[k]);
        }

        Motion                           motion;
        std::vector<dealii::Point<dim>>  points;
        std::vector<double>              displacement;
        std::vector<std::int64_t>        offsets, connectivity, faces, face_offsets;
        std::vector<std::uint8_t>        types;
        std::array<std::vector<int>, 6>  integers;
        std::vector<double>              rotations;
        std::vector<std::vector<double>> reals;
      };
    } // namespace



    template <int dim>
    void
    Model<dim>::write_vtu(std::ostream &out) const
    {
      // The cells (2D: polygons; 3D: the convex polyhedra of each cell) moved rigidly
      // (point data "displacement") and the facets (2D: lines; 3D: polygons), in one
      // unstructured grid. Each rank writes its own cells and facets.
      VtuPiece<dim> piece([this](const dealii::Point<dim> &p, const unsigned int c) {
        std::array<double, n_dofs> U;
        for (unsigned int k = 0; k < n_dofs; ++k)
          U[k] = u.local_element(n_dofs * c + k);
        return rigid_motion<dim>(U, p - local_nuclei[c]);
      });
      const unsigned int n_reals = vtu_real_fields<dim>().size();

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

      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          VtuCellData<dim> data({{int(cell_id[c]), -1, int(cell_body[c]), 0, int(fragment[c]), released[c] ? 1 : 0}},
                                n_reals);
          for (unsigned int k = 0; k < data.rotation.size(); ++k)
            data.rotation[k] = u.local_element(n_dofs * c + dim + k);
          data.reals[1] = cell_h1[c];
          if constexpr (dim == 2)
            for (const auto &loop : network.cells[c].outline)
              piece.add_cell(loop, c, vtk_polygon, data);
          else
            for (const auto &convex_piece : network.cells[c].pieces)
              piece.add_polyhedron(convex_piece, c, data);
        }

      // Every facet (moved with cell a): its spring forces, stresses and H1 (the largest
      // of its springs'); broken ones have broken = 1 and no force.
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const Springs<dim> &sp = springs[e];
          const Facet<dim>   &f  = network.facets[e];
          VtuCellData<dim>    data(
            {{-1, int(facet_id[e]), int(cell_body[f.a]), sp.broken ? 1 : 0, int(fragment[f.a]), released[f.a] ? 1 : 0}},
            n_reals);
          for (unsigned int i = 0; i < n_dofs; ++i)
            data.reals[1] = std::max(data.reals[1], this->h1(e, i));
          if (!sp.broken)
            {
              for (unsigned int i = 0; i < n_dofs; ++i)
                data.reals[2 + i] = sp.force[i];
              if constexpr (dim == 2)
                {
                  const double area = sp.thickness * f.length;
                  data.reals[5]     = sp.force[0] / area;
                  data.reals[6]     = sp.force[1] / area;
                }
              else
                {
                  data.reals[8] = sp.force[0] / sp.area;
                  data.reals[9] = std::hypot(sp.force[1], sp.force[2]) / sp.area;
                }
            }
          if constexpr (dim == 2)
            piece.add_cell(std::array<dealii::Point<2>, 2>{{f.p3, f.p4}}, f.a, vtk_line, data);
          else
            for (const auto &polygon : f.polygons)
              piece.add_cell(polygon, f.a, vtk_polygon, data);
        }
      piece.write(out);
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



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
