#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <hysteron/base/config.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include "run/run_scene.h"

#include "run/checkpoint_files.h"
#include "run/output_directory.h"

#include <iostream>

namespace hysteron
{
  namespace Run
  {
    template <int dim>
    void
    run_scene(Scene<dim> &scene, Output::RunRecord &record)
    {
      const MPI_Comm     comm    = scene.mpi_communicator();
      const RunOptions  &options = scene.run_options();
      const std::string &name    = scene.method_name();
      const std::string &directory_name = scene.output_control().directory;
      auto              &method  = scene.get_method();

      // A directory that cannot be written, or that another run is writing, is refused
      // before any work.
      OutputDirectory::check_usable(directory_name, comm);
      if (scene.checkpoint_control().enabled() || options.resume)
        {
          const std::string why = method.checkpoint_unsupported();
          require(why.empty(),
                  options.resume ? "--resume" : "Checkpoint",
                  "method '" + name + "': " + why);
        }
      // The inputs as read (their digests go into the manifest and every checkpoint); a
      // resume takes the newest intact checkpoint of the same scene and inputs, found
      // before the set-up so that the method can build from it.
      const auto          inputs = digest_inputs(scene.input_files(), comm);
      CheckpointDirectory resume_point;
      if (options.resume)
        {
          const auto checkpoint =
            find_resumable_checkpoint(method.output_directory(), name, scene.effective_parameters(), inputs, comm, std::cerr);
          resume_point.path        = checkpoint.directory;
          resume_point.saved_ranks = checkpoint.ranks;
          resume_point.n_ranks     = dealii::Utilities::MPI::n_mpi_processes(comm);
        }
      method.set_run_context(inputs, resume_point, record);

      dealii::Timer wall;
      wall.start();
      scene.console() << "hysteron " HYSTERON_VERSION ": " << dim << "D scene '"
                      << options.parameter_file << "', method '" << name << "'" << std::endl;
      try
        {
          {
            dealii::TimerOutput::Scope timing(scene.timer(), "set-up");
            method.setup();
          }
          if (const std::string problem = method.check_size(); !problem.empty())
            throw InputError("Time", problem);
        }
      catch (const NonFiniteExpression &e)
        {
          // Evaluated during the set-up (an initial velocity at a point): bad input.
          throw InputError(e.where(), e.problem());
        }

      // Only a scene that set up without a problem writes files.
      RunDescription description;
      description.command        = options.command_line;
      description.parameter_file = options.parameter_file;
      description.method         = name;
      description.n_ranks        = dealii::Utilities::MPI::n_mpi_processes(comm);
      description.inputs         = inputs;
      OutputDirectory directory(record);
      directory.open(directory_name, description, options.resume, comm);
      if (scene.is_root())
        Output::write_file(scene.output_file("parameters.prm"), scene.effective_parameters(), &record);

      try
        {
          method.run();
        }
      catch (const Interrupted &e)
        {
          directory.close("interrupted", e.what());
          throw;
        }
      catch (const std::exception &e)
        {
          directory.close("failed", e.what());
          throw;
        }
      wall.stop();

      const std::string summary = method.summary();
      directory.close("finished", summary);
      scene.console() << "hysteron: '" << name << "' finished in " << wall.wall_time() << " s";
      if (!summary.empty())
        scene.console() << " (" << summary << ")";
      scene.console() << ".\nResults are in " << directory_name << "/" << std::endl;
      scene.timer().print_summary();
    }

    template void
    run_scene<2>(Scene<2> &, Output::RunRecord &);
    template void
    run_scene<3>(Scene<3> &, Output::RunRecord &);
  } // namespace Run
} // namespace hysteron
