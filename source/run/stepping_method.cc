#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <hysteron/base/exceptions.h>
#include "base/progress.h"
#include "base/run_record.h"
#include <hysteron/run/stepping_method.h>
#include <hysteron/scene/scene.h>
#include <hysteron/scene/tables.h>

#include "run/checkpoint_files.h"
#include "run/signals.h"

#include <cmath>
#include <csignal>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <vector>

namespace hysteron
{
  namespace Run
  {
    namespace
    {
      std::string
      seconds(const double t)
      {
        std::ostringstream s;
        s << std::setprecision(6) << t;
        return s.str();
      }

    } // namespace

    /// The driver's state during run(): what step_finished() needs.
    template <int dim>
    struct SteppingMethod<dim>::Loop
    {
      Loop(const Scene<dim> &scene, const std::string &label)
        : rows(scene.output_control().probe_interval, scene.time_control().end_time)
        , fields(scene.output_control().interval, scene.time_control().end_time)
        , progress(scene.console(),
                   label,
                   scene.time_control().end_time,
                   scene.output_control().progress_interval)
      {
        wall.start();
      }

      PointData::Schedule rows, fields;
      Progress            progress;
      dealii::Timer       wall;
      double              last_checkpoint = 0;
      double              time            = 0; ///< of the last finished step (the last good state)
    };

    template <int dim>
    SteppingMethod<dim>::SteppingMethod() = default;

    template <int dim>
    SteppingMethod<dim>::~SteppingMethod() = default;

    template <int dim>
    std::string
    SteppingMethod<dim>::check_size()
    {
      const auto  &time = this->get_scene().time_control();
      const double end  = time.end_time;
      // The steps of each phase of Time/Steps (one phase without it): its length over the
      // step proposed at its start, so that a short first phase (1e-9: 1) is not taken for
      // the step of the whole run.
      std::vector<double> phase_ends;
      for (const auto &[phase_end, n] : time.steps)
        phase_ends.push_back(phase_end);
      if (phase_ends.empty() || phase_ends.back() < end)
        phase_ends.push_back(end);
      double steps = 0, dt = 0, start = 0;
      for (const double phase_end : phase_ends)
        {
          double phase_dt = 0;
          try
            {
              phase_dt = propose_step(start);
            }
          catch (const StepFailure &)
            {
              return ""; // the first step reports it, with the last good state
            }
          if (!(phase_dt > 0))
            return "";
          if (dt == 0)
            dt = phase_dt;
          steps += std::ceil((phase_end - start) / phase_dt * (1 - 1e-12));
          start = phase_end;
        }
      const double       size  = size_of_state();
      std::ostringstream m;
      m.precision(3);
      if (steps > 1e9)
        m << label() << ": Time/End time = " << end << " s at a first step of " << dt << " s is "
          << steps << " steps" << (phase_ends.size() > 1 ? " (in all phases of Time/Steps)" : "")
          << " (more than 1e9): the run would not end. Shorten the End time or "
          << "enlarge the step (Time/Time step, CFL factor, the number of increments).";
      else if (size > 0 && steps * size > 1e14)
        m << label() << ": " << steps << " steps of " << size << " unknowns (points or DoFs) are "
          << steps * size << " unknown-steps, months of computing at ~1e7 per second and core: "
          << "shorten Time/End time, enlarge the step or coarsen the discretisation.";
      return m.str();
    }

    template <int dim>
    void
    SteppingMethod<dim>::output_fields(const double t)
    {
      const Scene<dim> &scene = this->get_scene();
      if (!scene.output_control().write_vtu)
        return;
      dealii::TimerOutput::Scope timing(scene.timer(), "output");
      write_fields(t, *field_writer);
      ++outputs;
    }

    template <int dim>
    void
    SteppingMethod<dim>::write_last_state()
    {
      output_fields(loop->time);
      write_rows(loop->time);
      this->run_record().flush_tables();
    }

    template <int dim>
    void
    SteppingMethod<dim>::save_checkpoint()
    {
      const Scene<dim> &scene = this->get_scene();
      auto             &record = this->run_record();
      dealii::TimerOutput::Scope timing(scene.timer(), "checkpoint");
      // The tables' rows up to here are on disk before the checkpoint that counts them.
      record.sync_tables();
      const auto   sizes = record.table_sizes();
      const double t     = loop->time;
      write_checkpoint(this->output_directory(),
                       steps,
                       t,
                       scene.mpi_communicator(),
                       scene.checkpoint_control().keep,
                       sizes,
                       this->inputs(),
                       record,
                       [&](CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) {
                         write_resume_header(global, scene.method_name(), scene.effective_parameters());
                         global.put(t);
                         global.put(steps);
                         global.put(outputs);
                         global.put(loop->rows.next_time());
                         global.put(loop->fields.next_time());
                         global.put(field_writer->records());
                         global.put(sizes);
                         global.section(label(), 2); // the driver's format (as "driver")
                         rank.section(label(), 2);
                         save(global, rank, directory);
                       });
      loop->last_checkpoint = loop->wall.wall_time();
    }

