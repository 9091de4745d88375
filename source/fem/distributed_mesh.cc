// The FEM meshes that rank 0 makes whole (Gmsh files, the unstructured generator, triangles
// and tetrahedra, structured meshes too large to coarsen): checked and assigned to bodies on
// rank 0, refined, partitioned by METIS and described to every rank, which keeps only its
// own cells and their neighbours (parallel::fullydistributed::Triangulation).
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <deal.II/distributed/fully_distributed_tria.h>

#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>

#include "fem/fem.h"
#include <hysteron/geometry/mesh.h>

#include "fem/mesh_file.h"

#include <boost/serialization/map.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

#include <algorithm>
#include <iostream>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /// What rank 0 learns while it makes the serial mesh and every rank needs.
      struct SerialInfo
      {
        std::string  where, problem; ///< an InputError of rank 0
        std::string  failure;        ///< any other exception of rank 0
        double       n_cells = 0;    ///< before `Refinements`
        bool         simplex = false;
        std::vector<unsigned int> cell_tags; ///< the physical tags of the cells, sorted
        std::map<std::string, std::pair<unsigned int, unsigned int>> names; ///< $PhysicalNames
        std::vector<std::string>                                     warnings; ///< for stderr

        template <class Archive>
        void
        serialize(Archive &ar, const unsigned int)
        {
          ar &where &problem &failure &n_cells &simplex &cell_tags &names &warnings;
        }
      };

      /// The vertices of @p cell.
      template <int dim>
      std::vector<dealii::Point<dim>>
      points_of(const std::vector<dealii::Point<dim>> &vertices, const dealii::CellData<dim> &cell)
      {
        std::vector<dealii::Point<dim>> x;
        for (const unsigned int v : cell.vertices)
          x.push_back(vertices[v]);
        return x;
      }

      /**
       * Refuse a mesh that mixes kinds of cells, or has cells that are neither simplices nor
       * hypercubes, and check every cell's Jacobian (Geometry::check_cells(): inverted cells
       * repaired, a note for the log; a cell that cannot be used refused with its element
       * number and vertices).
       */
      template <int dim>
      void
      check_mesh(std::vector<dealii::Point<dim>>    &vertices,
                 std::vector<dealii::CellData<dim>> &cells,
                 const std::string                  &file,
                 SerialInfo                         &info)
      {
        const std::string where  = file.empty() ? "FEM/Mesh/Generator" : MeshFile::where;
        const std::string source = file.empty() ? "the generated mesh" : "'" + file + "'";
        const auto        first  = dealii::ReferenceCell::n_vertices_to_type(dim, cells.front().vertices.size());
        for (const auto &cell : cells)
          {
            const auto kind = dealii::ReferenceCell::n_vertices_to_type(dim, cell.vertices.size());
            require((kind == dealii::ReferenceCells::get_hypercube<dim>() ||
                     kind == dealii::ReferenceCells::get_simplex<dim>()) &&
                      kind == first,
                    where,
                    source + " has " + kind.to_string() + " and " + first.to_string() +
                      " cells; the fem method needs one kind: quadrilaterals or triangles (2D), "
                      "hexahedra or tetrahedra (3D)");
          }
        const Geometry::CellCheck check = Geometry::check_cells(vertices, cells);
        if (!check.valid)
          {
            const auto       &cell = cells[check.cell];
            dealii::Point<dim> lo = vertices[0], hi = vertices[0];
            for (const auto &p : vertices)
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lo[d] = std::min(lo[d], p[d]);
                  hi[d] = std::max(hi[d], p[d]);
                }
            const auto name = file.empty() ? "cell " + std::to_string(check.cell) :
                                             MeshFile::cell_name(file, check.cell, points_of(vertices, cell), lo.distance(hi));
            throw InputError(where,
                             source + ": " + name + " with the vertices " + Geometry::vertex_list(vertices, cell) +
                               " cannot carry finite elements: " + check.problem +
                               (file.empty() ? std::string(" (a defect of the generator: please report it)") :
                                               std::string(" (repair or remesh it in Gmsh)")));
          }
        if (check.inverted > 0)
          info.warnings.push_back(where + ": " + std::to_string(check.inverted) + " cell" +
                               (check.inverted > 1 ? "s" : "") + " of " + source +
                               (check.inverted > 1 ? " were" : " was") +
                               " inverted (vertices in the mirrored, in 2D clockwise, order) and " +
                               (check.inverted > 1 ? "are" : "is") + " repaired");
      }

      /**
       * Each cell's material id becomes body + n_bodies * (index of its physical tag in
       * @p tags), which refinement and the description carry to every rank (decoded by
       * make_distributed_mesh()). The body is the first whose shape contains the centre.
       */
      template <int dim>
      void
      assign_bodies(std::vector<dealii::Point<dim>>                  &vertices,
                    std::vector<dealii::CellData<dim>>               &cells,
                    const std::vector<const Geometry::Region<dim> *> &shapes,
                    const std::string                                &file,
                    std::vector<unsigned int>                        &tags)
      {
        tags.clear();
        for (const auto &cell : cells)
          tags.push_back(file.empty() ? 0 : cell.material_id);
        std::sort(tags.begin(), tags.end());
        tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
        const unsigned int n = shapes.size();
        for (auto &cell : cells)
          {
            if (!file.empty())
              {
                dealii::Point<dim> centre;
                double             diameter = 0;
                for (const unsigned int v : cell.vertices)
                  {
                    centre += vertices[v] / static_cast<double>(cell.vertices.size());
                    for (const unsigned int w : cell.vertices)
                      diameter = std::max(diameter, vertices[v].distance(vertices[w]));
                  }
                unsigned int body = n;
                for (unsigned int m = 0; m < n && body == n; ++m)
                  if (shapes[m]->contains(centre, 1e-9 * diameter))
                    body = m;
                if (body == n)
                  {
                    std::ostringstream p;
                    p << centre;
                    throw InputError(MeshFile::where,
                                     "the cell with centre (" + p.str() + ") of '" + file +
                                       "' lies in no body's Shape");
                  }
                const auto tag   = std::lower_bound(tags.begin(), tags.end(), cell.material_id) - tags.begin();
                cell.material_id = body + n * static_cast<unsigned int>(tag);
              }
          }
      }
    } // namespace



    template <int dim>
    void
    Solver<dim>::make_distributed_mesh(const std::vector<const Geometry::Region<dim> *> &shapes,
                                       const std::string                                &kind)
    {
      using namespace dealii;
      const MPI_Comm comm = this->get_scene().mpi_communicator();
      Triangulation<dim> serial; // rank 0
      SerialInfo         info;
      if (Utilities::MPI::this_mpi_process(comm) == 0)
        try
          {
            std::vector<Point<dim>>    vertices;
            std::vector<CellData<dim>> cells;
            SubCellData                subcells;
            const std::string          file = kind == "file" ? mesh_file : std::string();
            if (kind == "file")
              {
                MeshFile::read(mesh_file, vertices, cells, subcells);
                info.names = MeshFile::physical_names(mesh_file);
              }
            else
              {
                auto mesh = generated_mesh(shapes, kind);
                vertices  = std::move(mesh.vertices);
                cells     = std::move(mesh.cells);
              }
            check_mesh(vertices, cells, file, info);
            assign_bodies(vertices, cells, shapes, file, info.cell_tags);
            try
              {
                serial.create_triangulation(vertices, cells, subcells);
              }
            catch (const ExceptionBase &e)
              {
                std::ostringstream m;
                e.print_info(m);
                throw InputError(file.empty() ? "FEM/Mesh/Generator" : MeshFile::where,
                                 "cannot make a mesh of " + (file.empty() ? "the generated cells" : "'" + file + "'") +
                                   ": " + Utilities::trim(m.str()));
              }
            if (generate_simplices)
              {
                // Each quadrilateral into 8 triangles, each hexahedron into 24 tetrahedra
                // (material ids kept).
                Triangulation<dim> hypercubes(std::move(serial));
                GridGenerator::convert_hypercube_to_simplex_mesh(hypercubes, serial);
              }
            info.n_cells = serial.n_active_cells();
            info.simplex = serial.begin_active()->reference_cell() == ReferenceCells::get_simplex<dim>();
          }
        catch (const InputError &e)
          {
            info.where   = e.where();
            info.problem = e.problem();
          }
        catch (const std::exception &e)
          {
            info.failure = e.what();
          }
      info = Utilities::MPI::broadcast(comm, info, 0);
      if (!info.problem.empty())
        throw InputError(info.where, info.problem);
      AssertThrow(info.failure.empty(), ExcMessage("rank 0 could not make the mesh: " + info.failure));
      if (this->get_scene().is_root())
        for (const auto &warning : info.warnings)
          std::cerr << "hysteron: warning: " << warning << std::endl;
      simplex        = info.simplex;
      physical_names = info.names;
      check_memory(info.n_cells, 0, true);

      // Rank 0 refines and partitions the serial mesh and sends each rank the description
      // of its cells and their neighbours (a group of all ranks: only rank 0 reads).
      const auto description =
        TriangulationDescription::Utilities::create_description_from_triangulation_in_groups<dim, dim>(
          [&](Triangulation<dim> &tria) {
            tria = std::move(serial);
            tria.refine_global(refinements);
          },
          [](Triangulation<dim> &tria, const MPI_Comm c, const unsigned int) {
            GridTools::partition_triangulation(Utilities::MPI::n_mpi_processes(c), tria);
          },
          comm,
          Utilities::MPI::n_mpi_processes(comm));
      auto distributed = std::make_unique<parallel::fullydistributed::Triangulation<dim>>(comm);
      distributed->create_triangulation(description);
      triangulation = std::move(distributed);

      // Decode the material ids: the body, and the physical group of each cell.
      const unsigned int n_bodies = mesh_to_body.size();
      cell_group.assign(triangulation->n_active_cells(), 0);
      for (const auto &cell : triangulation->active_cell_iterators())
        if (!cell->is_artificial())
          {
            const unsigned int id = cell->material_id();
            if (!info.cell_tags.empty())
              cell_group[cell->active_cell_index()] = info.cell_tags[id / n_bodies];
            cell->set_material_id(id % n_bodies);
          }
    }



    template void Solver<2>::make_distributed_mesh(const std::vector<const Geometry::Region<2> *> &,
                                                   const std::string &);
    template void Solver<3>::make_distributed_mesh(const std::vector<const Geometry::Region<3> *> &,
                                                   const std::string &);
  } // namespace FEM
} // namespace hysteron
