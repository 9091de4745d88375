#ifndef hysteron_scene_ground_motion_h
#define hysteron_scene_ground_motion_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>

#include <string>
#include <vector>

namespace hysteron
{
  /**
   * A ground-motion record (`subsection Ground motion`): accelerations a_k at
   * equally spaced times t_k = t_0 + k dt, times `Scale factor`, along the unit
   * vector `Direction`. Between samples the acceleration is linear in time; before
   * the first sample and after the last it is zero (the ground at rest).
   *
   * Formats (`Format = auto` tells them apart by the first line):
   *  - PEER NGA `.AT2`: three header lines, a fourth with the number of points and
   *    the time step ("NPTS=  7818, DT=   .0050 SEC", or the older "7818  0.005
   *    NPTS, DT"), then the values, any number per line, t_0 = 0;
   *  - CSV: two columns t [s], a, separated by commas or blanks; lines that start
   *    with '#' and a first line without numbers (a header) are skipped. The times
   *    must increase in equal steps (to 1e-6 of the step).
   * A record that breaks these rules (a header that is not PEER's, a count that does
   * not match, uneven or decreasing times, a value that is not a finite number) is
   * refused naming the file and the line.
   */
  class GroundMotion
  {
  public:
    /// The entries of `subsection Ground motion` (the caller enters it).
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Read the section @p s; @p resolved_file is `File` as resolved by the scene
    /// (Scene::resolve_input_file()), "" if none is given. Reads the record.
    void
    parse_parameters(const Section &s, const std::string &resolved_file);

    /// Read a record from @p file (@p format: "auto", "peer" or "csv"); errors name
    /// @p where (the parameter) and the file's line.
    void
    read(const std::string &file, const std::string &format, const std::string &where);

    /// Whether a record is given.
    bool
    empty() const
    {
      return values.empty();
    }

    /// The scaled acceleration along Direction at time @p t [m/s^2].
    double
    acceleration(double t) const;

    /// The ground's velocity along Direction at time @p t [m/s]: the exact integral of
    /// the piecewise-linear acceleration from rest at t = 0.
    double
    velocity(double t) const;

    /// The ground's displacement along Direction at time @p t [m]: the exact double
    /// integral of the piecewise-linear acceleration (no baseline correction: a record's
    /// drift shows here, never in the relative motion the field methods compute).
    double
    displacement(double t) const;

    /// The sampling step of the record [s].
    double
    time_step() const
    {
      return dt;
    }

    /// The time of the last sample [s].
    double
    end_time() const
    {
      return t0 + dt * (values.empty() ? 0 : values.size() - 1);
    }

    /// The unit vector of `Direction` (3 components; 2D scenes use the first two).
    const std::vector<double> &
    direction() const
    {
      return unit_direction;
    }

    /// The number of samples.
    std::size_t
    size() const
    {
      return values.size();
    }

  private:
    void
    read_peer(std::istream &in, const std::string &name, const std::string &where);
    void
    read_csv(std::istream &in, const std::string &name, const std::string &where);

    /// The segment of @p t: k with t_k <= t < t_{k+1}, and s = t - t_k (k = size() - 1 after
    /// the last sample); false before the first sample.
    bool
    locate(double t, std::size_t &k, double &s) const;

    std::vector<double> values; ///< scaled samples
    std::vector<double> velocities, displacements; ///< the integrals at the samples
    double              t0    = 0;
    double              dt    = 0;
    double              scale = 1;
    std::vector<double> unit_direction{1, 0, 0};
  };
} // namespace hysteron

#endif