    template <int dim>
    void
    SteppingMethod<dim>::step_finished(const double t)
    {
      const Scene<dim>  &scene   = this->get_scene();
      const auto        &control = scene.checkpoint_control();
      MPI_Comm           comm    = scene.mpi_communicator();
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      const double       end     = scene.time_control().end_time;
      loop->time = t;
      ++steps;
      const bool last = !(t < end - 1e-12 * end);
      if (loop->rows.due(t, last))
        write_rows(t);
      if (loop->fields.due(t, last))
        output_fields(t);
      loop->progress.update(steps, t);
      test_signal_after_step(scene.run_options().test_signal, steps, this->run_record());

      // One reduction (on several ranks) decides signals and wall-clock checkpoints.
      bool wall_due = scene.is_root() && control.wall_minutes > 0 &&
                      loop->wall.wall_time() - loop->last_checkpoint >= 60 * control.wall_minutes;
      const int  signal   = received_signal(comm, n_ranks, wall_due);
      const bool step_due = control.interval > 0 && steps % control.interval == 0;
      if (signal != 0 || (!last && (step_due || wall_due)))
        save_checkpoint();
      if (signal != 0)
        {
          // The checkpoint holds the tables without the rows written now: a resumed
          // run's tables equal an uninterrupted run's.
          write_last_state();
          loop->progress.finish(steps, t);
          throw Interrupted(
            std::string(signal == SIGINT ? "SIGINT" : "SIGTERM") + " received: " + label() +
            " stopped after step " + std::to_string(steps) + " at t = " + seconds(t) +
            " s; the state was written (tables, a VTU and a checkpoint). Continue with: " +
            (n_ranks > 1 ? "mpirun -np " + std::to_string(n_ranks) + " " : std::string()) +
            "hysteron --resume " + scene.parameter_file());
        }
    }

    template <int dim>
    void
    SteppingMethod<dim>::run()
    {
      const Scene<dim>  &scene     = this->get_scene();
      const auto        &time      = scene.time_control();
      MPI_Comm           comm      = scene.mpi_communicator();
      const std::string  name      = label();
      const std::string  directory = this->output_directory();
      auto              &record    = this->run_record();
      loop = std::make_unique<Loop>(scene, name);
      double t = 0;

      // Resume: the driver's part of the checkpoint comes first, since the tables
      // must know their lengths before the method opens them.
      std::unique_ptr<CheckpointParts> resume;
      std::vector<std::pair<double, std::string>> field_records;
      if (this->resuming())
        {
          resume       = std::make_unique<CheckpointParts>(this->resume_from(), comm);
          auto &reader = resume->global();
          std::string method, parameters;
          reader.section("driver", 2);
          reader.get(method);
          reader.get(parameters);
          reader.get(t);
          reader.get(steps);
          reader.get(outputs);
          double next_row, next_field;
          reader.get(next_row);
          reader.get(next_field);
          loop->rows.restart(next_row);
          loop->fields.restart(next_field);
          reader.get(field_records);
          std::map<std::string, std::uint64_t> sizes;
          reader.get(sizes);
          record.set_resume_sizes(sizes);
        }

      open_outputs();
      field_writer = std::make_unique<Output::FieldWriter>(directory, field_name(), comm, &record);
      record.set_resume_sizes({});
      loop->time = t;
      if (resume)
        {
          field_writer->restore(field_records);
          resume->global().section(name, 2);
          for (auto &part : resume->ranks())
            part.section(name, 2);
          load(resume->global(), resume->ranks(), this->resume_from());
          if (!resume->global().at_end())
            resume->global().refuse("the checkpoint holds more than this scene reads");
          scene.console() << name << ": resumed from " << this->resume_from().path << " at t = "
                          << seconds(t) << " s (step " << steps << ")"
                          << (this->resume_from().same_ranks() ?
                                std::string() :
                                ", written on " + std::to_string(this->resume_from().saved_ranks) +
                                  " MPI rank(s), now on " + std::to_string(this->resume_from().n_ranks))
                          << std::endl;
          resume.reset();
        }
      else
        {
          initialize();
          output_fields(t);
          write_rows(t);
        }

      const double eps = 1e-12 * time.end_time;
      install_signal_handlers();
      try
        {
          while (t < time.end_time - eps)
            {
              bool accepted = false;
              try
                {
                  const double dt = propose_step(t);
                  dealii::TimerOutput::Scope timing(scene.timer(), "steps");
                  accepted = advance(t, dt);
                }
              catch (const StepFailure &failure)
                {
                  // The state of the last finished step (loop->time) is the last good one.
                  write_last_state();
                  throw RuntimeError(std::string(failure.what()) + " The last good state (t = " +
                                     seconds(loop->time) + " s) was written.");
                }
              if (accepted)
                step_finished(t);
            }
        }
      catch (...)
        {
          restore_signal_handlers();
          throw;
        }
      restore_signal_handlers();
      loop->progress.finish(steps, t);
      finish(t);
      record.flush_tables();
    }

    template class SteppingMethod<2>;
    template class SteppingMethod<3>;
  } // namespace Run
} // namespace hysteron
