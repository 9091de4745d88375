// Gmsh mesh files for the FEM: read with every library failure turned into an InputError
// that names the file (and the line when it is known), the named physical groups, and the
// element number of a cell for messages.
#ifndef hysteron_fem_mesh_file_h
#define hysteron_fem_mesh_file_h

#include <deal.II/base/point.h>

#include <deal.II/grid/tria_description.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace FEM
  {
    namespace MeshFile
    {
      /// The parameter every message of this namespace names.
      inline const std::string where = "FEM/Mesh/Mesh file";

      /**
       * Read the Gmsh file @p file (deal.II's GridIn, through the Gmsh library) into the
       * arrays of Triangulation::create_triangulation(): the cells' material ids are their
       * physical tags, the boundary faces' ids in @p subcells theirs. A file whose first
       * line is not `$MeshFormat` is refused before the reader sees it (Gmsh would run any
       * other text as a .geo script). Whatever the reader throws (a std::string from Gmsh,
       * a deal.II exception, a std::exception, anything) becomes an InputError naming the
       * file and, for ASCII files, the first line that is not what Gmsh's format allows.
       * A file without cells of dimension @p dim is refused.
       */
      template <int dim>
      void
      read(const std::string                  &file,
           std::vector<dealii::Point<dim>>    &vertices,
           std::vector<dealii::CellData<dim>> &cells,
           dealii::SubCellData                &subcells);

      /// The $PhysicalNames section (versions 2 and 4, ASCII or binary: the section is text
      /// in both): name -> (dimension, tag).
      std::map<std::string, std::pair<unsigned int, unsigned int>>
      physical_names(const std::string &file);

      /**
       * How a message names cell @p index (in the order of read()) with vertices @p x: "element
       * <n> (cell <index>)" if @p file is ASCII and lists an element of this kind on nodes at
       * these points, else "cell <index>". Points match to 2e-8 of @p mesh_size, the diagonal
       * of the mesh's bounding box (Gmsh merges nodes closer than 1e-8 of it).
       */
      template <int dim>
      std::string
      cell_name(const std::string                     &file,
                const unsigned int                     index,
                const std::vector<dealii::Point<dim>> &x,
                const double                           mesh_size);
    } // namespace MeshFile
  }   // namespace FEM
} // namespace hysteron

#endif
