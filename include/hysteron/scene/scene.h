#ifndef hysteron_scene_scene_h
#define hysteron_scene_scene_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/timer.h>

#include <hysteron/material/interface.h>
#include <hysteron/scene/description.h>
#include <hysteron/scene/ground_motion.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/output_column.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hysteron
{
  /// `subsection Time`: for the time-stepping methods (the material point has its own path).
  struct TimeControl
  {
    double end_time   = 1.0;
    double time_step  = 0.0; ///< 0: automatic from the CFL factor.
    double cfl_factor = 0.5;
    /// `Steps`: the load steps (end time, number of increments); empty: one step.
    std::vector<std::pair<double, unsigned int>> steps;

    /// The end times and nominal increments of the load steps (for IncrementControl).
    void
    step_grid(std::vector<double> &ends, std::vector<double> &nominals) const
    {
      ends.clear();
      nominals.clear();
      double start = 0;
      for (const auto &[end, n] : steps)
        {
          ends.push_back(end);
          nominals.push_back((end - start) / n);
          start = end;
        }
    }

    bool
    automatic_time_step() const
    {
      return time_step == 0.0;
    }
  };

  /// `subsection Output`.
  template <int dim>
  struct OutputControl
  {
    std::string              directory = "output";
    double                   interval  = 0.0; ///< simulated seconds between field outputs
    bool                     write_vtu = true;
    std::vector<dealii::Point<dim>> probe_points;
    double                   progress_interval = 2.0; ///< wall seconds between progress lines
    double                   probe_interval    = 0.0; ///< simulated seconds between table rows
    std::vector<Geometry::Region<dim>> average_regions;
    /// `History sets`: the sets (indices into Scene::set_descriptions()) whose
    /// load-displacement history is written to history_<name>.csv (the fem method).
    std::vector<unsigned int> history_sets;
    /// `Additional columns`: the output column plugins of this scene's point tables.
    PointData::ColumnSelection<dim> additional_columns;
  };

  /// `subsection Checkpoint`: when a time-stepping method saves its state.
  struct CheckpointControl
  {
    unsigned int interval     = 0; ///< steps between checkpoints, 0: none
    double       wall_minutes = 0; ///< wall-clock minutes between checkpoints, 0: none
    unsigned int keep         = 2; ///< the newest checkpoints kept

    bool
    enabled() const
    {
      return interval > 0 || wall_minutes > 0;
    }
  };

  /// How the executable was called.
  struct RunOptions
  {
    std::string parameter_file;
    std::string command_line; ///< for the run's manifest
    bool        quiet  = false;
    bool        resume = false; ///< --resume: continue from the newest checkpoint
    MPI_Comm    comm  = MPI_COMM_WORLD;
    /// The files read before the scene: the parameter file, its includes, libraries.
    std::vector<std::string> input_files;
    /// Test hook, read once at start-up from HYSTERON_TEST_SIGNAL=<SIGINT|SIGTERM|SIGKILL>@<step>
    /// (tests/run/, tests/fuzz/): the run raises @p signal in itself after the outputs of
    /// step @p step.
    struct TestSignal
    {
      int           signal = 0; ///< 0: none
      unsigned long step   = 0;
    } test_signal;
  };

  /**
   * What a .prm file describes, validated and in SI units: materials by name,
   * time and output control, the random seed and the chosen method. Bodies,
   * loads and boundary conditions are added here by the modules that need them
   * (MPM, FEM, RBSN), as named subsections like the materials
   * (see doc/architecture.md).
   *
   * Run::run_scene() (source/run/run_scene.h, called by run_application()) runs it: set-up, output directory,
   * the method, the summary and timer table.
   */
  template <int dim>
  class Scene
  {
  public:
    /// Every entry of every module (all methods, all material models).
    static void
    declare_parameters(dealii::ParameterHandler &prm, const SceneNames &names);

    /// Parse and validate everything, including the method's own parameters.
    Scene(dealii::ParameterHandler &prm, const RunOptions &options);

    /// The material called @p name; "" is the default `subsection Material`.
    const Material::Interface<dim> &
    material(const std::string &name, const std::string &where) const;

    std::vector<std::string>
    material_names() const;

    /// The bodies, boundary conditions and loads of the field methods (validated).
    const std::vector<BodyDescription<dim>> &
    body_descriptions() const
    {
      return bodies;
    }

    const std::vector<BoundaryDescription<dim>> &
    boundary_descriptions() const
    {
      return boundaries;
    }

    const std::vector<LoadDescription<dim>> &
    load_descriptions() const
    {
      return loads;
    }

    /// The named sets (`Set names`).
    const std::vector<SetDescription<dim>> &
    set_descriptions() const
    {
      return sets;
    }

    /**
     * Throw an InputError naming the entry if the scene asks @p method for what only
     * the fem method reads: a Gmsh physical group (through a `Set` of a boundary or a
     * load) or, unless @p history_tables, `Output/History sets`.
     */
    void
    refuse_fem_only_sets(const std::string &method, const bool history_tables = false) const;

    /**
     * Whether the scene is a solid of revolution (`Stress state = axisymmetric` in the
     * materials of its deformable bodies): x is the radius r >= 0, y the axis.
     */
    bool
    axisymmetric() const
    {
      return axisymmetric_;
    }

    /**
     * What multiplies a section area (2D) into a volume at the point @p x of @p body:
     * the body's thickness there, or 2 pi x (the ring around the axis) when the scene
     * is axisymmetric; 1 in 3D.
     */
    double
    thickness_at(const BodyDescription<dim> &body, const dealii::Point<dim> &x) const
    {
      return axisymmetric_ ? 2.0 * dealii::numbers::PI * x[0] : body.thickness_at(x);
    }

    /// `Gravity` [m/s^2].
    const dealii::Tensor<1, dim> &
    gravity() const
    {
      return gravity_vector;
    }

    /// `subsection Ground motion`: the record (empty() without `File`).
    const GroundMotion &
    ground_motion() const
    {
      return ground;
    }

    /// The ground's acceleration a_g(t) d at time @p t (zero without a record).
    dealii::Tensor<1, dim>
    ground_acceleration(const double t) const
    {
      dealii::Tensor<1, dim> a;
      if (!ground.empty())
        {
          const double a_g = ground.acceleration(t);
          for (unsigned int i = 0; i < dim; ++i)
            a[i] = a_g * ground.direction()[i];
        }
      return a;
    }

    /**
     * The body force per unit mass at time @p t [m/s^2]. The field methods solve for
     * the motion relative to the ground: with u the relative displacement, the absolute
     * acceleration is u'' + a_g(t) d, so the ground's motion enters as the body force
     * -a_g(t) d beside gravity, g - a_g(t) d; supports hold u = 0 (they move with the
     * ground) and their reactions are the base forces.
     */
    dealii::Tensor<1, dim>
    body_acceleration(const double t) const
    {
      return gravity_vector - ground_acceleration(t);
    }

    const TimeControl &
    time_control() const
    {
      return time;
    }

    const OutputControl<dim> &
    output_control() const
    {
      return output;
    }

    const CheckpointControl &
    checkpoint_control() const
    {
      return checkpoint;
    }

    /// `hysteron --resume`: continue from the newest checkpoint.
    bool
    resume() const
    {
      return options.resume;
    }

    /// The method that runs the scene.
    Methods::Interface<dim> &
    get_method()
    {
      return *method;
    }

    /// How the executable was called.
    const RunOptions &
    run_options() const
    {
      return options;
    }

    /// The registered name of the scene's method ("mpm").
    const std::string &
    method_name() const
    {
      return method_name_;
    }

    /// Every parameter of the run, defaults included (parameters.prm).
    const std::string &
    effective_parameters() const
    {
      return effective_parameters_;
    }

    /// "<Output/Directory>/<file>".
    std::string
    output_file(const std::string &file) const
    {
      return output.directory + "/" + file;
    }

    unsigned int
    random_seed() const
    {
      return seed;
    }

    MPI_Comm
    mpi_communicator() const
    {
      return options.comm;
    }

    bool
    is_root() const
    {
      return dealii::Utilities::MPI::this_mpi_process(options.comm) == 0;
    }

    bool
    quiet() const
    {
      return options.quiet;
    }

    /// The parameter file of the run ("" when built in memory).
    const std::string &
    parameter_file() const
    {
      return options.parameter_file;
    }

    /**
     * A file named in the parameter file: as given if it exists (relative to the
     * working directory), else relative to the parameter file's directory.
     */
    std::string
    resolve_input_file(const std::string &name) const;

    /**
     * Every file the run reads: the parameter file and its includes, the shared
     * libraries, and each file resolved by resolve_input_file() (meshes,
     * amplitude tables). Their digests go into the manifest and every
     * checkpoint; a resume refuses a changed one.
     */
    std::vector<std::string>
    input_files() const;

    /// Progress and messages: rank 0 only, silent with --quiet.
    dealii::ConditionalOStream &
    console() const
    {
      return pcout;
    }

    dealii::TimerOutput &
    timer() const
    {
      return *computing_timer;
    }

  private:
    /// The constructor's work: parse the scene and create the method.
    void
    parse(dealii::ParameterHandler &prm);

    /// Set axisymmetric_ and check the bodies against it (one kind of material, no
    /// thickness, x >= 0).
    void
    check_axisymmetry();

    /// Refuse inputs the created method would ignore or cannot use: a ground-motion record
    /// (Methods::Interface::takes_ground_motion()), a material that is no continuum for a
    /// continuum method (Material::Interface::continuum_unsupported()).
    void
    check_method_inputs(dealii::ParameterHandler &prm) const;

    RunOptions                                                      options;
    mutable dealii::ConditionalOStream                              pcout;
    /// Created first and destroyed while a parse error is still caught: a
    /// TimerOutput destroyed during stack unwinding prints a warning.
    mutable std::optional<dealii::TimerOutput>                      computing_timer;
    std::string                                                     method_name_;
    std::map<std::string, std::unique_ptr<Material::Interface<dim>>> materials;
    std::vector<BodyDescription<dim>>                               bodies;
    std::vector<BoundaryDescription<dim>>                           boundaries;
    std::vector<LoadDescription<dim>>                               loads;
    std::vector<SetDescription<dim>>                                sets;
    dealii::Tensor<1, dim>                                          gravity_vector;
    GroundMotion                                                    ground;
    TimeControl                                                     time;
    OutputControl<dim>                                              output;
    CheckpointControl                                               checkpoint;
    unsigned int                                                    seed = 0;
    bool                                                            axisymmetric_ = false;
    std::string                                                     effective_parameters_;
    /// The files resolve_input_file() returned (inputs of the run).
    mutable std::vector<std::string>                                resolved_inputs;
    std::unique_ptr<Methods::Interface<dim>>                        method;
  };

  /// Entries read before the full parse: Dimension, Method, Material names, libraries.
  void
  declare_preamble(dealii::ParameterHandler &prm);

  /// The subsection name of a named material ("Material" for the default "").
  std::string
  material_subsection(const std::string &name);
} // namespace hysteron

#endif
