#include <hysteron/base/exceptions.h>
#include <hysteron/scene/output_column.h>

#include <algorithm>

namespace hysteron
{
  namespace PointData
  {
    template <int dim>
    void
    ColumnSelection<dim>::select(const std::vector<std::string> &names, const std::string &where)
    {
      columns.clear();
      widths.clear();
      std::vector<std::string> seen;
      for (const auto &name : names)
        {
          require(std::find(seen.begin(), seen.end(), name) == seen.end(),
                  where,
                  "'" + name + "' is named twice");
          seen.push_back(name);
          columns.push_back(ColumnRegistry<dim>::create(name, where));
          widths.push_back(columns.back()->names().size());
        }
    }

    template <int dim>
    std::vector<std::string>
    ColumnSelection<dim>::names() const
    {
      std::vector<std::string> all;
      for (const auto &column : columns)
        for (const auto &name : column->names())
          all.push_back(name);
      return all;
    }

    template <int dim>
    void
    ColumnSelection<dim>::evaluate(const PointView<dim> &point, double *out) const
    {
      for (unsigned int i = 0; i < columns.size(); ++i)
        {
          columns[i]->evaluate(point, out);
          out += widths[i];
        }
    }

    template class ColumnSelection<2>;
    template class ColumnSelection<3>;
  } // namespace PointData
} // namespace hysteron
