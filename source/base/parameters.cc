#include <deal.II/base/utilities.h>

#include <hysteron/base/parameters.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace hysteron
{
  Section::Section(dealii::ParameterHandler &prm, const std::vector<std::string> &path)
    : prm(prm)
    , path(path)
    , n_entered(path.size())
  {
    for (const auto &p : path)
      prm.enter_subsection(p);
  }

  Section::Section(const Section &parent, const std::string &name)
    : prm(parent.prm)
    , path(parent.path)
    , n_entered(1)
  {
    path.push_back(name);
    prm.enter_subsection(name);
  }

  Section::~Section()
  {
    for (std::size_t i = 0; i < n_entered; ++i)
      prm.leave_subsection();
  }

  std::string
  Section::where(const std::string &entry) const
  {
    std::string s;
    for (const auto &p : path)
      s += p + "/";
    return s + entry;
  }

  std::string
  Section::get(const std::string &entry) const
  {
    return prm.get(entry);
  }

  bool
  Section::get_bool(const std::string &entry) const
  {
    return prm.get_bool(entry);
  }

  long
  Section::get_integer(const std::string &entry) const
  {
    return prm.get_integer(entry);
  }

  double
  Section::get_double(const std::string &entry) const
  {
    const double v = prm.get_double(entry);
    require(std::isfinite(v), where(entry), "must be a finite number (got " + get(entry) + ")");
    return v;
  }

  double
  Section::get_positive(const std::string &entry) const
  {
    const double v = get_double(entry);
    require(v > 0, where(entry), "must be > 0 (got " + get(entry) + ")");
    return v;
  }

  double
  Section::get_non_negative(const std::string &entry) const
  {
    const double v = get_double(entry);
    require(v >= 0, where(entry), "must be >= 0 (got " + get(entry) + ")");
    return v;
  }

  double
  Section::get_in_open_interval(const std::string &entry,
                                const double       lower,
                                const double       upper) const
  {
    const double       v = get_double(entry);
    std::ostringstream s;
    s << "must lie in the open interval (" << lower << ", " << upper << ") (got " << get(entry)
      << ")";
    require(v > lower && v < upper, where(entry), s.str());
    return v;
  }

  std::vector<std::string>
  Section::get_list(const std::string &entry) const
  {
    std::vector<std::string> out;
    for (const auto &s : dealii::Utilities::split_string_list(get(entry), ','))
      if (!s.empty())
        out.push_back(s);
    return out;
  }

  template <int dim>
  std::unique_ptr<dealii::FunctionParser<dim>>
  parse_function(const std::string &expression,
                 const std::string &variables,
                 const bool         time_dependent,
                 const std::string &where)
  {
    return parse_vector_function<dim>(expression, 1, variables, time_dependent, where);
  }

  template <int dim>
  std::unique_ptr<dealii::FunctionParser<dim>>
  parse_vector_function(const std::string &expression,
                        const unsigned int n_components,
                        const std::string &variables,
                        const bool         time_dependent,
                        const std::string &where)
  {
    require(!dealii::Utilities::trim(expression).empty(), where, "the expression is empty");
    const auto components = dealii::Utilities::split_string_list(expression, ';');
    require(components.size() == n_components,
            where,
            "'" + expression + "' has " + std::to_string(components.size()) +
              " component(s) separated by ';', " + std::to_string(n_components) +
              " expected");
    for (const auto &c : components)
      require(!c.empty(), where, "an empty component in '" + expression + "'");
    auto function = std::make_unique<dealii::FunctionParser<dim>>(n_components);
    const std::map<std::string, double> constants{{"pi", M_PI}, {"e", M_E}};
    try
      {
        function->initialize(variables, components, constants, time_dependent);
        for (unsigned int c = 0; c < n_components; ++c)
          {
            const double v = function->value(dealii::Point<dim>(), c);
            (void)v;
          }
      }
    catch (const dealii::ExceptionBase &e)
      {
        std::ostringstream info;
        e.print_info(info);
        std::string message = dealii::Utilities::trim(info.str());
        // print_info starts with the exception's own text; keep it on one line.
        for (auto &c : message)
          if (c == '\n')
            c = ' ';
        throw InputError(where,
                         "cannot parse the expression '" + expression + "' in the variables (" +
                           variables + "): " + message);
      }
    catch (const std::exception &e)
      {
        throw InputError(where, "cannot parse the expression '" + expression + "': " + e.what());
      }
    return function;
  }

  std::vector<std::string>
  parse_names(const std::string &list, const std::string &where)
  {
    std::vector<std::string> names;
    std::set<std::string>    seen;
    for (const auto &raw : dealii::Utilities::split_string_list(list, ','))
      {
        const std::string name = dealii::Utilities::trim(raw);
        require(!name.empty(), where, "an empty name in the list '" + list + "'");
        require(name.find_first_of("#\\") == std::string::npos,
                where,
                "the name '" + name + "' contains '#' or '\\'");
        require(seen.insert(name).second, where, "the name '" + name + "' appears twice");
        names.push_back(name);
      }
    return names;
  }

  template std::unique_ptr<dealii::FunctionParser<1>>
  parse_function<1>(const std::string &, const std::string &, bool, const std::string &);
  template std::unique_ptr<dealii::FunctionParser<1>>
  parse_vector_function<1>(const std::string &, unsigned int, const std::string &, bool, const std::string &);
  template std::unique_ptr<dealii::FunctionParser<2>>
  parse_function<2>(const std::string &, const std::string &, bool, const std::string &);
  template std::unique_ptr<dealii::FunctionParser<2>>
  parse_vector_function<2>(const std::string &, unsigned int, const std::string &, bool, const std::string &);
  template std::unique_ptr<dealii::FunctionParser<3>>
  parse_function<3>(const std::string &, const std::string &, bool, const std::string &);
  template std::unique_ptr<dealii::FunctionParser<3>>
  parse_vector_function<3>(const std::string &, unsigned int, const std::string &, bool, const std::string &);
} // namespace hysteron
