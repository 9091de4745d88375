// Gmsh mesh files for the FEM: reading with clear errors, physical names, element numbers.
#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include <hysteron/base/exceptions.h>

#include "fem/mesh_file.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <tuple>

namespace hysteron
{
  namespace FEM
  {
    namespace MeshFile
    {
      namespace
      {
        /// @p line without a trailing carriage return and surrounding blanks.
        std::string
        clean(const std::string &line)
        {
          return dealii::Utilities::trim(line.substr(0, line.find_last_not_of('\r') + 1));
        }

        /// A line as a message shows it: at most 60 characters, other bytes than printable
        /// ASCII as '?'.
        std::string
        quoted(const std::string &line)
        {
          std::string shown = line.size() > 60 ? line.substr(0, 57) + "..." : line;
          for (char &c : shown)
            if (c < 32 || c > 126)
              c = '?';
          return "'" + shown + "'";
        }

        /// Whether every blank-separated token of @p line is a number.
        bool
        numbers_only(const std::string &line)
        {
          std::istringstream in(line);
          std::string        token;
          while (in >> token)
            {
              char *end = nullptr;
              std::strtod(token.c_str(), &end);
              if (end != token.c_str() + token.size())
                return false;
            }
          return true;
        }

        struct Header
        {
          bool   ascii   = true;
          double version = 0;
        };

        /// The $MeshFormat section of the first two lines; an InputError if it is not there.
        Header
        check_header(const std::string &file)
        {
          std::ifstream in(file, std::ios::binary);
          std::string   line;
          require(static_cast<bool>(std::getline(in, line)),
                  where,
                  "'" + file + "' is empty; a Gmsh mesh file starts with $MeshFormat");
          if (line.compare(0, 3, "\xEF\xBB\xBF") == 0) // a UTF-8 byte-order mark
            line.erase(0, 3);
          require(clean(line) == "$MeshFormat",
                  where,
                  "'" + file + "', line 1: " + quoted(clean(line)) +
                    ": this is not a Gmsh mesh file, which starts with $MeshFormat (the format has "
                    "no comment lines)");
          Header header;
          int    type = -1, size = 0;
          std::getline(in, line);
          std::istringstream row(line);
          require(static_cast<bool>(row >> header.version >> type >> size) && header.version >= 2 &&
                    header.version < 5 && (type == 0 || type == 1),
                  where,
                  "'" + file + "', line 2: " + quoted(clean(line)) +
                    ": expected the format version (2.2 or 4.1), the file type (0 ASCII, 1 binary) "
                    "and the size of a double (8)");
          header.ascii = type == 0;
          return header;
        }

        /**
         * Where an ASCII file breaks Gmsh's format, as ", line <n>: <what>", or "" if nowhere
         * that this scan sees: a line of $Nodes or $Elements that is not a list of numbers, or
         * a section without its end.
         */
        std::string
        first_bad_line(const std::string &file)
        {
          std::ifstream in(file, std::ios::binary);
          std::string   line, section;
          unsigned long number = 0, opened = 0;
          while (std::getline(in, line))
            {
              ++number;
              const std::string text = clean(line);
              if (!text.empty() && text[0] == '$')
                {
                  if (section.empty())
                    {
                      section = text;
                      opened  = number;
                    }
                  else if (text == "$End" + section.substr(1))
                    section.clear();
                  else
                    return ", line " + std::to_string(number) + ": " + quoted(text) + " inside the section " +
                           section + " of line " + std::to_string(opened) + ", which has no $End" +
                           section.substr(1);
                }
              else if ((section == "$Nodes" || section == "$Elements") && !numbers_only(text))
                return ", line " + std::to_string(number) + ": " + quoted(text) + " in " + section +
                       " is not a list of numbers";
            }
          if (!section.empty())
            return ", line " + std::to_string(opened) + ": the section " + section + " has no $End" +
                   section.substr(1);
          return "";
        }

