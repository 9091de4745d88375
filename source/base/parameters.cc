#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/vector.h>

#include <hysteron/base/parameters.h>

#include <cctype>
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

  namespace
  {
    /**
     * A FunctionParser that checks every value it returns: NaN or infinity
     * throws NonFiniteExpression with the entry, the expression, the value and
     * the variables of the evaluation (x, y, z and t as the user named them).
     */
    template <int dim>
    class CheckedFunctionParser : public dealii::FunctionParser<dim>
    {
    public:
      CheckedFunctionParser(const unsigned int n_components,
                            const std::string &expression,
                            const std::string &variables,
                            const std::string &where)
        : dealii::FunctionParser<dim>(n_components)
        , expression(expression)
        , variables(dealii::Utilities::split_string_list(variables, ','))
        , where(where)
      {}

      double
      value(const dealii::Point<dim> &p, const unsigned int component = 0) const override
      {
        const double v = dealii::FunctionParser<dim>::value(p, component);
        if (!std::isfinite(v))
          fail(p, v);
        return v;
      }

      void
      vector_value(const dealii::Point<dim> &p, dealii::Vector<double> &values) const override
      {
        dealii::FunctionParser<dim>::vector_value(p, values);
        for (const double v : values)
          if (!std::isfinite(v))
            fail(p, v);
      }

    private:
      [[noreturn]] void
      fail(const dealii::Point<dim> &p, const double v) const
      {
        std::ostringstream s;
        s.precision(6);
        s << "the expression '" << expression << "' evaluates to " << v << " at ";
        for (unsigned int i = 0; i < variables.size(); ++i)
          {
            s << (i > 0 ? ", " : "") << variables[i] << " = ";
            if (i < dim)
              s << p[i];
            else
              s << this->get_time();
          }
        throw NonFiniteExpression(where, s.str());
      }

      const std::string              expression;
      const std::vector<std::string> variables; // the point's, then t if time dependent
      const std::string              where;
    };

    /// A call of rand() (not rand_seed(...)) in a muParser expression.
    bool
    calls_rand(const std::string &expression)
    {
      for (std::size_t at = expression.find("rand"); at != std::string::npos;
           at = expression.find("rand", at + 4))
        {
          const bool word_start =
            at == 0 || !(std::isalnum(static_cast<unsigned char>(expression[at - 1])) ||
                         expression[at - 1] == '_');
          std::size_t next = at + 4;
          while (next < expression.size() && std::isspace(static_cast<unsigned char>(expression[next])))
            ++next;
          if (word_start && next < expression.size() && expression[next] == '(')
            return true;
        }
      return false;
    }
  } // namespace

  void
  check_finite_in_time(const dealii::Function<1> &f, const double end_time, const unsigned int n_samples)
  {
    try
      {
        for (unsigned int i = 0; i <= n_samples; ++i)
          for (unsigned int c = 0; c < f.n_components; ++c)
            f.value(dealii::Point<1>(end_time * i / n_samples), c);
      }
    catch (const NonFiniteExpression &e)
      {
        throw InputError(e.where(),
                         e.problem() + " (expressions of time are checked at " +
                           std::to_string(n_samples + 1) + " times from 0 to the end time)");
      }
  }

  template <int dim>
  std::vector<dealii::Point<dim>>
  parse_points(const std::string &text, const std::string &where)
  {
    std::vector<dealii::Point<dim>> points;
    for (const auto &item : dealii::Utilities::split_string_list(text, ';'))
      {
        if (item.empty())
          continue;
        const auto items = dealii::Utilities::split_string_list(item, ',');
        require(items.size() == dim,
                where,
                "the point '" + item + "' has " + std::to_string(items.size()) +
                  " coordinates; a " + std::to_string(dim) + "D scene needs " + std::to_string(dim));
        dealii::Point<dim> p;
        for (unsigned int d = 0; d < dim; ++d)
          {
            try
              {
                p[d] = dealii::Utilities::string_to_double(items[d]);
              }
            catch (const dealii::ExceptionBase &)
              {
                throw InputError(where, "cannot read the point '" + item + "'");
              }
            require(std::isfinite(p[d]), where, "the point '" + item + "' has a coordinate that is not finite");
          }
        points.push_back(p);
      }
    return points;
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
    require(!calls_rand(expression),
            where,
            "rand() gives a new number at every evaluation, so runs could not be repeated: "
            "use rand_seed(<integer>), a fixed pseudo-random number, or `Random seed`");
    auto function =
      std::make_unique<CheckedFunctionParser<dim>>(n_components, expression, variables, where);
    const std::map<std::string, double> constants{{"pi", M_PI}, {"e", M_E}};
    try
      {
        function->initialize(variables, components, constants, time_dependent);
        for (unsigned int c = 0; c < n_components; ++c)
          {
            // Unchecked: a finite value at the origin is not required (1/x).
            const double v = function->dealii::FunctionParser<dim>::value(dealii::Point<dim>(), c);
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

  template std::vector<dealii::Point<1>>
  parse_points<1>(const std::string &, const std::string &);
  template std::vector<dealii::Point<2>>
  parse_points<2>(const std::string &, const std::string &);
  template std::vector<dealii::Point<3>>
  parse_points<3>(const std::string &, const std::string &);
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
