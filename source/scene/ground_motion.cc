// A ground-motion record: PEER NGA .AT2 or two-column CSV, checked line by line.
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/scene/ground_motion.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

namespace hysteron
{
  namespace
  {
    /// The blank- (and comma-, semicolon-) separated fields of @p line.
    std::vector<std::string>
    fields(const std::string &line)
    {
      std::vector<std::string> out;
      std::string              field;
      for (const char c : line)
        if (std::isspace(static_cast<unsigned char>(c)) || c == ',' || c == ';')
          {
            if (!field.empty())
              out.push_back(field);
            field.clear();
          }
        else
          field += c;
      if (!field.empty())
        out.push_back(field);
      return out;
    }

    /// @p field as a finite number, or false.
    bool
    number(const std::string &field, double &value)
    {
      char *end = nullptr;
      value     = std::strtod(field.c_str(), &end);
      return !field.empty() && end == field.c_str() + field.size() && std::isfinite(value);
    }

    std::string
    upper(std::string s)
    {
      std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
      return s;
    }
  } // namespace



  void
  GroundMotion::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii;
    prm.declare_entry("File",
                      "",
                      Patterns::Anything(),
                      "A ground-motion record: a PEER NGA .AT2 file (accelerations, usually in "
                      "g) or a two-column CSV of time [s] and acceleration. Empty: no ground "
                      "motion. Resolved like the other input files (as given, else next to the "
                      "parameter file). The acceleration is linear between samples and zero "
                      "after the last. Taken by the oscillator and spectrum methods, and by the "
                      "dynamic analyses of the fem, mpm and rbsn methods as uniform base "
                      "excitation (supports move with the ground, displacements relative to it).");
    prm.declare_entry("Format",
                      "auto",
                      Patterns::Selection("auto|peer|csv"),
                      "auto: a file whose first line starts with PEER, or named *.AT2, is a PEER "
                      "record, any other a CSV.");
    prm.declare_entry("Scale factor",
                      "1",
                      Patterns::Double(),
                      "Multiplies the record's values (9.81 for a record in g, to m/s^2).");
    prm.declare_entry("Direction",
                      "1, 0, 0",
                      Patterns::Anything(),
                      "The direction of the ground's motion (normalised; 2 or 3 components) in "
                      "the field methods' coordinates.");
  }



  void
  GroundMotion::parse_parameters(const Section &s, const std::string &resolved_file)
  {
    scale = s.get_double("Scale factor");
    require(std::isfinite(scale) && scale != 0, s.where("Scale factor"), "must be a nonzero number");
    const std::vector<std::string> d = s.get_list("Direction");
    require(d.size() == 2 || d.size() == 3, s.where("Direction"), "needs 2 or 3 components");
    unit_direction.assign(3, 0.0);
    double norm = 0;
    for (unsigned int i = 0; i < d.size(); ++i)
      {
        require(number(d[i], unit_direction[i]), s.where("Direction"), "'" + d[i] + "' is not a number");
        norm += unit_direction[i] * unit_direction[i];
      }
    require(norm > 0, s.where("Direction"), "must not be the zero vector");
    for (double &c : unit_direction)
      c /= std::sqrt(norm);
    values.clear();
    if (!resolved_file.empty())
      read(resolved_file, s.get("Format"), s.where("File"));
  }



  void
  GroundMotion::read(const std::string &file, const std::string &format, const std::string &where)
  {
    std::ifstream in(file);
    require(static_cast<bool>(in), where, "cannot open the ground-motion record '" + file + "'");
    std::string first;
    std::getline(in, first);
    in.clear();
    in.seekg(0);
    const std::string name = upper(file);
    const bool        peer = format == "peer" ||
                      (format == "auto" && (upper(dealii::Utilities::trim(first)).rfind("PEER", 0) == 0 ||
                                            (name.size() > 4 && name.substr(name.size() - 4) == ".AT2")));
    values.clear();
    if (peer)
      read_peer(in, file, where);
    else
      read_csv(in, file, where);
    for (double &a : values)
      a *= scale;
    // The integrals at the samples (the segment formulas of velocity() at s = dt).
    velocities.assign(values.size(), 0.0);
    displacements.assign(values.size(), 0.0);
    for (std::size_t k = 0; k + 1 < values.size(); ++k)
      {
        velocities[k + 1]    = velocities[k] + (values[k] + values[k + 1]) * dt / 2;
        displacements[k + 1] = displacements[k] + velocities[k] * dt + (2 * values[k] + values[k + 1]) * dt * dt / 6;
      }
  }



  void
  GroundMotion::read_peer(std::istream &in, const std::string &name, const std::string &where)
  {
    const auto fail = [&](const unsigned int line, const std::string &what) {
      throw InputError(where, name + ":" + std::to_string(line) + ": " + what);
    };
    std::string header[4];
    for (unsigned int l = 0; l < 4; ++l)
      if (!std::getline(in, header[l]))
        fail(l + 1, "the file ends inside the header of a PEER record (4 lines)");
    // Line 3 names the quantity: a velocity (.VT2) or displacement (.DT2) record is not
    // an acceleration.
    if (upper(header[2]).find("ACCELERATION") == std::string::npos)
      fail(3, "a PEER acceleration record says 'ACCELERATION' here (got '" + dealii::Utilities::trim(header[2]) + "')");
    const std::string line4 = upper(header[3]);
    const std::regex  modern(R"(NPTS\s*=\s*([0-9]+)\s*,?\s*DT\s*=\s*([-+0-9.E]+))");
    const std::regex  old(R"(^\s*([0-9]+)\s+([-+0-9.E]+)\s+NPTS)");
    std::smatch       m;
    if (!std::regex_search(line4, m, modern) && !std::regex_search(line4, m, old))
      fail(4, "expected 'NPTS= <n>, DT= <step> SEC' of a PEER .AT2 header (got '" +
                dealii::Utilities::trim(header[3]) + "')");
    const unsigned long n_points = std::stoul(m[1].str());
    if (!number(m[2].str(), dt) || !(dt > 0))
      fail(4, "the time step DT must be a positive number (got '" + m[2].str() + "')");
    if (n_points == 0)
      fail(4, "NPTS must be at least 1");
    t0 = 0;
    values.reserve(n_points);
    std::string  line;
    unsigned int line_number = 4;
    while (std::getline(in, line))
      {
        ++line_number;
        for (const std::string &f : fields(line))
          {
            double a = 0;
            if (!number(f, a))
              fail(line_number, "'" + f + "' is not a finite number");
            if (values.size() == n_points)
              fail(line_number, "more values than NPTS = " + std::to_string(n_points));
            values.push_back(a);
          }
      }
    if (values.size() != n_points)
      fail(line_number, "the record ends after " + std::to_string(values.size()) + " of NPTS = " +
                          std::to_string(n_points) + " values");
  }



  void
  GroundMotion::read_csv(std::istream &in, const std::string &name, const std::string &where)
  {
    const auto fail = [&](const unsigned int line, const std::string &what) {
      throw InputError(where, name + ":" + std::to_string(line) + ": " + what);
    };
    std::string         line;
    unsigned int        line_number = 0;
    bool                header_seen = false;
    std::vector<double> times;
    while (std::getline(in, line))
      {
        ++line_number;
        const std::string trimmed = dealii::Utilities::trim(line);
        if (trimmed.empty() || trimmed[0] == '#')
          continue;
        const std::vector<std::string> f = fields(trimmed);
        double                         t = 0, a = 0;
        const bool numbers = f.size() == 2 && number(f[0], t) && number(f[1], a);
        if (!numbers && times.empty() && !header_seen)
          {
            // A header line (column names) before the data.
            double x;
            if (std::none_of(f.begin(), f.end(), [&](const std::string &s) { return number(s, x); }))
              {
                header_seen = true;
                continue;
              }
          }
        if (f.size() != 2)
          fail(line_number, "expected two columns, time and acceleration (got " + std::to_string(f.size()) + ")");
        if (!numbers)
          fail(line_number, "'" + (number(f[0], t) ? f[1] : f[0]) + "' is not a finite number");
        if (!times.empty())
          {
            const double step = t - times.back();
            if (!(step > 0))
              fail(line_number, "the times must increase (t = " + std::to_string(t) + " s after " +
                                  std::to_string(times.back()) + " s)");
            const double first = times.size() == 1 ? step : times[1] - times[0];
            if (std::abs(step - first) > 1e-6 * first)
              {
                std::ostringstream what;
                what << "uneven time step: " << step << " s here, " << first
                     << " s between the first two samples (a record has equal steps)";
                fail(line_number, what.str());
              }
          }
        times.push_back(t);
        values.push_back(a);
      }
    if (times.size() < 2)
      fail(line_number, "a CSV record needs at least two samples");
    if (times[0] < 0)
      fail(1, "the record starts at a negative time");
    t0 = times[0];
    // The mean step, so that t_k = t_0 + k dt reproduces the last time.
    dt = (times.back() - times[0]) / (times.size() - 1);
  }



  bool
  GroundMotion::locate(const double t, std::size_t &k, double &s) const
  {
    if (values.empty() || t < t0)
      return false;
    k = std::min(static_cast<std::size_t>(std::floor((t - t0) / dt)), values.size() - 1);
    s = t - (t0 + k * dt);
    return true;
  }



  // On a segment the acceleration is a_k + (a_{k+1} - a_k) s/dt, so
  //   v = V_k + a_k s + (a_{k+1} - a_k) s^2/(2 dt),
  //   d = D_k + V_k s + a_k s^2/2 + (a_{k+1} - a_k) s^3/(6 dt);
  // after the last sample the ground moves on at V_last (the acceleration is zero).
  double
  GroundMotion::velocity(const double t) const
  {
    std::size_t k;
    double      s;
    if (!locate(t, k, s))
      return 0;
    if (k + 1 == values.size())
      return velocities[k];
    return velocities[k] + values[k] * s + (values[k + 1] - values[k]) * s * s / (2 * dt);
  }



  double
  GroundMotion::displacement(const double t) const
  {
    std::size_t k;
    double      s;
    if (!locate(t, k, s))
      return 0;
    if (k + 1 == values.size())
      return displacements[k] + velocities[k] * s;
    return displacements[k] + velocities[k] * s + values[k] * s * s / 2 +
           (values[k + 1] - values[k]) * s * s * s / (6 * dt);
  }



  double
  GroundMotion::acceleration(const double t) const
  {
    if (values.empty() || t < t0)
      return 0;
    const double x    = (t - t0) / dt;
    const double last = static_cast<double>(values.size() - 1);
    if (x >= last)
      return x <= last + 1e-9 ? values.back() : 0.0; // the last sample (to round-off of t), then rest
    const auto   k = static_cast<std::size_t>(std::floor(x));
    const double w = x - k;
    return (1 - w) * values[k] + w * values[k + 1];
  }
} // namespace hysteron
