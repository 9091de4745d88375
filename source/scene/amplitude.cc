#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/scene/amplitude.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace hysteron
{
  Amplitude::Amplitude(const std::string         &name,
                       const std::vector<double> &times,
                       const std::vector<double> &values,
                       const Interpolation        interpolation,
                       const std::string         &where)
    : name_(name)
    , t(times)
    , a(values)
    , interpolation(interpolation)
  {
    require(!t.empty(), where, "the amplitude has no point: give pairs 't, a' separated by ';'");
    AssertDimension(t.size(), a.size());
    for (std::size_t k = 0; k < t.size(); ++k)
      {
        require(std::isfinite(t[k]) && std::isfinite(a[k]),
                where,
                "point " + std::to_string(k + 1) + " is not finite");
        if (k > 0)
          require(t[k] > t[k - 1],
                  where,
                  "the times must increase strictly: point " + std::to_string(k + 1) + " (t = " +
                    std::to_string(t[k]) + ") does not come after point " + std::to_string(k) +
                    " (t = " + std::to_string(t[k - 1]) + ")");
      }
  }

  double
  Amplitude::value(const double time) const
  {
    // Constant before the first and after the last point.
    if (!(time > t.front()))
      return a.front();
    if (!(time < t.back()))
      return a.back();
    // t[k - 1] < time <= t[k]: the segment that holds time.
    const std::size_t k = std::lower_bound(t.begin(), t.end(), time) - t.begin();
    if (time == t[k])
      return a[k];
    if (interpolation == Interpolation::step)
      return a[k - 1];
    const double s = (time - t[k - 1]) / (t[k] - t[k - 1]);
    return (1 - s) * a[k - 1] + s * a[k];
  }

  std::vector<double>
  Amplitude::breakpoints(const double t0, const double t1) const
  {
    std::vector<double> inside;
    for (const double tk : t)
      if (tk > t0 && tk < t1)
        inside.push_back(tk);
    return inside;
  }

  void
  Amplitude::declare_parameters(dealii::ParameterHandler &prm, const std::vector<std::string> &names)
  {
    using namespace dealii;
    for (const auto &name : names)
      {
        prm.enter_subsection("Amplitude " + name);
        prm.declare_entry("Values",
                          "",
                          Patterns::Anything(),
                          "The points of a(t) as pairs 't, a' separated by ';', e.g. "
                          "'0, 0; 1, 1; 3, -1; 4, 0' (t strictly increasing [s]); or use `File`.");
        prm.declare_entry("File",
                          "",
                          Patterns::Anything(),
                          "A CSV file of the points: two columns t, a per line (',' or blanks "
                          "between them; a first line that is not numbers is a header, lines "
                          "starting with '#' are comments). Relative names are looked up in the "
                          "working directory, then beside the parameter file.");
        prm.declare_entry("Interpolation",
                          "linear",
                          Patterns::Selection("linear|step"),
                          "Between two points: 'linear' interpolates, 'step' holds the value of "
                          "the earlier point. Before the first and after the last point a(t) "
                          "keeps their values.");
        prm.leave_subsection();
      }
  }

  namespace
  {
    /// "t, a" or "t a" (blanks or commas) -> the two numbers; false if it is not that.
    bool
    read_pair(std::string line, double &t, double &a)
    {
      std::replace(line.begin(), line.end(), ',', ' ');
      std::replace(line.begin(), line.end(), '\t', ' ');
      std::istringstream in(line);
      std::string        rest;
      return static_cast<bool>(in >> t >> a) && !(in >> rest);
    }
  } // namespace

  std::map<std::string, std::shared_ptr<const Amplitude>>
  Amplitude::parse_all(dealii::ParameterHandler                              &prm,
                       const std::vector<std::string>                        &names,
                       const std::function<std::string(const std::string &)> &resolve)
  {
    std::map<std::string, std::shared_ptr<const Amplitude>> amplitudes;
    for (const auto &name : names)
      {
        Section             s(prm, {"Amplitude " + name});
        const std::string   values = dealii::Utilities::trim(s.get("Values"));
        const std::string   file   = dealii::Utilities::trim(s.get("File"));
        std::vector<double> t, a;
        std::string         where;
        require(values.empty() != file.empty(),
                s.where(values.empty() ? "Values" : "File"),
                values.empty() ? "an amplitude needs its points: `Values` or a `File`" :
                                 "give the points either in `Values` or in a `File`, not both");
        if (!values.empty())
          {
            where = s.where("Values");
            for (const auto &item : dealii::Utilities::split_string_list(values, ';'))
              {
                double tk, ak;
                require(read_pair(item, tk, ak),
                        where,
                        "'" + item + "' is not a pair 't, a' of numbers");
                t.push_back(tk);
                a.push_back(ak);
              }
          }
        else
          {
            const std::string path = resolve(file);
            std::ifstream     in(path);
            require(static_cast<bool>(in), s.where("File"), "cannot open '" + path + "'");
            std::string  line;
            unsigned int number = 0;
            while (std::getline(in, line))
              {
                ++number;
                const std::string trimmed = dealii::Utilities::trim(line);
                if (trimmed.empty() || trimmed[0] == '#')
                  continue;
                double tk, ak;
                if (!read_pair(trimmed, tk, ak))
                  {
                    // One header line before the first point.
                    require(t.empty() && number == 1,
                            s.where("File"),
                            path + ", line " + std::to_string(number) + ": '" + trimmed +
                              "' is not a pair 't, a' of numbers");
                    continue;
                  }
                t.push_back(tk);
                a.push_back(ak);
              }
            where = s.where("File") + " (" + path + ")";
          }
        amplitudes[name] = std::make_shared<const Amplitude>(
          name, t, a, s.get("Interpolation") == "step" ? Interpolation::step : Interpolation::linear, where);
      }
    return amplitudes;
  }

  std::shared_ptr<const Amplitude>
  find_amplitude(const Section                                                 &section,
                 const std::string                                             &entry,
                 const std::map<std::string, std::shared_ptr<const Amplitude>> &amplitudes)
  {
    const std::string name = dealii::Utilities::trim(section.get(entry));
    if (name.empty())
      return nullptr;
    const auto it = amplitudes.find(name);
    if (it == amplitudes.end())
      {
        std::string known;
        for (const auto &[n, amplitude] : amplitudes)
          known += (known.empty() ? "" : ", ") + n;
        throw InputError(section.where(entry),
                         "no amplitude named '" + name + "' (`Amplitude names`: " +
                           (known.empty() ? std::string("none") : known) + ")");
      }
    return it->second;
  }
} // namespace hysteron
