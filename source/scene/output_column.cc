#include <hysteron/base/exceptions.h>
#include <hysteron/scene/output_column.h>

#include <algorithm>
#include <memory>

namespace hysteron
{
  namespace PointData
  {
    namespace
    {
      template <int dim>
      std::vector<std::unique_ptr<Column<dim>>> &
      selected()
      {
        static std::vector<std::unique_ptr<Column<dim>>> columns;
        return columns;
      }

      /// The number of values of each selected column (names() allocates).
      template <int dim>
      std::vector<unsigned int> &
      widths()
      {
        static std::vector<unsigned int> n;
        return n;
      }
    } // namespace

    template <int dim>
    const std::vector<std::unique_ptr<Column<dim>>> &
    additional_columns()
    {
      return selected<dim>();
    }

    template <int dim>
    void
    evaluate_additional_columns(const PointView<dim> &point, double *out)
    {
      const auto &columns = selected<dim>();
      const auto &n       = widths<dim>();
      for (unsigned int i = 0; i < columns.size(); ++i)
        {
          columns[i]->evaluate(point, out);
          out += n[i];
        }
    }

    template <int dim>
    void
    select_additional_columns(const std::vector<std::string> &names, const std::string &where)
    {
      auto &columns = selected<dim>();
      columns.clear();
      widths<dim>().clear();
      std::vector<std::string> seen;
      for (const auto &name : names)
        {
          require(std::find(seen.begin(), seen.end(), name) == seen.end(),
                  where,
                  "'" + name + "' is named twice");
          seen.push_back(name);
          columns.push_back(ColumnRegistry<dim>::create(name, where));
          widths<dim>().push_back(columns.back()->names().size());
        }
    }

    template const std::vector<std::unique_ptr<Column<2>>> &
    additional_columns<2>();
    template const std::vector<std::unique_ptr<Column<3>>> &
    additional_columns<3>();
    template void
    evaluate_additional_columns<2>(const PointView<2> &, double *);
    template void
    evaluate_additional_columns<3>(const PointView<3> &, double *);
    template void
    select_additional_columns<2>(const std::vector<std::string> &, const std::string &);
    template void
    select_additional_columns<3>(const std::vector<std::string> &, const std::string &);
  } // namespace PointData
} // namespace hysteron