        /// The message of the exception being handled, whatever its type (call in a catch).
        std::string
        library_message()
        {
          try
            {
              throw;
            }
          catch (const std::string &message)
            {
              return message;
            }
          catch (const char *message)
            {
              return message;
            }
          catch (const dealii::ExceptionBase &e)
            {
              std::ostringstream m;
              e.print_info(m);
              return clean(m.str());
            }
          catch (const std::exception &e)
            {
              return e.what();
            }
          catch (...)
            {
              return "the reader failed with an exception of an unknown type";
            }
        }

        /// The Gmsh element type of a first-order cell with @p n_vertices in @p dim.
        int
        element_type(const int dim, const std::size_t n_vertices)
        {
          if (dim == 2)
            return n_vertices == 3 ? 2 : 3;
          return n_vertices == 4 ? 4 : 5;
        }

        /// The nodes of an ASCII file whose points are within @p tolerance of one of @p x.
        template <int dim>
        std::map<long, dealii::Point<dim>>
        nodes_at(std::istream &in, const bool version4, const std::vector<dealii::Point<dim>> &x, const double tolerance)
        {
          std::map<long, dealii::Point<dim>> found;
          // A node's coordinates from @p row.
          const auto consider = [&](const long tag, std::istream &row) {
            double c[3] = {0, 0, 0};
            row >> c[0] >> c[1] >> c[2];
            dealii::Point<dim> p;
            for (unsigned int d = 0; d < dim; ++d)
              p[d] = c[d];
            for (const auto &v : x)
              if (v.distance(p) <= tolerance)
                found[tag] = p;
          };
          std::string line;
          std::getline(in, line);
          std::istringstream head(line);
          long               blocks = 0;
          head >> blocks;
          if (!version4)
            {
              for (long k = 0; k < blocks && std::getline(in, line); ++k)
                {
                  std::istringstream row(line);
                  long               tag = 0;
                  row >> tag;
                  consider(tag, row);
                }
              return found;
            }
          for (long b = 0; b < blocks && std::getline(in, line); ++b)
            {
              std::istringstream block(line);
              long               entity_dim = 0, entity = 0, parametric = 0, n = 0;
              block >> entity_dim >> entity >> parametric >> n;
              std::vector<long> tags(std::max(0L, n));
              for (long &tag : tags)
                {
                  std::getline(in, line);
                  tag = std::atol(line.c_str());
                }
              for (const long tag : tags)
                if (std::getline(in, line))
                  {
                    std::istringstream row(line);
                    consider(tag, row);
                  }
            }
          return found;
        }

        /// The tag of the first element of type @p type in $Elements on nodes at the points
        /// @p x (each node within @p tolerance of another vertex), or -1.
        template <int dim>
        long
        element_at(std::istream                             &in,
                   const bool                                version4,
                   const int                                 type,
                   const std::map<long, dealii::Point<dim>> &nodes,
                   const std::vector<dealii::Point<dim>>    &x,
                   const double                              tolerance)
        {
          // Whether the rest of @p row are the nodes of the cell.
          const auto is_cell = [&](std::istringstream &row) {
            std::vector<bool> used(x.size(), false);
            long              node = 0, n = 0;
            while (row >> node)
              {
                const auto it = nodes.find(node);
                if (it == nodes.end() || ++n > static_cast<long>(x.size()))
                  return false;
                bool matched = false;
                for (unsigned int v = 0; v < x.size() && !matched; ++v)
                  if (!used[v] && x[v].distance(it->second) <= tolerance)
                    used[v] = matched = true;
                if (!matched)
                  return false;
              }
            return n == static_cast<long>(x.size());
          };
          std::string line;
          std::getline(in, line);
          const long count = std::atol(line.c_str()); // elements (2), entity blocks (4)
          if (!version4)
            {
              for (long k = 0; k < count && std::getline(in, line); ++k)
                {
                  std::istringstream row(line);
                  long               tag = 0, element = 0, n_tags = 0, skip = 0;
                  row >> tag >> element >> n_tags;
                  for (long t = 0; t < n_tags; ++t)
                    row >> skip;
                  if (element == type && is_cell(row))
                    return tag;
                }
              return -1;
            }
          for (long b = 0; b < count && std::getline(in, line); ++b)
            {
              std::istringstream block(line);
              long               entity_dim = 0, entity = 0, block_type = 0, n = 0;
              block >> entity_dim >> entity >> block_type >> n;
              for (long k = 0; k < n && std::getline(in, line); ++k)
                {
                  std::istringstream row(line);
                  long               tag = 0;
                  row >> tag;
                  if (block_type == type && is_cell(row))
                    return tag;
                }
            }
          return -1;
        }
      } // namespace



