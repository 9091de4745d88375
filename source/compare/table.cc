#include <deal.II/base/numbers.h>

#include <hysteron/base/exceptions.h>

#include "compare/compare.h"
#include "compare/text.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace hysteron
{
  namespace Compare
  {
    using internal::split;
    using internal::trim;

    namespace
    {
      /// Parse a whole field as a finite number (locale independent).
      bool
      parse_number(const std::string &field, double &value)
      {
        const char *begin = field.data();
        const char *end   = field.data() + field.size();
        if (begin != end && *begin == '+')
          ++begin;
        if (begin != end && (*begin == '+' || *begin == '-') && begin != field.data())
          return false;
        const auto result = std::from_chars(begin, end, value);
        return begin != end && result.ec == std::errc() && result.ptr == end &&
               std::isfinite(value);
      }
    } // namespace



    unsigned int
    Table::n_rows() const
    {
      return values.empty() ? 0 : values.front().size();
    }



    unsigned int
    Table::column_index(const std::string &name) const
    {
      const auto it = std::find(columns.begin(), columns.end(), name);
      return it == columns.end() ? dealii::numbers::invalid_unsigned_int
                                 : static_cast<unsigned int>(it - columns.begin());
    }



    void
    Table::add_row(const std::vector<double> &row)
    {
      if (row.size() != columns.size())
        throw std::logic_error("Table::add_row: " + std::to_string(row.size()) + " values for " +
                               std::to_string(columns.size()) + " columns");
      values.resize(columns.size());
      for (std::size_t c = 0; c < row.size(); ++c)
        values[c].push_back(row[c]);
    }



    std::string
    Table::where(const unsigned int row) const
    {
      if (row < lines.size())
        return source + ":" + std::to_string(lines[row]);
      return source + ", row " + std::to_string(row + 1);
    }



    Table
    read_csv(const std::string &file)
    {
      std::ifstream in(file);
      if (!in)
        throw InputError(file, std::string("cannot open the file: ") + std::strerror(errno));

      Table table;
      table.source = file;
      std::string line;
      if (!std::getline(in, line) || trim(line).empty())
        throw InputError(file + ":1", "no header line");
      table.columns = split(line);
      for (std::size_t c = 0; c < table.columns.size(); ++c)
        {
          require(!table.columns[c].empty(),
                  file + ":1",
                  "column " + std::to_string(c + 1) + " has no name");
          require(std::find(table.columns.begin(), table.columns.begin() + c, table.columns[c]) ==
                    table.columns.begin() + c,
                  file + ":1",
                  "the column name '" + table.columns[c] + "' appears twice");
        }
      table.values.resize(table.columns.size());

      for (unsigned int number_of_line = 2; std::getline(in, line); ++number_of_line)
        {
          if (trim(line).empty())
            continue;
          const std::vector<std::string> fields = split(line);
          const std::string              where  = file + ":" + std::to_string(number_of_line);
          require(fields.size() == table.columns.size(),
                  where,
                  "the row has " + std::to_string(fields.size()) + " values, the header has " +
                    std::to_string(table.columns.size()) + " columns");
          for (std::size_t c = 0; c < fields.size(); ++c)
            {
              double value = 0;
              require(parse_number(fields[c], value),
                      where,
                      "'" + fields[c] + "' in column '" + table.columns[c] +
                        "' is not a finite number");
              table.values[c].push_back(value);
            }
          table.lines.push_back(number_of_line);
        }
      if (in.bad())
        throw InputError(file, std::string("cannot read the file: ") + std::strerror(errno));
      return table;
    }
  } // namespace Compare
} // namespace hysteron
