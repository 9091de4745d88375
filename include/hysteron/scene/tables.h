#ifndef hysteron_scene_tables_h
#define hysteron_scene_tables_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/tensor.h>

#include <hysteron/base/output.h>
#include <hysteron/base/checkpoint.h>
#include <hysteron/scene/ground_motion.h>
#include <hysteron/scene/point_data.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace PointData
  {
    /**
     * The time tables of a field method (see point_data.h for their columns):
     * probe_<i>.csv, average_<i>.csv, energy.csv and reactions.csv, opened on
     * rank 0 and written from the partial sums of every rank (one reduction per
     * row, none on one rank), and history_<set>.csv for the scene's `History sets`.
     */
    template <int dim>
    class Tables
    {
    public:
      /// Open the tables in @p directory (rank 0): one probe table per probe point of
      /// the scene, one average table per average region, with the @p point_columns
      /// (PointData::columns() for material points and quadrature points), as files
      /// of the run of @p record.
      void
      open(const Scene<dim>               &scene,
           const std::string              &directory,
           const std::vector<std::string> &point_columns,
           Output::RunRecord              &record,
           const bool                      with_damping_work = false);

      /// The number of values of a point (the probe columns without `time`).
      unsigned int
      n_point_values() const
      {
        return n_values;
      }

      /**
       * Add a row to every table at time @p t. Each rank passes its partial
       * sums: @p probes (n_probes x n_point_values(): the rank that owns a
       * probe's point fills it, the others leave zeros), @p averages (per region:
       * mass, then the mass-weighted sums of the point values), @p energies
       * (kinetic, strain energy, internal, external and boundary work) and
       * @p reactions (one per column pair of reactions.csv) and @p histories (per
       * history set, history_columns(): the mean displacement, the reaction and
       * the load, each dim values; empty without history sets). The arrays are
       * summed in place. A second row at the time of the last one is not written
       * (every rank skips it, before the reduction). @p damping_work (this rank's part)
       * is the damping_work column of a table opened with_damping_work (and enters the
       * balance). A NaN or infinite value is
       * never written: every rank throws RuntimeError naming the table, the column
       * and the time (the tables keep every row before).
       */
      void
      write(const double                         t,
            std::vector<double>                 &probes,
            std::vector<double>                 &averages,
            std::array<double, 5>                energies,
            std::vector<dealii::Tensor<1, dim>>  reactions,
            const MPI_Comm                       comm,
            std::vector<double>                  histories    = {},
            double                               damping_work = 0);

      /**
       * With a ground motion (Scene::ground_motion()), the relative accelerations at the
       * probes for the next write(): n_probes x dim partial sums like the probes' values.
       * The probe tables then end with a_x, a_y(, a_z), the absolute acceleration
       * (these plus a_g(t) d), and ground.csv holds the ground's own motion along
       * Direction (a_g, v_g, d_g) and the base force: the sum of the reactions of all
       * `Boundary` conditions. A method that takes a ground motion calls this before
       * every write().
       */
      void
      set_probe_accelerations(std::vector<double> relative)
      {
        probe_accelerations = std::move(relative);
      }

      /// The columns of history_<set>.csv after `time`: u_x, u_y(, u_z), reaction_x, ...,
      /// load_x, ...
      static std::vector<std::string>
      history_columns();

      /**
       * Draw each history table as history_<set>.png with gnuplot (rank 0): the force
       * (reaction or load, whichever varies more) against the mean displacement in the
       * direction where their product varies most. Returns the warnings (gnuplot missing
       * or failing); never throws because of the plotter. Call after flush().
       */
      std::vector<std::string>
      draw_histories(double timeout = 60) const;

      /// Write the buffered rows of every table (rank 0).
      void
      flush();

      /// The state between rows (the last row's time, the energy reference), for a
      /// checkpoint (CheckpointWriter) and its resume (CheckpointReader).
      template <class Archive>
      void
      serialize(Archive &ar);

    private:
      Output::RunRecord                              *record = nullptr; ///< of open()
      std::vector<std::unique_ptr<Output::TimeTable>> probe_tables, average_tables;
      std::unique_ptr<Output::TimeTable>              energy_table, reaction_table, ground_table;
      const GroundMotion                             *ground = nullptr; ///< of open(), null without a record
      unsigned int                                    n_boundaries = 0; ///< the scene's Boundary conditions
      std::vector<double>                             probe_accelerations; ///< set_probe_accelerations()
      std::vector<std::unique_ptr<Output::TimeTable>> history_tables;
      std::vector<std::string>                        history_names, history_paths;
      /// Per history table and column (after time): the smallest and largest value written.
      std::vector<std::vector<std::pair<double, double>>> history_ranges;
      EnergyLog                                       energy_log;
      unsigned int                                    n_values = 0;
      bool                                            damping_column = false; ///< of open()
      std::vector<std::string>                        point_names, reaction_names;

      /// Throw RuntimeError if a value of @p row (of @p table, columns @p names) is not finite.
      static void
      check_finite(const double                     t,
                   const std::vector<double>       &row,
                   const std::string               &table,
                   const std::vector<std::string>  &names);
      /// The time of the last row (a failing run writes its last good state, which
      /// may be the row just written: it is not repeated).
      double last_time   = 0;
      bool   has_written = false;
    };

    /**
     * When outputs are due in a time-stepping run: every step for an interval
     * of 0, else each time t passes the next multiple of the interval, and on
     * the last step.
     */
    class Schedule
    {
    public:
      Schedule(const double interval, const double end_time)
        : interval(interval)
        , next(interval)
        , eps(1e-12 * end_time)
      {}

      /// The time of the next output (for a checkpoint).
      double
      next_time() const
      {
        return next;
      }

      /// Resume: the next output is at @p t.
      void
      restart(const double t)
      {
        next = t;
      }

      /// After a step that ended at @p t (the last one if @p last): is an output due?
      bool
      due(const double t, const bool last)
      {
        const bool now = interval == 0 || t >= next - eps || last;
        // The next multiple of the interval after t: by steps of the interval (the
        // times every earlier version wrote), or at once when a step spans more than
        // a thousand intervals (an interval of 1e-300 s must not loop for ever).
        for (unsigned int k = 0; interval > 0 && next <= t + eps; ++k)
          if (k < 1000)
            next += interval;
          else
            next = std::max(std::nextafter(t + eps, 1e300), (std::floor((t + eps) / interval) + 1) * interval);
        return now;
      }

    private:
      double interval, next, eps;
    };
  } // namespace PointData
} // namespace hysteron

#endif