      template <int dim>
      void
      read(const std::string                  &file,
           std::vector<dealii::Point<dim>>    &vertices,
           std::vector<dealii::CellData<dim>> &cells,
           dealii::SubCellData                &subcells)
      {
        const Header               header = check_header(file);
        dealii::Triangulation<dim> mesh;
        try
          {
            dealii::GridIn<dim> in;
            in.attach_triangulation(mesh);
            in.read_msh(file);
          }
        catch (...)
          {
            const std::string message = library_message();
            throw InputError(where,
                             "cannot read '" + file + "'" + (header.ascii ? first_bad_line(file) : "") +
                               ": " + message);
          }
        require(mesh.n_active_cells() > 0,
                where,
                "'" + file + "' has no " + (dim == 2 ? "2D" : "3D") + " cells");
        std::tie(vertices, cells, subcells) = dealii::GridTools::get_coarse_mesh_description(mesh);
      }



      std::map<std::string, std::pair<unsigned int, unsigned int>>
      physical_names(const std::string &file)
      {
        std::map<std::string, std::pair<unsigned int, unsigned int>> names;
        std::ifstream in(file, std::ios::binary);
        std::string   line;
        while (std::getline(in, line))
          {
            line = clean(line);
            if (line == "$Nodes" || line == "$Entities")
              break;
            if (line != "$PhysicalNames")
              continue;
            unsigned int n = 0;
            if (!std::getline(in, line) || !(std::istringstream(line) >> n))
              throw InputError(where, "'" + file + "': $PhysicalNames has no count");
            for (unsigned int k = 0; k < n && std::getline(in, line); ++k)
              {
                std::istringstream row(line);
                unsigned int       dim = 0, tag = 0;
                const auto         open = line.find('"'), close = line.rfind('"');
                if (!(row >> dim >> tag) || open == std::string::npos || close <= open)
                  throw InputError(where, "'" + file + "': cannot read the physical name " + quoted(clean(line)));
                names[line.substr(open + 1, close - open - 1)] = {dim, tag};
              }
            break;
          }
        return names;
      }



      template <int dim>
      std::string
      cell_name(const std::string                     &file,
                const unsigned int                     index,
                const std::vector<dealii::Point<dim>> &x,
                const double                           mesh_size)
      {
        const std::string fallback = "cell " + std::to_string(index);
        Header            header;
        try
          {
            header = check_header(file);
          }
        catch (const InputError &)
          {
            return fallback;
          }
        if (!header.ascii)
          return fallback;
        const double tolerance = 2e-8 * mesh_size;

        std::ifstream                      in(file, std::ios::binary);
        std::string                        line;
        std::map<long, dealii::Point<dim>> nodes;
        while (std::getline(in, line))
          if (clean(line) == "$Nodes")
            nodes = nodes_at(in, header.version >= 4, x, tolerance);
          else if (clean(line) == "$Elements")
            {
              const long tag =
                element_at(in, header.version >= 4, element_type(dim, x.size()), nodes, x, tolerance);
              return tag >= 0 ? "element " + std::to_string(tag) + " (" + fallback + ")" : fallback;
            }
        return fallback;
      }



      template void
      read(const std::string &, std::vector<dealii::Point<2>> &, std::vector<dealii::CellData<2>> &, dealii::SubCellData &);
      template void
      read(const std::string &, std::vector<dealii::Point<3>> &, std::vector<dealii::CellData<3>> &, dealii::SubCellData &);
      template std::string
      cell_name(const std::string &, const unsigned int, const std::vector<dealii::Point<2>> &, const double);
      template std::string
      cell_name(const std::string &, const unsigned int, const std::vector<dealii::Point<3>> &, const double);
    } // namespace MeshFile
  }   // namespace FEM
} // namespace hysteron
