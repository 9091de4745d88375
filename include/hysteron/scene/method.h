#ifndef hysteron_scene_method_h
#define hysteron_scene_method_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/checkpoint.h>
#include <hysteron/base/registry.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace Output
  {
    class RunRecord; // the run's record of its files (opaque to methods)
  }

  template <int dim>
  class Scene;

  namespace Methods
  {
    /**
     * A discretisation that runs a scene: `material point`, `mpm`, `fem`,
     * `rbsn`. A method declares its parameters in its own subsection (static
     * declare_parameters), reads only those plus what the Scene offers (materials,
     * time and output control, bodies), and never parses another method's
     * parameters. Register with HYSTERON_REGISTER_METHOD.
     */
    template <int dim>
    class Interface
    {
    public:
      virtual ~Interface() = default;

      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /// Attach the scene and read the method's parameters (all checks happen here).
      void
      initialize(const Scene<dim> &scene, dealii::ParameterHandler &prm)
      {
        scene_ptr = &scene;
        parse_parameters(prm);
      }

      /**
       * Build everything the run needs (grids, bodies, networks, conditions) and
       * refuse bad input (InputError). Writes no file: the output directory is
       * prepared only after a successful set-up, so a refused run leaves nothing.
       */
      virtual void
      setup()
      {}

      /**
       * After setup(): "" if the run's predicted size is reasonable, else why not,
       * with the estimate (a run of 1e30 steps is refused before it writes anything
       * instead of running forever).
       */
      virtual std::string
      check_size()
      {
        return "";
      }

      /// "" if the method writes checkpoints (and can resume) in this scene, else why not.
      virtual std::string
      checkpoint_unsupported() const
      {
        return "this method does not write checkpoints";
      }

      /// Whether the method reads `Ground motion/File` (the scene refuses a record that
      /// a method would ignore).
      virtual bool
      takes_ground_motion() const
      {
        return false;
      }

      /// Whether the bodies' materials act as continua (update() of strain tensors): the
      /// scene then refuses a material whose continuum_unsupported() says why not.
      virtual bool
      takes_continuum_materials() const
      {
        return false;
      }

      /// Run the scene to the end, writing outputs into the scene's directory.
      virtual void
      run() = 0;

      /// One line for the run summary ("4000 steps, 3 outputs").
      virtual std::string
      summary() const
      {
        return "";
      }

      /**
       * Write into the subdirectory @p name of `Output/Directory` instead of the
       * directory itself (the compare method runs several methods in one scene).
       * Call before run(); the subdirectory is created by run().
       */
      void
      set_output_subdirectory(const std::string &name)
      {
        subdirectory = name;
      }

      /**
       * Set by the runner before setup(): the run's input files as read (their
       * digests go into every checkpoint), with `--resume` the checkpoint the
       * run continues from, found and checked before setup() so that a method
       * can build its set-up from it (e.g. a triangulation saved with its cells'
       * data), and the record of the run's files, which outlives the method's run.
       */
      void
      set_run_context(const std::vector<FileDigest> &inputs,
                      const CheckpointDirectory     &resume,
                      Output::RunRecord             &record)
      {
        input_digests = inputs;
        resume_point  = resume;
        files         = &record;
      }

      /// The record of the run's files (set_run_context()): every file the method writes is given it.
      Output::RunRecord &
      run_record() const
      {
        Assert(files != nullptr, dealii::ExcMessage("run_record() before set_run_context()"));
        return *files;
      }

      /// Whether the run continues from a checkpoint (resume_from()).
      bool
      resuming() const
      {
        return !resume_point.path.empty();
      }

      /// The checkpoint of `--resume`.
      const CheckpointDirectory &
      resume_from() const
      {
        return resume_point;
      }

      /// The run's input files as read.
      const std::vector<FileDigest> &
      inputs() const
      {
        return input_digests;
      }

      /// The directory this method writes into.
      std::string
      output_directory() const;

      /// "<output_directory()>/<file>".
      std::string
      output_file(const std::string &file) const
      {
        return output_directory() + "/" + file;
      }

    protected:
      virtual void
      parse_parameters(dealii::ParameterHandler &prm) = 0;

      const Scene<dim> &
      get_scene() const
      {
        return *scene_ptr;
      }

    private:
      const Scene<dim>       *scene_ptr = nullptr;
      std::string             subdirectory;
      std::vector<FileDigest> input_digests;
      CheckpointDirectory     resume_point;
      Output::RunRecord      *files = nullptr;
    };

    template <int dim>
    using Registry = Plugins::Registry<Interface<dim>>;
  } // namespace Methods
} // namespace hysteron

/// Register a method class template (dim = 2, 3) under @p name.
#define HYSTERON_REGISTER_METHOD(classname, name, description) \
  HYSTERON_REGISTER_DIM_PLUGIN(::hysteron::Methods::Interface, classname, name, description)

#endif
