#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/config.h>
#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include <hysteron/scene/output_column.h>
#include <hysteron/scene/ground_motion.h>
#include <hysteron/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace hysteron
{
  void
  declare_preamble(dealii::ParameterHandler &prm)
  {
    using namespace dealii;
    prm.declare_entry("Dimension",
                      "2",
                      Patterns::Integer(2, 3),
                      "Space dimension of the scene: 2 or 3. Read before everything else.");
    prm.declare_entry("Method",
                      "material point",
                      Patterns::Selection(Methods::Registry<3>::pattern_string()),
                      "The method that runs the scene. Registered methods:" +
                        Methods::Registry<3>::documentation());
    prm.declare_entry("Material names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of further materials, besides the default one of `subsection "
                      "Material`. Each name N gets its own `subsection Material N` with the same "
                      "entries; bodies refer to materials by name.");
    prm.declare_entry("Body names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of the bodies of a field method (mpm, fem, rbsn); each name N gets "
                      "`subsection Body N` with its shape, material, thickness and velocity.");
    prm.declare_entry("Boundary names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of the kinematic boundary conditions; each name N gets `subsection "
                      "Boundary N`.");
    prm.declare_entry("Load names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of the loads (forces, tractions); each name N gets `subsection Load "
                      "N`.");
    prm.declare_entry("Amplitude names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of the amplitudes: tables of a(t) that multiply the loads, "
                      "boundary conditions and rigid-body velocities that name them in their "
                      "`Amplitude` entry; each name N gets `subsection Amplitude N`.");
    prm.declare_entry("Set names",
                      "",
                      Patterns::List(Patterns::Anything()),
                      "Names of node, point and cell sets (box faces, regions or Gmsh physical "
                      "groups) that boundaries and loads name in their `Set` entry and "
                      "`Output/History sets` writes; each name N gets `subsection Set N`.");
    prm.declare_entry("Additional shared libraries",
                      "",
                      Patterns::List(Patterns::FileName()),
                      "Shared libraries to load before the parameters are declared: user plugins "
                      "(materials, methods) that register themselves. See "
                      "doc/examples/custom_material.");
  }

  std::string
  material_subsection(const std::string &name)
  {
    return name.empty() ? std::string("Material") : "Material " + name;
  }

  template <int dim>
  void
  Scene<dim>::declare_parameters(dealii::ParameterHandler &prm, const SceneNames &names)
  {
    using namespace dealii;
    declare_preamble(prm);
    prm.declare_entry("Random seed",
                      "0",
                      Patterns::Integer(0),
                      "Seed of every random number generator (point sets, perturbations): the "
                      "same seed gives the same results.");
    prm.declare_entry("Gravity",
                      "",
                      Patterns::Anything(),
                      "Acceleration of gravity [m/s^2] acting on every body of a field method, "
                      "as 'gx, gy' (2D) or 'gx, gy, gz' (3D); empty: none.");

    prm.enter_subsection("Time");
    {
      prm.declare_entry("End time", "1", Patterns::Double(), "End of the simulation [s], > 0.");
      prm.declare_entry("Time step",
                        "0",
                        Patterns::Double(),
                        "Fixed time step [s], >= 0; 0 chooses it automatically from the CFL "
                        "factor and the critical step of the method.");
      prm.declare_entry("CFL factor",
                        "0.5",
                        Patterns::Double(),
                        "Fraction of the critical time step used by automatic stepping, in (0, 1].");
      prm.declare_entry("Steps",
                        "",
                        Patterns::Anything(),
                        "Load steps of the implicit analyses (FEM quasi-static and implicit "
                        "dynamics; RBSN static, quasi-static and implicit dynamics) as 'end time: "
                        "increments' separated by ';', e.g. '1: 20; 1.5: 1; 3: 40' (load, hold, "
                        "unload with the histories of doc/amplitudes.md): each step has its own "
                        "increment (end - start) / increments and no increment crosses its end. "
                        "The last end time is `End time`. Empty: one step with the method's "
                        "`Number of increments` or `Time step`, which the steps replace. The MPM, "
                        "explicit and variable-order analyses take their own steps.");
    }
    prm.leave_subsection();

    prm.enter_subsection("Output");
    {
      prm.declare_entry("Directory",
                        "output",
                        Patterns::DirectoryName(),
                        "Directory for all results (created if missing). Relative paths are "
                        "relative to the working directory.");
      prm.declare_entry("Interval",
                        "0",
                        Patterns::Double(),
                        "Simulated time between field outputs (VTU) and probe rows [s], >= 0; "
                        "0 writes every step.");
      prm.declare_entry("Write VTU",
                        "true",
                        Patterns::Bool(),
                        "Write fields as VTU/PVD for ParaView (field methods only).");
      prm.declare_entry("Probe points",
                        "",
                        Patterns::Anything(),
                        "Points whose history is written to probe_<i>.csv (i = 0, 1, ... in the "
                        "order given), as 'x,y; x,y' in 2D or "
                        "'x,y,z; ...' in 3D [m] (field methods only).");
      prm.declare_entry("Probe interval",
                        "0",
                        Patterns::Double(),
                        "Simulated time between rows of the probe, average, energy and reaction "
                        "tables [s], >= 0; 0: every step (field methods).");
      prm.declare_entry("Additional columns",
                        "",
                        Patterns::MultipleSelection(PointData::ColumnRegistry<3>::pattern_string()),
                        "Output column plugins appended to every point table, in the order given: "
                        "probe_<i>.csv and average_<i>.csv, and particles.csv (mpm), "
                        "quadrature_points.csv (fem) or cells.csv (rbsn, a cell's Love-Weber "
                        "stress and fitted strain: doc/rbsn.md). Registered columns:" +
                          PointData::ColumnRegistry<3>::documentation());
      PointData::ColumnRegistry<3>::declare_parameters(prm);
      prm.declare_entry("Average regions",
                        "",
                        Patterns::Anything(),
                        "Regions separated by ';' (doc/geometry.md); for each, average_<i>.csv "
                        "holds the mass-weighted mean of the probe columns over the material "
                        "(MPM: the points that started in the region; FEM: the quadrature points "
                        "in it), e.g. a body's mean velocity or a section's mean stress, every "
                        "`Probe interval` (field methods).");
      prm.declare_entry("History sets",
                        "",
                        Patterns::Anything(),
                        "fem and rbsn methods: names of sets (`Set names`) whose history is "
                        "written every `Probe interval` to history_<name>.csv: the mean "
                        "displacement of the set's nodes (RBSN: of its cells' nuclei), the "
                        "reaction on them (the force of the supports, as in "
                        "reactions.csv) and the external load on them, side by side (the "
                        "load-displacement curve), drawn at the end of the run in "
                        "history_<name>.png when gnuplot is installed.");
      prm.declare_entry("Progress interval",
                        "2",
                        Patterns::Double(),
                        "Wall-clock seconds between progress lines, > 0 (silenced by --quiet).");
    }
    prm.leave_subsection();

    prm.enter_subsection("Checkpoint");
    {
      prm.declare_entry("Interval",
                        "0",
                        Patterns::Integer(0),
                        "Steps (or load increments) between checkpoints of a time-stepping "
                        "method (mpm, fem, rbsn), >= 0; 0: none. `hysteron --resume scene.prm` "
                        "continues a run from the newest checkpoint in its output directory.");
      prm.declare_entry("Wall-clock interval",
                        "0",
                        Patterns::Double(0),
                        "Wall-clock minutes between checkpoints, >= 0; 0: none. Both intervals may "
                        "be set. A run stopped by SIGINT or SIGTERM always writes one.");
      prm.declare_entry("Number kept",
                        "2",
                        Patterns::Integer(1),
                        "How many checkpoints (the newest) stay in the output directory, >= 1; "
                        "each is written completely before the oldest is removed.");
    }
    prm.leave_subsection();

    std::vector<std::string> sections{""};
    sections.insert(sections.end(), names.materials.begin(), names.materials.end());
    for (const auto &name : sections)
      {
        prm.enter_subsection(material_subsection(name));
        Material::declare_parameters(prm);
        prm.leave_subsection();
      }

    declare_scene_descriptions(prm, names);
    prm.enter_subsection("Ground motion");
    GroundMotion::declare_parameters(prm);
    prm.leave_subsection();
    Amplitude::declare_parameters(prm, names.amplitudes);
    Methods::Registry<3>::declare_parameters(prm);
  }


  template <int dim>
  Scene<dim>::Scene(dealii::ParameterHandler &prm, const RunOptions &options)
    : options(options)
    , pcout(std::cout, !options.quiet && dealii::Utilities::MPI::this_mpi_process(options.comm) == 0)
  {
    computing_timer.emplace(options.comm, pcout, dealii::TimerOutput::never, dealii::TimerOutput::wall_times);
    try
      {
        parse(prm);
      }
    catch (...)
      {
        computing_timer.reset();
        throw;
      }
  }



  template <int dim>
  void
  Scene<dim>::parse(dealii::ParameterHandler &prm)
  {
    method_name_ = prm.get("Method");
    seed        = prm.get_integer("Random seed");

    {
      Section s(prm, {"Time"});
      time.end_time   = s.get_positive("End time");
      time.time_step  = s.get_non_negative("Time step");
      time.cfl_factor = s.get_positive("CFL factor");
      require(time.cfl_factor <= 1.0,
              s.where("CFL factor"),
              "must be <= 1 (got " + s.get("CFL factor") + ")");
      double previous = 0;
      for (const auto &item : dealii::Utilities::split_string_list(s.get("Steps"), ';'))
        {
          const auto parts = dealii::Utilities::split_string_list(item, ':');
          double     end   = 0;
          long       n     = 0;
          bool       ok    = parts.size() == 2;
          try
            {
              if (ok)
                {
                  end = dealii::Utilities::string_to_double(parts[0]);
                  n   = dealii::Utilities::string_to_int(parts[1]);
                }
            }
          catch (const dealii::ExceptionBase &)
            {
              ok = false; // not a number (deal.II's conversion)
            }
          require(ok && std::isfinite(end),
                  s.where("Steps"),
                  "'" + item + "' is not 'end time: increments', e.g. '1.5: 10'");
          require(end > previous,
                  s.where("Steps"),
                  "the step '" + item + "' does not end after the previous one (at " +
                    std::to_string(previous) + " s): the end times must increase");
          require(n >= 1 && n <= 10000000L,
                  s.where("Steps"),
                  "the step '" + item + "' needs 1 to 10,000,000 increments");
          time.steps.emplace_back(end, static_cast<unsigned int>(n));
          previous = end;
        }
      if (!time.steps.empty())
        require(std::abs(previous - time.end_time) <= 1e-12 * time.end_time,
                s.where("Steps"),
                "the last step ends at " + std::to_string(previous) + " s, but `End time` is " +
                  std::to_string(time.end_time) + " s: they must agree");
    }
    {
      Section s(prm, {"Output"});
      output.directory = dealii::Utilities::trim(s.get("Directory"));
      require(!output.directory.empty(), s.where("Directory"), "must not be empty");
      output.interval          = s.get_non_negative("Interval");
      output.write_vtu         = s.get_bool("Write VTU");
      output.probe_points      = parse_points<dim>(s.get("Probe points"), s.where("Probe points"));
      output.progress_interval = s.get_positive("Progress interval");
      output.probe_interval    = s.get_non_negative("Probe interval");
      output.additional_columns.select(s.get_list("Additional columns"), s.where("Additional columns"));
      for (const auto &expression :
           dealii::Utilities::split_string_list(s.get("Average regions"), ';'))
        if (!expression.empty())
          output.average_regions.push_back(
            Geometry::Region<dim>::parse(expression, s.where("Average regions")));
    }

    {
      Section s(prm, {"Checkpoint"});
      checkpoint.interval     = s.get_integer("Interval");
      checkpoint.wall_minutes = s.get_non_negative("Wall-clock interval");
      checkpoint.keep         = s.get_integer("Number kept");
    }

    const SceneNames scene_names = SceneNames::read(prm);
    std::vector<std::string> names{""};
    names.insert(names.end(), scene_names.materials.begin(), scene_names.materials.end());
    for (const auto &name : names)
      {
        Section s(prm, {material_subsection(name)});
        materials[name] = Material::create<dim>(s);
        if (is_root())
          for (const auto &w : materials[name]->warnings())
            std::cerr << "hysteron: warning: " << w << std::endl;
      }

    gravity_vector = parse_vector<dim>(prm.get("Gravity"), "Gravity");
    {
      Section           g(prm, {"Ground motion"});
      const std::string file = dealii::Utilities::trim(g.get("File"));
      ground.parse_parameters(g, file.empty() ? "" : resolve_input_file(file));
      require(dim == 3 || ground.empty() || ground.direction()[2] == 0,
              g.where("Direction"),
              "has a third component in a 2D scene (the ground moves in the x-y plane)");
    }
    const AmplitudeMap amplitudes = Amplitude::parse_all(prm, scene_names.amplitudes, [this](const std::string &f) {
      return resolve_input_file(f);
    });
    bodies         = parse_bodies<dim>(prm, scene_names, amplitudes);
    for (const auto &b : bodies)
      material(b.material, "Body " + b.name + "/Material");
    check_axisymmetry();
    sets       = parse_sets<dim>(prm, scene_names);
    boundaries = parse_boundaries<dim>(prm, scene_names, amplitudes, sets);
    loads      = parse_loads<dim>(prm, scene_names, amplitudes, sets);
    {
      Section s(prm, {"Output"});
      for (const auto &name : s.get_list("History sets"))
        {
          unsigned int k = 0;
          while (k < sets.size() && sets[k].name != name)
            ++k;
          require(k < sets.size(),
                  s.where("History sets"),
                  "no set named '" + name + "' (define it in `Set names` and `subsection Set " +
                    name + "`)");
          require(name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") ==
                      std::string::npos,
                  s.where("History sets"),
                  "the set name '" + name + "' names the file history_" + name +
                    ".csv: use letters, digits, '_', '.' and '-' only");
          require(std::find(output.history_sets.begin(), output.history_sets.end(), k) ==
                    output.history_sets.end(),
                  s.where("History sets"),
                  "the set '" + name + "' is listed twice");
          output.history_sets.push_back(k);
        }
    }
    // Expressions of time only: NaN or infinity anywhere in [0, End time] is bad input.
    for (const auto &b : bodies)
      if (b.rigid_velocity)
        check_finite_in_time(*b.rigid_velocity, time.end_time);
    for (const auto &b : boundaries)
      if (b.velocity)
        check_finite_in_time(*b.velocity, time.end_time);
    for (const auto &l : loads)
      check_finite_in_time(*l.value, time.end_time);

    std::ostringstream text;
    prm.print_parameters(text, dealii::ParameterHandler::ShortPRM);
    effective_parameters_ = "# Parameters of this hysteron " HYSTERON_VERSION " run (" +
                           options.parameter_file + "), defaults included.\n" + text.str();

    method = Methods::Registry<dim>::create(method_name_, "Method");
    check_method_inputs(prm);
    method->initialize(*this, prm);
  }

  template <int dim>
  void
  Scene<dim>::check_method_inputs(dealii::ParameterHandler &prm) const
  {
    // A record that the method would not read must not pass silently, nor a material that
    // a continuum method cannot use.
    {
      Section ground(prm, {"Ground motion"});
      require(dealii::Utilities::trim(ground.get("File")).empty() || method->takes_ground_motion(),
              ground.where("File"),
              "the " + method_name_ + " method does not take a ground motion");
    }
    if (method->takes_continuum_materials())
      for (const auto &b : bodies)
        if (!b.rigid)
          {
            const std::string why = material(b.material, "Body " + b.name + "/Material").continuum_unsupported();
            require(why.empty(),
                    material_subsection(b.material),
                    "the " + method_name_ + " method (Body " + b.name + "): " + why);
          }
  }

  template <int dim>
  const Material::Interface<dim> &
  Scene<dim>::material(const std::string &name, const std::string &where) const
  {
    const auto it = materials.find(name);
    if (it == materials.end())
      {
        std::string known = "'' (the default `subsection Material`)";
        for (const auto &m : materials)
          if (!m.first.empty())
            known += ", '" + m.first + "'";
        throw InputError(where, "no material named '" + name + "'; known: " + known);
      }
    return *it->second;
  }

  template <int dim>
  void
  Scene<dim>::check_axisymmetry()
  {
    using Material::StressState;
    // A scene is axisymmetric as a whole: all its deformable bodies or none.
    const BodyDescription<dim> *first = nullptr;
    for (const auto &b : bodies)
      if (!b.rigid)
        {
          const bool ax = material(b.material, "Body " + b.name + "/Material").elasticity().stress_state ==
                          StressState::axisymmetric;
          if (first == nullptr)
            {
              first         = &b;
              axisymmetric_ = ax;
            }
          else if (ax != axisymmetric_)
            throw InputError(material_subsection(b.material) + "/Stress state",
                             "the material of Body " + b.name + " is " +
                               (ax ? "" : "not ") + "axisymmetric but that of Body " +
                               first->name + " is " + (axisymmetric_ ? "" : "not") +
                               ": an axisymmetric scene has axisymmetric materials only");
        }
    if (!axisymmetric_)
      return;
    for (const auto &b : bodies)
      {
        // The ring's circumference 2 pi r takes the place of the thickness.
        if (b.varying_thickness() || b.thickness != 1.0)
          throw InputError("Body " + b.name + "/Thickness",
                           "an axisymmetric body has no thickness (each point stands for the "
                           "ring 2 pi r around the axis): leave it at 1");
        const auto box = b.shape.bounding_box();
        if (box.get_boundary_points().first[0] < 0)
          throw InputError("Body " + b.name + "/Shape",
                           "reaches x = " + std::to_string(box.get_boundary_points().first[0]) +
                             " < 0, but x is the radius r >= 0 in an axisymmetric scene");
      }
  }

  template <int dim>
  void
  Scene<dim>::refuse_fem_only_sets(const std::string &method, const bool history_tables) const
  {
    const std::string why = " is a Gmsh physical group, which only the fem method (with FEM/Mesh/"
                            "Generator = file) reads; the " +
                            method + " method needs a set of Faces and/or a Region";
    for (const auto &b : boundaries)
      if (!b.physical_group.empty())
        throw InputError("Boundary " + b.name + "/Set", "the set '" + b.set + "'" + why);
    for (const auto &l : loads)
      if (!l.physical_group.empty())
        throw InputError("Load " + l.name + "/Set", "the set '" + l.set + "'" + why);
    if (!history_tables && !output.history_sets.empty())
      throw InputError("Output/History sets",
                       "the " + method + " method writes no set histories (the fem and rbsn methods "
                       "do; use probes, averages and reactions.csv)");
  }

  template <int dim>
  std::string
  Scene<dim>::resolve_input_file(const std::string &name) const
  {
    std::error_code ec;
    std::string     path = name;
    if (!name.empty() && !std::filesystem::exists(name, ec) && !std::filesystem::path(name).is_absolute())
      {
        const auto beside = std::filesystem::path(options.parameter_file).parent_path() / name;
        if (std::filesystem::exists(beside, ec))
          path = beside.string();
      }
    if (!path.empty() && std::filesystem::is_regular_file(path, ec) &&
        std::find(resolved_inputs.begin(), resolved_inputs.end(), path) == resolved_inputs.end())
      resolved_inputs.push_back(path);
    return path;
  }



  template <int dim>
  std::vector<std::string>
  Scene<dim>::input_files() const
  {
    std::vector<std::string> files = options.input_files;
    for (const auto &f : resolved_inputs)
      if (std::find(files.begin(), files.end(), f) == files.end())
        files.push_back(f);
    return files;
  }



  template <int dim>
  std::vector<std::string>
  Scene<dim>::material_names() const
  {
    std::vector<std::string> names;
    for (const auto &m : materials)
      names.push_back(m.first);
    return names;
  }

  namespace Methods
  {
    template <int dim>
    std::string
    Interface<dim>::output_directory() const
    {
      const std::string &directory = get_scene().output_control().directory;
      return subdirectory.empty() ? directory : directory + "/" + subdirectory;
    }

    template class Interface<2>;
    template class Interface<3>;
  } // namespace Methods

  template class Scene<2>;
  template class Scene<3>;
} // namespace hysteron
