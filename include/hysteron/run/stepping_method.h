#ifndef hysteron_run_stepping_method_h
#define hysteron_run_stepping_method_h

#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include <hysteron/base/checkpoint.h>
#include <hysteron/scene/method.h>

#include <memory>
#include <string>

namespace hysteron
{
  namespace Run
  {
    /**
     * Thrown by SteppingMethod::advance() (or propose_step()) when a step cannot
     * be taken: a NaN, an instability, Newton out of cuts. The method has put
     * its state back to the start of the step; the driver writes that last good
     * state (a table row, a VTU) and stops the run with exit status 2.
     */
    class StepFailure : public RuntimeError
    {
    public:
      using RuntimeError::RuntimeError;
    };

    /**
     * A time-stepping field method (MPM, FEM, RBSN): it implements its set-up,
     * its step, its state and its fields; the driver (run(), the same for every
     * method) owns what they all repeat:
     *  - time or load control: the loop from t = 0 to `Time/End time` over the
     *    steps the method proposes, cuts included;
     *  - the output cadence: table rows every `Output/Probe interval`, fields
     *    every `Output/Interval`, both at t = 0 and at the end;
     *  - the VTU/PVD series (one FieldWriter), progress lines with an ETA and the
     *    timer sections "set-up", "steps" and "output";
     *  - the last good state: a StepFailure writes the state at the step's start;
     *  - SIGINT and SIGTERM: the current step ends, the state is written (tables,
     *    a VTU and a checkpoint) and the run stops with exit status 4;
     *  - checkpoints every `Checkpoint/Interval` steps or `Checkpoint/Wall-clock
     *    interval` minutes, and `hysteron --resume`.
     *
     * The story of run():
     *   open_outputs(); initialize() (or load() a checkpoint);
     *   write_rows(0); write_fields(0);
     *   while t < T: dt = propose_step(t); if advance(t, dt): rows, fields, checkpoint
     *   finish(t)
     * A method's setup() (Methods::Interface) runs before, and writes no file.
     */
    template <int dim>
    class SteppingMethod : public Methods::Interface<dim>
    {
    public:
      SteppingMethod();
      ~SteppingMethod() override;

      /// The predicted number of steps (End time / the first step) and the work
      /// (steps x size_of_state()) against fixed limits: 1e9 steps, 1e14 unknown-steps.
      std::string
      check_size() override;

      /// The driver: the same loop for every method.
      void
      run() final;

    protected:
      /// The prefix of messages and progress lines ("mpm").
      virtual std::string
      label() const = 0;

      /// The base name of the VTU series ("particles": particles.pvd).
      virtual std::string
      field_name() const = 0;

      /// Open the method's tables in output_directory() (the first files of the run).
      virtual void
      open_outputs() = 0;

      /// The state at t = 0 (not called on resume).
      virtual void
      initialize()
      {}

      /// The step from @p t, at most `End time - t`. May throw StepFailure.
      virtual double
      propose_step(double t) = 0;

      /**
       * Take the step from @p t to t + @p dt. On success advance @p t (to t + dt,
       * or a rounded value) and return true; return false to have the step cut
       * (propose_step() is asked again from the same t). Throw StepFailure after
       * restoring the state of @p t when the run cannot go on.
       *
       * An integrator that chooses its own steps (SUNDIALS IDA) may instead
       * integrate further, call step_finished() at each of its output times, set
       * @p t to the last of them and return false.
       */
      virtual bool
      advance(double &t, double dt) = 0;

      /// A row of every time table at @p t (collective on the method's ranks).
      virtual void
      write_rows(double t) = 0;

      /// The fields at @p t into @p writer (collective).
      virtual void
      write_fields(double t, Output::FieldWriter &writer) = 0;

      /// After the last step: the end-of-run tables (particles.csv, ...).
      virtual void
      finish(double)
      {}

      /// The unknowns one step updates (material points, DoFs), for check_size(); 0: unknown.
      virtual double
      size_of_state() const
      {
        return 0;
      }

      /// "" if this run can be checkpointed, else why not (refused at set-up).
      virtual std::string
      checkpoint_unsupported() const
      {
        return "";
      }

      /**
       * Write the state (everything advance() reads), bit for bit, into a
       * checkpoint: @p global what is the same on every rank (rank 0's is kept),
       * @p rank this rank's own part (its partial sums and the like), and the
       * distributed state (points, cells) into files of @p directory, in a form
       * that any number of ranks can read back. Collective.
       */
      virtual void
      save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const = 0;

      /**
       * Read what save() wrote, after setup() and open_outputs() of the same
       * scene (setup() may have built from resume_from() already).
       * @p rank_parts holds this rank's own part when the run has as many ranks
       * as the one that wrote the checkpoint (directory.same_ranks()), else the
       * parts of all the ranks that wrote it, for the method to share out.
       */
      virtual void
      load(CheckpointReader &global, std::vector<CheckpointReader> &rank_parts, const CheckpointDirectory &directory) = 0;

      /**
       * What follows every step: table rows and fields when due, progress, the
       * checkpoint when due, and a signal's stop. The driver calls it after each
       * accepted step; an integrator with its own loop calls it at its output times.
       */
      void
      step_finished(double t);

      /// Steps accepted so far.
      unsigned long
      n_steps() const
      {
        return steps;
      }

      /// Field outputs written so far.
      unsigned int
      n_outputs() const
      {
        return outputs;
      }

    private:
      struct Loop;

      /// Write the fields at @p t (if VTU output is on), timed as "output".
      void
      output_fields(double t);

      /// Fields and table rows of the last finished step, tables flushed.
      void
      write_last_state();

      /// A checkpoint of the last finished step.
      void
      save_checkpoint();

      std::unique_ptr<Loop>                loop;
      unsigned long                        steps   = 0;
      unsigned int                         outputs = 0;
      std::unique_ptr<Output::FieldWriter> field_writer;
    };
  } // namespace Run
} // namespace hysteron

#endif
