#ifndef hysteron_base_parameters_h
#define hysteron_base_parameters_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/exceptions.h>

#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * Reads entries of one subsection of a ParameterHandler and knows its path,
   * so that every rejected value is reported as "Material/Young's modulus: ...".
   * Enters the subsections on construction and leaves them on destruction.
   */
  class Section
  {
  public:
    /// @p path: the subsections from the top level, e.g. {"Material", "Bouc-Wen"}.
    Section(dealii::ParameterHandler &prm, const std::vector<std::string> &path);
    /// A subsection @p name of @p parent (which must outlive this object).
    Section(const Section &parent, const std::string &name);
    ~Section();

    Section(const Section &) = delete;
    Section &
    operator=(const Section &) = delete;

    /// "Material/Young's modulus" for @p entry.
    std::string
    where(const std::string &entry) const;

    std::string
    get(const std::string &entry) const;
    bool
    get_bool(const std::string &entry) const;
    long
    get_integer(const std::string &entry) const;
    double
    get_double(const std::string &entry) const;

    /// A double that must be > 0 (and finite).
    double
    get_positive(const std::string &entry) const;
    /// A double that must be >= 0 (and finite).
    double
    get_non_negative(const std::string &entry) const;
    /// A double in the open interval (lower, upper).
    double
    get_in_open_interval(const std::string &entry, double lower, double upper) const;

    /// A comma separated list, entries trimmed, empty entries dropped.
    std::vector<std::string>
    get_list(const std::string &entry) const;

    dealii::ParameterHandler &
    handler() const
    {
      return prm;
    }

    const std::vector<std::string> &
    subsection_path() const
    {
      return path;
    }

  private:
    dealii::ParameterHandler &prm;
    std::vector<std::string>  path;
    std::size_t               n_entered;
  };

  /**
   * Parse a muParser expression in the variables @p variables (e.g. "t" or
   * "x,y,t"), with the constants pi and e. The expression is evaluated once at
   * the origin so that unknown names and syntax errors are reported here, as an
   * InputError at @p where, and not in the middle of a run. `rand()` is refused
   * (a new number at every evaluation would break the reproducibility that
   * `Random seed` promises; `rand_seed(<integer>)` is deterministic).
   * Every value the function returns is checked: NaN or infinity throws
   * NonFiniteExpression naming @p where, the expression, the point and the time.
   * @p time_dependent: the last variable is time (FunctionParser convention).
   */
  template <int dim>
  std::unique_ptr<dealii::FunctionParser<dim>>
  parse_function(const std::string &expression,
                 const std::string &variables,
                 const bool         time_dependent,
                 const std::string &where);

  /**
   * As parse_function(), for a vector of @p n_components components separated
   * by ';' ("0; -9.81"). A wrong number of components is an InputError.
   */
  template <int dim>
  std::unique_ptr<dealii::FunctionParser<dim>>
  parse_vector_function(const std::string &expression,
                        const unsigned int n_components,
                        const std::string &variables,
                        const bool         time_dependent,
                        const std::string &where);

  /**
   * Evaluate every component of the function of time @p f (a FunctionParser<1>
   * in t from parse_function()) at @p n_samples + 1 equidistant times of
   * [0, @p end_time]: an expression that is NaN or infinite there (1/(t - 1),
   * log(t), sqrt(0.5 - t)) is refused as an InputError before the run starts,
   * with the time. The check during the run catches what falls between samples.
   */
  void
  check_finite_in_time(const dealii::Function<1> &f,
                       const double               end_time,
                       const unsigned int         n_samples = 1000);

  /**
   * Points separated by ';', each of @p dim finite coordinates separated by ','
   * ("0.5, 0.1; 1, 0.1"); empty items are skipped. A point that does not read,
   * has the wrong number of coordinates or a NaN/infinite coordinate is an
   * InputError at @p where.
   */
  template <int dim>
  std::vector<dealii::Point<dim>>
  parse_points(const std::string &text, const std::string &where);

  /// Names in a top-level list entry such as "Material names" (validated: no
  /// duplicates, no empty names, no characters that would break a subsection name).
  std::vector<std::string>
  parse_names(const std::string &list, const std::string &where);
} // namespace hysteron

#endif
