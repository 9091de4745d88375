#ifndef hysteron_scene_amplitude_h
#define hysteron_scene_amplitude_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * `subsection Amplitude <name>`: a scalar history a(t) given by a table of points
   * (t_k, a_k), inline (`Values = 0, 0; 1, 1; 2, -1`) or from a CSV file of two columns
   * (`File`), interpolated linearly between the points (`Interpolation = linear`) or held
   * from one point to the next (`step`), and held constant before the first point and
   * after the last (CalculiX's and Abaqus' *AMPLITUDE). A load, a boundary condition or a
   * rigid body that names it in its `Amplitude` entry is multiplied by a(t), so that a
   * cyclic or stepped history needs no nested expression.
   */
  class Amplitude
  {
  public:
    enum class Interpolation
    {
      linear,
      step
    };

    /// The table (t strictly increasing, everything finite; at least one point).
    Amplitude(const std::string         &name,
              const std::vector<double> &times,
              const std::vector<double> &values,
              const Interpolation        interpolation,
              const std::string         &where);

    const std::string &
    name() const
    {
      return name_;
    }

    /// a(t).
    double
    value(const double t) const;

    /// The table's times strictly inside (t0, t1): where a(t) has a kink or a jump, so that a
    /// quadrature of a(t) f(t) is exact piece by piece.
    std::vector<double>
    breakpoints(const double t0, const double t1) const;

    /// Declare `Values`, `File` and `Interpolation` in `subsection Amplitude <name>` for each name.
    static void
    declare_parameters(dealii::ParameterHandler &prm, const std::vector<std::string> &names);

    /**
     * Read the amplitudes named @p names. @p resolve turns a `File` entry into the path to
     * open (relative names are looked up beside the parameter file). InputErrors name the
     * entry, the file and line, and what is wrong.
     */
    static std::map<std::string, std::shared_ptr<const Amplitude>>
    parse_all(dealii::ParameterHandler                              &prm,
              const std::vector<std::string>                        &names,
              const std::function<std::string(const std::string &)> &resolve);

  private:
    std::string         name_;
    std::vector<double> t, a;
    Interpolation       interpolation;
  };

  /// The amplitude named in the entry @p entry of @p section ("" = none, a null pointer).
  std::shared_ptr<const Amplitude>
  find_amplitude(const Section                                                 &section,
                 const std::string                                             &entry,
                 const std::map<std::string, std::shared_ptr<const Amplitude>> &amplitudes);
} // namespace hysteron

#endif
