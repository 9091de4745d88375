#include <deal.II/base/multithread_info.h>
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>

#include <hysteron/base/newton.h>
#include <hysteron/base/parameters.h>
#include "fem/fem.h"
#include <hysteron/geometry/mesh.h>

#include "base/implicit_step.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <iostream>
#include <set>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    Solver<dim>::Solver() = default;



    template <int dim>
    Solver<dim>::~Solver()
    {
      dof_handler.clear();
    }



    namespace
    {
      /// The entries of `FEM/Mesh`.
      void
      declare_mesh_parameters(dealii::ParameterHandler &prm)
      {
        using namespace dealii;
        prm.declare_entry("Generator",
                          "automatic",
                          Patterns::Selection("automatic|structured|unstructured|file"),
                          "structured: a tensor-product mesh with lines at every coordinate of "
                          "the bodies' rectangles/boxes (exact for such bodies); unstructured "
                          "(2D): a Delaunay triangulation of the bodies' boundaries, each "
                          "triangle split into three quadrilaterals; file: a Gmsh .msh file of "
                          "quadrilaterals/hexahedra or of triangles/tetrahedra (`Mesh file`), "
                          "cells assigned to the body "
                          "that contains their centre; automatic: structured if every body is "
                          "made of rectangles/boxes, else unstructured (2D). See doc/fem.md.");
        prm.declare_entry("Cell size",
                          "0",
                          Patterns::Double(),
                          "Target cell size h [m] of the generated mesh, > 0 (not used with "
                          "`file`).");
        prm.declare_entry("Cell shape",
                          "hypercube",
                          Patterns::Selection("hypercube|simplex"),
                          "hypercube: the generated mesh of quadrilaterals / hexahedra; simplex: "
                          "each of its cells split into triangles (8 per quadrilateral) or "
                          "tetrahedra (24 per hexahedron), with FE_SimplexP elements of the "
                          "same `Degree`. A mesh file's cells decide by themselves "
                          "(Generator = file reads quadrilaterals/hexahedra or "
                          "triangles/tetrahedra). See doc/fem.md.");
        prm.declare_entry("Curved boundary resolution",
                          "0",
                          Patterns::Double(),
                          "unstructured: the segment length [m] of curved boundaries (disks "
                          "become regular polygons with sides of about this length), >= 0; 0: "
                          "half the cell size. The mesh is graded towards finer boundaries.");
        prm.declare_entry("Refinements",
                          "0",
                          Patterns::Integer(0, 10),
                          "Uniform refinements of the generated or read mesh (each halves h): "
                          "by p4est on every rank for a structured mesh of quadrilaterals / "
                          "hexahedra, on rank 0 before the mesh is partitioned for any other. "
                          "A mesh that would not fit into the machine's memory is refused "
                          "before it is made.");
        prm.declare_entry("Mesh file",
                          "",
                          Patterns::Anything(),
                          "Generator = file: a Gmsh .msh file (ASCII or binary, version 2 or "
                          "4) with quadrilaterals / triangles (2D) or hexahedra / tetrahedra "
                          "(3D), one kind per mesh; a relative name is "
                          "looked up in the working directory, then beside the parameter file. "
                          "Every cell's Jacobian is checked: inverted (clockwise) cells are "
                          "repaired with a warning; self-intersecting and degenerate cells and "
                          "coincident nodes are refused with the element (doc/fem.md).");
      }


      /// The entries of `FEM/Linear solver`.
      void
      declare_linear_solver_parameters(dealii::ParameterHandler &prm)
      {
        using namespace dealii;
        prm.declare_entry("Type",
                          "automatic",
                          Patterns::Selection("automatic|direct|cg|gmres"),
                          "direct: Trilinos Amesos KLU; cg / gmres: with ML algebraic multigrid "
                          "aggregated on the rigid-body modes of the mesh (translations and "
                          "rotations); automatic: direct up "
                          "to `Direct solver limit` DoFs, else CG if every material's tangent "
                          "is symmetric, GMRES otherwise.");
        prm.declare_entry("Direct solver package",
                          "automatic",
                          Patterns::Selection("automatic|Amesos_Klu|Amesos_Mumps"),
                          "The Trilinos Amesos package of the direct solver: KLU (left-looking, "
                          "no dense kernels: the fastest in 2D), MUMPS (multifrontal, on "
                          "OpenBLAS: 2.6 times faster than KLU on a 3D Q2 cantilever of 11k "
                          "DoFs) or automatic (the default): KLU in 2D, MUMPS in 3D. Under MPI "
                          "MUMPS factorizes in parallel, and its results vary at round-off from "
                          "run to run.");
        prm.declare_entry("Direct solver limit",
                          "100000",
                          Patterns::Integer(1),
                          "automatic: the largest number of DoFs solved directly.");
        prm.declare_entry("Tolerance",
                          "1e-10",
                          Patterns::Double(),
                          "Iterative solvers: relative residual reduction, > 0.");
        prm.declare_entry("Preconditioner reuse",
                          "true",
                          Patterns::Bool(),
                          "cg / gmres: keep the algebraic multigrid hierarchy over Newton "
                          "iterations and increments while a solve takes at most twice the "
                          "iterations (plus 10) of the first solve after its set-up; then, or "
                          "when a solve fails, it is set up again from the current tangent. "
                          "false: a new hierarchy for every solve.");
        prm.declare_entry("Maximum iterations",
                          "5000",
                          Patterns::Integer(1),
                          "Iterative solvers: iterations before the solve counts as failed.");
      }
    } // namespace



    template <int dim>
    void
    Solver<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("FEM");
      {
        prm.declare_entry("Degree",
                          "1",
                          Patterns::Integer(1, 2),
                          "Polynomial degree p of the FE_Q(p) displacement elements: 1 "
                          "(bilinear / trilinear) or 2 (biquadratic / triquadratic); Gauss "
                          "quadrature with p + 1 points per direction.");
        prm.declare_entry("B-bar",
                          "false",
                          Patterns::Bool(),
                          "Mean-dilatation (B-bar) elements: the volumetric part of the strain "
                          "(the in-plane trace in plane strain, the trace in 3D) is replaced by its "
                          "mean over the cell, in the strain increments, the internal forces and "
                          "the tangent, so that Q1 does not lock in nearly incompressible "
                          "(plastic) flow. Plane strain and 3D only (plane stress has no "
                          "volumetric constraint); not with axisymmetric scenes.");
        prm.declare_entry("Kinematics",
                          "small strain",
                          Patterns::Selection("small strain|updated Lagrangian"),
                          "small strain: equilibrium and strains in the reference configuration "
                          "(infinitesimal deformation). updated Lagrangian: equilibrium in the "
                          "current configuration (x = X + u), each increment's strain and spin at "
                          "the midpoint configuration and the stress (and the material's tensor "
                          "state) rotated with the Hughes-Winget rotation, i.e. the Jaumann rate "
                          "of the MPM's `Stress rate = Jaumann`; a rigid rotation leaves the "
                          "stress unchanged. Loads are dead loads (fixed directions, reference "
                          "areas); 2D thicknesses stay constant. Not with axisymmetric scenes. "
                          "See doc/fem.md.");
        prm.declare_entry("Threads",
                          "1",
                          Patterns::Integer(0),
                          "Threads of the element loop (assembly and material updates) on each "
                          "MPI rank; 0: the cores of the machine divided by the ranks. The cells' "
                          "contributions are added in the order of the cells, so any number above "
                          "one gives the same results; they differ from one thread's at round-off "
                          "(deal.II then computes each cell's geometry afresh instead of reusing a "
                          "translated neighbour's). A user material's update() must be safe to "
                          "call from several threads (the shipped ones are).");
        prm.declare_entry("Analysis",
                          "quasi-static",
                          Patterns::Selection("quasi-static|implicit dynamics|explicit dynamics"),
                          "quasi-static: equilibrium f_int(u) = f_ext(t) at every increment "
                          "(Newton; t is a load parameter, loads and prescribed displacements "
                          "follow it); implicit dynamics: Newmark average acceleration or "
                          "HHT-alpha with Newton; explicit dynamics: central differences with a "
                          "lumped mass matrix, as the MPM.");
        prm.declare_entry("Time step",
                          "0",
                          Patterns::Double(),
                          "Time step or load increment [s], >= 0. 0: `Time/Time step` if that is "
                          "> 0; otherwise End time / `Number of increments` (quasi-static, implicit "
                          "dynamics) or `Time/CFL factor` times the critical step (explicit). "
                          "Newton failures halve the increment automatically.");
        prm.declare_entry("Number of increments",
                          "100",
                          Patterns::Integer(1),
                          "Implicit analyses with an automatic time step: End time / this.");
        prm.declare_entry("Maximum CFL number",
                          "1",
                          Patterns::Double(),
                          "Explicit dynamics: a fixed time step larger than this multiple of the "
                          "critical step 2 / omega_max stops the run, > 0.");
        prm.declare_entry("Write quadrature point table",
                          "false",
                          Patterns::Bool(),
                          "Write quadrature_points.csv at the end: one row per quadrature point "
                          "(body, then the probe columns: position, displacement, velocity, "
                          "stress, von Mises stress, strain, material state), sorted by position.");

        prm.enter_subsection("Mesh");
        declare_mesh_parameters(prm);
        prm.leave_subsection();

        prm.enter_subsection("Newton");
        NewtonParameters::declare_parameters(prm);
        prm.leave_subsection();

        prm.enter_subsection("Dynamics");
        ImplicitDynamicsParameters::declare_parameters(prm);
        prm.leave_subsection();

        prm.enter_subsection("Linear solver");
        declare_linear_solver_parameters(prm);
        prm.leave_subsection();
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Solver<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      const Scene<dim> &scene = this->get_scene();
      {
        Section s(prm, {"FEM"});
        degree                 = s.get_integer("Degree");
        b_bar                  = s.get_bool("B-bar");
        if (b_bar)
          {
            require(!scene.axisymmetric(),
                    s.where("B-bar"),
                    "B-bar is not available in an axisymmetric scene (the hoop strain is part of "
                    "the dilatation)");
            if (dim == 2)
              for (const auto &b : scene.body_descriptions())
                if (!b.rigid)
                  require(scene.material(b.material, "Body " + b.name + "/Material").elasticity().stress_state ==
                            Material::StressState::plane_strain,
                          s.where("B-bar"),
                          "B-bar needs plane strain, but the material of Body " + b.name +
                            " is not (plane stress has no volumetric locking)");
          }
        finite_strain = s.get("Kinematics") == "updated Lagrangian";
        require(!finite_strain || !scene.axisymmetric(),
                s.where("Kinematics"),
                "the updated-Lagrangian FEM is not available in an axisymmetric scene (use "
                "small strain, or the MPM with Stress rate = Jaumann)");
        threads = s.get_integer("Threads");
        const std::string type = s.get("Analysis");
        analysis = type == "quasi-static"      ? Analysis::quasi_static :
                   type == "implicit dynamics" ? Analysis::implicit_dynamics :
                                                 Analysis::explicit_dynamics;
        fem_time_step    = s.get_non_negative("Time step");
        n_increments     = s.get_integer("Number of increments");
        maximum_cfl      = s.get_positive("Maximum CFL number");
        quadrature_table = s.get_bool("Write quadrature point table");
      }
      {
        Section s(prm, {"FEM", "Mesh"});
        generator   = s.get("Generator");
        cell_size   = s.get_non_negative("Cell size");
        refinements = s.get_integer("Refinements");
        boundary_resolution = s.get_non_negative("Curved boundary resolution");
        generate_simplices  = s.get("Cell shape") == "simplex";
        require(!generate_simplices || generator != "file",
                s.where("Cell shape"),
                "a mesh file's cells are read as they are (quadrilaterals / hexahedra or "
                "triangles / tetrahedra); Cell shape = simplex splits generated meshes only");
        mesh_file   = scene.resolve_input_file(dealii::Utilities::trim(s.get("Mesh file")));
        if (generator == "file")
          {
            require(!mesh_file.empty(), s.where("Mesh file"), "Generator = file needs a mesh file");
            std::error_code ec;
            require(std::filesystem::is_regular_file(mesh_file, ec),
                    s.where("Mesh file"),
                    "cannot open '" + mesh_file + "': no such file (relative names are looked up "
                    "in the working directory, then beside the parameter file)");
          }
        else
          {
            require(cell_size > 0,
                    s.where("Cell size"),
                    "must be > 0 for the " + generator + " mesh generator (got " +
                      s.get("Cell size") + ")");
            require(mesh_file.empty(),
                    s.where("Mesh file"),
                    "a mesh file is only read with Generator = file");
          }
        if (generator == "unstructured")
          require(dim == 2,
                  s.where("Generator"),
                  "the unstructured generator is two-dimensional; in 3D use structured (boxes) "
                  "or a Gmsh file");
      }
      {
        newton.parse_parameters(Section(prm, {"FEM", "Newton"}));
      }
      dynamics.parse_parameters(Section(prm, {"FEM", "Dynamics"}));
      {
        Section           s(prm, {"FEM", "Linear solver"});
        const std::string type = s.get("Type");
        solver_type            = type == "automatic" ? LinearSolver::automatic :
                                 type == "direct"    ? LinearSolver::direct :
                                 type == "cg"        ? LinearSolver::cg :
                                                       LinearSolver::gmres;
        direct_limit          = s.get_integer("Direct solver limit");
        direct_package        = s.get("Direct solver package");
        if (direct_package == "automatic")
          direct_package = dim == 3 ? "Amesos_Mumps" : "Amesos_Klu";
        solver_tolerance      = s.get_positive("Tolerance");
        solver_max_iterations = s.get_integer("Maximum iterations");
        reuse_preconditioner  = s.get_bool("Preconditioner reuse");
      }

      // What the scene asks of this method.
      const auto &bodies = scene.body_descriptions();
      require(!bodies.empty(), "Body names", "the fem method needs at least one body");
      bool deformable = false;
      for (const auto &b : bodies)
        deformable = deformable || !b.rigid;
      require(deformable, "Body names", "the fem method needs at least one body that is not rigid");
      using Type = typename BoundaryDescription<dim>::Type;
      for (const auto &b : scene.boundary_descriptions())
        if (b.type == Type::wall)
          require(analysis == Analysis::explicit_dynamics,
                  "Boundary " + b.name + "/Type",
                  "a wall (unilateral contact) needs FEM/Analysis = explicit dynamics; "
                  "implicit analyses support fixed, roller, velocity and displacement");
      for (const auto &b : scene.boundary_descriptions())
        if (b.type == Type::absorbing)
          require(analysis != Analysis::quasi_static,
                  "Boundary " + b.name + "/Type",
                  "an absorbing boundary is a dashpot on the velocities, which a quasi-static "
                  "analysis does not have: use FEM/Analysis = implicit dynamics or explicit dynamics");
      require(analysis != Analysis::quasi_static || scene.ground_motion().empty(),
              "Ground motion/File",
              "a ground motion is a base excitation, which needs inertia: use FEM/Analysis = "
              "implicit dynamics or explicit dynamics");
      if (analysis == Analysis::quasi_static)
        for (const auto &b : bodies)
          require(!b.initial_velocity || b.rigid,
                  "Body " + b.name + "/Initial velocity",
                  "a quasi-static analysis has no velocities (use FEM/Analysis = implicit "
                  "dynamics or explicit dynamics)");
    }



    template <int dim>
    void
    Solver<dim>::setup()
    {
      const Scene<dim> &scene = this->get_scene();
      const auto       &time  = scene.time_control();
      // The element loop's threads (everything else keeps the one MPI_InitFinalize sets).
      if (threads == 0)
        threads = std::max(1u, dealii::MultithreadInfo::n_cores() /
                                 dealii::Utilities::MPI::n_mpi_processes(scene.mpi_communicator()));
      make_mesh();
      setup_system();
      setup_history();
      setup_dirichlet();
      check_supports();
      warn_about_locking();
      setup_loads();
      setup_absorbing();
      setup_probes();
      setup_set_histories();
      setup_dynamics();
      const std::string analysis_name = analysis == Analysis::quasi_static      ? "quasi-static" :
                                        analysis == Analysis::implicit_dynamics ? "implicit dynamics" :
                                                                                  "explicit dynamics";
      scene.console() << "fem: " << triangulation->n_global_active_cells() << " cells, "
                      << dof_handler.n_dofs() << " DoFs (" << (simplex ? "P" : "Q") << degree << (b_bar ? ", B-bar" : "")
                      << (finite_strain ? ", updated Lagrangian" : "") << "), " << analysis_name;
      if (analysis != Analysis::explicit_dynamics)
        scene.console() << ", " << solver_name << " linear solver";
      else
        scene.console() << ", critical step " << critical_step << " s";
      scene.console() << std::endl;
      if (analysis != Analysis::explicit_dynamics && !consistent_tangent && scene.is_root())
        std::cerr << "hysteron: warning: FEM: a material's tangent is not its algorithmic "
                     "tangent (Bouc-Wen: Integrator = adaptive or forward euler), so Newton "
                     "converges linearly; Integrator = backward euler gives quadratic convergence"
                  << std::endl;

      // The nominal step (halved by the increment control when Newton fails).
      double nominal = fem_time_step > 0 ? fem_time_step : time.time_step;
      if (analysis == Analysis::explicit_dynamics && nominal == 0)
        nominal = time.cfl_factor * critical_step;
      else if (nominal == 0)
        nominal = time.end_time / n_increments;
      increments = increment_control(nominal, newton.max_cuts, time, analysis != Analysis::explicit_dynamics);
      step_checked = false;
    }



    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      open_tables();
    }



    template <int dim>
    void
    Solver<dim>::warn_about_locking() const
    {
      // Fully integrated Q1 (without B-bar) and P1 (constant strain) constrain the
      // dilatation at every Gauss point resp. cell. As nu -> 1/2 the bulk modulus outgrows
      // the shear modulus, lambda / mu = 2 nu / (1 - 2 nu) (49 at nu = 0.49, 5,000 at
      // 0.4999), and these constraints stiffen the mesh by a factor that grows with it
      // (volumetric locking). Plane stress has no such constraint (eps_zz is free).
      const Scene<dim> &scene = this->get_scene();
      if (degree != 1 || (b_bar && !simplex))
        return;
      std::ostringstream materials;
      std::set<std::string> seen;
      double                worst = 0;
      for (const auto &b : scene.body_descriptions())
        {
          const std::string name = b.material.empty() ? "Material" : "Material " + b.material;
          if (b.rigid || !seen.insert(name).second)
            continue;
          const auto &el = scene.material(b.material, "Body " + b.name + "/Material").elasticity();
          if ((dim == 2 && el.stress_state == Material::StressState::plane_stress) || !(el.poissons_ratio >= 0.49))
            continue;
          materials << (worst > 0 ? ", " : "") << name << " (Poisson's ratio " << el.poissons_ratio << ")";
          worst = std::max(worst, el.poissons_ratio);
        }
      if (worst == 0 || !scene.is_root())
        return;
      std::cerr << "hysteron: warning: FEM: " << materials.str() << " is nearly incompressible (0.49 or more), and "
                << (simplex ? "linear triangles / tetrahedra (P1)" : "bilinear / trilinear elements (Q1) without B-bar")
                << " lock volumetrically: the mesh is too stiff by a factor that grows with lambda / mu = "
                << 2 * worst / (1 - 2 * worst) << " (a Q1 plane-strain cantilever at 0.4999: 18 times). "
                << (simplex                ? "B-bar cannot help P1: use FEM/Degree = 2." :
                    scene.axisymmetric() ? "Use FEM/Degree = 2 (B-bar is not available in an axisymmetric scene)." :
                                           "Use FEM/B-bar = true or FEM/Degree = 2.")
                << std::endl;
    }



    template <int dim>
    double
    Solver<dim>::propose_step(const double t)
    {
      if (analysis == Analysis::explicit_dynamics && !step_checked)
        {
          const double nominal = increments.nominal();
          if (nominal > maximum_cfl * critical_step)
            {
              std::ostringstream m;
              m << "fem: the time step " << nominal << " s is above the critical step "
                << critical_step << " s = 2 / omega_max of central differences"
                << (absorbers.empty() ? "" : " (lowered by the dashpots of absorbing boundaries)") << " times "
                << "FEM/Maximum CFL number = " << maximum_cfl
                << ": the explicit scheme would be unstable. Use a time step <= "
                << maximum_cfl * critical_step << " s or 0 (automatic).";
              throw Run::StepFailure(m.str());
            }
          step_checked = true;
        }
      return increments.step(t, this->get_scene().time_control().end_time);
    }



    template <int dim>
    bool
    Solver<dim>::advance(double &t, const double dt)
    {
      if (analysis == Analysis::explicit_dynamics)
        explicit_step(t, dt);
      else
        {
          if (!implicit_step(t, dt))
            {
              if (increments.cut())
                return false;
              n_cuts = increments.cuts();
              const std::string cause =
                !material_failure.empty() ?
                  "the last failure was in the material: " + material_failure :
                  residual_cause(system_rhs.l2_norm() / force_level(), std::max(newton.tolerance, residual_floor()));
              throw Run::StepFailure(increment_failure("fem", t, dt, increments, {cause}));
            }
          commit(t + dt, dt);
        }
      increments.accept(t, dt);
      n_cuts = increments.cuts();
      return true;
    }



    template <int dim>
    void
    Solver<dim>::finish(const double)
    {
      if (quadrature_table)
        write_quadrature_table();
      // The load-displacement curves of the history sets (rank 0; a warning, never an error).
      tables.flush();
      for (const auto &warning : tables.draw_histories())
        std::cerr << "hysteron: warning: " << warning << std::endl;
    }



    template <int dim>
    std::string
    Solver<dim>::summary() const
    {
      std::ostringstream s;
      s << this->n_steps() << " steps";
      if (analysis != Analysis::explicit_dynamics)
        s << ", " << n_newton << " Newton iterations, " << n_cuts << " increment cuts";
      s << ", " << dof_handler.n_dofs() << " DoFs, " << this->n_outputs() << " outputs";
      if (analysis != Analysis::explicit_dynamics && solver_type != LinearSolver::direct)
        s << ", " << n_linear << " linear iterations, " << n_amg_setups << " AMG set-ups";
      // The material's share of the timer's "FEM assembly" (this rank's).
      std::ostringstream seconds;
      seconds << std::setprecision(3) << material_seconds;
      s << ", material updates " << seconds.str() << " s of the assembly";
      return s.str();
    }

    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::FEM::Solver,
                         "fem",
                         "the hysteretic finite element method: FE_Q(1 or 2) elements on a mesh "
                         "of the bodies, quasi-static (Newton), implicit (Newmark / HHT) or "
                         "explicit (central differences) dynamics; see doc/fem.md");
