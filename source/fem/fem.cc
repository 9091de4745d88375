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
#include <hysteron/fem/fem.h>
#include <hysteron/geometry/mesh.h>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      const char *const *const component_names = PointData::component_names;
    } // namespace



    template <int dim>
    Solver<dim>::Solver()
      : triangulation(MPI_COMM_WORLD)
      , mapping(1)
    {}



    template <int dim>
    Solver<dim>::~Solver()
    {
      dof_handler.clear();
    }



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
        {
          prm.declare_entry("Generator",
                            "automatic",
                            Patterns::Selection("automatic|structured|unstructured|file"),
                            "structured: a tensor-product mesh with lines at every coordinate of "
                            "the bodies' rectangles/boxes (exact for such bodies); unstructured "
                            "(2D): a Delaunay triangulation of the bodies' boundaries, each "
                            "triangle split into three quadrilaterals; file: a Gmsh .msh file of "
                            "quadrilaterals/hexahedra (`Mesh file`), cells assigned to the body "
                            "that contains their centre; automatic: structured if every body is "
                            "made of rectangles/boxes, else unstructured (2D). See doc/fem.md.");
          prm.declare_entry("Cell size",
                            "0",
                            Patterns::Double(),
                            "Target cell size h [m] of the generated mesh, > 0 (not used with "
                            "`file`).");
          prm.declare_entry("Curved boundary resolution",
                            "0",
                            Patterns::Double(),
                            "unstructured: the segment length [m] of curved boundaries (disks "
                            "become regular polygons with sides of about this length), >= 0; 0: "
                            "half the cell size. The mesh is graded towards finer boundaries.");
          prm.declare_entry("Refinements",
                            "0",
                            Patterns::Integer(0, 10),
                            "Uniform refinements of the generated or read mesh (each halves h).");
          prm.declare_entry("Mesh file",
                            "",
                            Patterns::Anything(),
                            "Generator = file: a Gmsh .msh file (ASCII or binary, version 2 or "
                            "4) with quadrilaterals (2D) or hexahedra (3D); a relative name is "
                            "looked up in the working directory, then beside the parameter file.");
        }
        prm.leave_subsection();

        prm.enter_subsection("Newton");
        NewtonParameters::declare_parameters(prm);
        prm.leave_subsection();

        prm.enter_subsection("Dynamics");
        ImplicitDynamicsParameters::declare_parameters(prm);
        prm.leave_subsection();

        prm.enter_subsection("Linear solver");
        {
          prm.declare_entry("Type",
                            "automatic",
                            Patterns::Selection("automatic|direct|cg|gmres"),
                            "direct: Trilinos Amesos KLU; cg / gmres: with ML algebraic multigrid "
                            "(elasticity: one constant mode per component); automatic: direct up "
                            "to `Direct solver limit` DoFs, else CG if every material's tangent "
                            "is symmetric, GMRES otherwise.");
          prm.declare_entry("Direct solver package",
                            "Amesos_Klu",
                            Patterns::Selection("Amesos_Klu|Amesos_Mumps"),
                            "The Trilinos Amesos package of the direct solver: KLU (the default; "
                            "fastest here up to ~1e5 DoFs in 2D with Debian's reference BLAS) or "
                            "MUMPS (multifrontal; pays off with an optimised BLAS and in 3D).");
          prm.declare_entry("Direct solver limit",
                            "100000",
                            Patterns::Integer(1),
                            "automatic: the largest number of DoFs solved directly.");
          prm.declare_entry("Tolerance",
                            "1e-10",
                            Patterns::Double(),
                            "Iterative solvers: relative residual reduction, > 0.");
          prm.declare_entry("Maximum iterations",
                            "5000",
                            Patterns::Integer(1),
                            "Iterative solvers: iterations before the solve counts as failed.");
        }
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
        solver_tolerance      = s.get_positive("Tolerance");
        solver_max_iterations = s.get_integer("Maximum iterations");
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
      if (analysis == Analysis::quasi_static)
        for (const auto &b : bodies)
          require(!b.initial_velocity || b.rigid,
                  "Body " + b.name + "/Initial velocity",
                  "a quasi-static analysis has no velocities (use FEM/Analysis = implicit "
                  "dynamics or explicit dynamics)");
    }



    template <int dim>
    void
    Solver<dim>::make_mesh()
    {
      const Scene<dim> &scene  = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      body_to_mesh.assign(bodies.size(), dealii::numbers::invalid_unsigned_int);
      mesh_to_body.clear();
      std::vector<const Geometry::Region<dim> *> shapes;
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (!bodies[b].rigid)
          {
            body_to_mesh[b] = mesh_to_body.size();
            mesh_to_body.push_back(b);
            shapes.push_back(&bodies[b].shape);
          }

      if (generator == "file")
        {
          dealii::Triangulation<dim> serial;
          dealii::GridIn<dim>        in;
          in.attach_triangulation(serial);
          try
            {
              in.read_msh(mesh_file);
            }
          catch (const dealii::ExceptionBase &e)
            {
              std::ostringstream m;
              e.print_info(m);
              throw InputError("FEM/Mesh/Mesh file", "cannot read '" + mesh_file + "': " + m.str());
            }
          for (const auto &cell : serial.active_cell_iterators())
            {
              require(cell->reference_cell() == dealii::ReferenceCells::get_hypercube<dim>(),
                      "FEM/Mesh/Mesh file",
                      "'" + mesh_file + "' has " + cell->reference_cell().to_string() +
                        " cells; the fem method needs quadrilaterals (2D) or hexahedra (3D) "
                        "(in Gmsh: Mesh.RecombineAll = 1 and Mesh.SubdivisionAlgorithm = 1)");
              const auto   centre = cell->center();
              unsigned int body   = dealii::numbers::invalid_unsigned_int;
              for (unsigned int m = 0; m < shapes.size() && body == dealii::numbers::invalid_unsigned_int; ++m)
                if (shapes[m]->contains(centre, 1e-9 * cell->diameter()))
                  body = m;
              if (body == dealii::numbers::invalid_unsigned_int)
                {
                  std::ostringstream p;
                  p << centre;
                  throw InputError("FEM/Mesh/Mesh file",
                                   "the cell with centre (" + p.str() + ") of '" + mesh_file +
                                     "' lies in no body's Shape");
                }
              cell->set_material_id(body);
            }
          triangulation.copy_triangulation(serial);
        }
      else
        {
          std::string kind = generator;
          if (kind == "automatic")
            {
              bool rectilinear = true;
              for (const auto *shape : shapes)
                rectilinear = rectilinear && Geometry::is_rectilinear(*shape);
              require(rectilinear || dim == 2,
                      "FEM/Mesh/Generator",
                      "in 3D only bodies made of boxes are meshed automatically; give a Gmsh "
                      "file (Generator = file)");
              kind = rectilinear ? "structured" : "unstructured";
            }
          Geometry::CoarseMesh<dim> mesh;
          if constexpr (dim == 2)
            mesh = kind == "structured" ?
                     Geometry::structured_mesh<dim>(shapes, cell_size, "FEM/Mesh/Cell size") :
                     // The generator's size bound is that of its triangles; each is split
                     // into three quadrilaterals with edges of at most half of it.
                     Geometry::unstructured_mesh(shapes, 2 * cell_size, "FEM/Mesh/Cell size",
                                                 boundary_resolution > 0 ? boundary_resolution :
                                                                           0.5 * cell_size);
          else
            mesh = Geometry::structured_mesh<dim>(shapes, cell_size, "FEM/Mesh/Cell size");
          if (kind == "structured")
            {
              // A staircase approximation of a curved or oblique body is refused.
              double body_volume = 0;
              for (const auto *shape : shapes)
                body_volume += shape->volume_estimate();
              const double mismatch = std::abs(mesh.volume() - body_volume) / body_volume;
              require(mismatch < 2e-3,
                      "FEM/Mesh/Generator",
                      "the structured mesh misses " + std::to_string(100 * mismatch) +
                        " % of the bodies' volume (a body is not made of rectangles/boxes): "
                        "use Generator = unstructured (2D) or a Gmsh file");
            }
          triangulation.create_triangulation(mesh.vertices, mesh.cells, dealii::SubCellData());
        }
      if (refinements > 0)
        triangulation.refine_global(refinements);

      // The bounding box of the mesh (faces of boundary conditions) and its scale.
      std::vector<dealii::Point<dim>> corners;
      for (const auto &cell : triangulation.active_cell_iterators())
        if (cell->is_locally_owned())
          for (const unsigned int v : cell->vertex_indices())
            corners.push_back(cell->vertex(v));
      dealii::Point<dim> lo, hi;
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::numeric_limits<double>::max();
          hi[d] = -std::numeric_limits<double>::max();
        }
      for (const auto &p : corners)
        for (unsigned int d = 0; d < dim; ++d)
          {
            lo[d] = std::min(lo[d], p[d]);
            hi[d] = std::max(hi[d], p[d]);
          }
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = dealii::Utilities::MPI::min(lo[d], scene.mpi_communicator());
          hi[d] = dealii::Utilities::MPI::max(hi[d], scene.mpi_communicator());
        }
      mesh_box = dealii::BoundingBox<dim>(std::make_pair(lo, hi));
      u_scale  = 0;
      for (unsigned int d = 0; d < dim; ++d)
        u_scale = std::max(u_scale, hi[d] - lo[d]);
    }



    template <int dim>
    void
    Solver<dim>::setup_system()
    {
      using namespace dealii;
      const Scene<dim> &scene = this->get_scene();
      MPI_Comm          comm  = scene.mpi_communicator();
      fe              = std::make_unique<FESystem<dim>>(FE_Q<dim>(degree), dim);
      quadrature      = std::make_unique<QGauss<dim>>(degree + 1);
      face_quadrature = std::make_unique<QGauss<dim - 1>>(degree + 1);
      dof_handler.reinit(triangulation);
      dof_handler.distribute_dofs(*fe);
      owned_dofs = dof_handler.locally_owned_dofs();
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant_dofs);

      u.reinit(owned_dofs, comm);
      for (Vector *w : {&v, &a, &u_trial, &f_int, &f_ext, &f_int_old, &f_ext_old, &inertia})
        w->reinit(owned_dofs, comm);
      u_ghost.reinit(owned_dofs, relevant_dofs, comm);
      v_ghost.reinit(owned_dofs, relevant_dofs, comm);
      a_ghost.reinit(owned_dofs, relevant_dofs, comm);

      // Materials of the mesh's bodies; the tangent kinds decide the solver.
      const auto &bodies = scene.body_descriptions();
      body_material.assign(mesh_to_body.size(), nullptr);
      state_names.clear();
      symmetric_tangent = consistent_tangent = true;
      unsigned int n_state = 0;
      for (unsigned int m = 0; m < mesh_to_body.size(); ++m)
        {
          const auto &body = bodies[mesh_to_body[m]];
          body_material[m] = &scene.material(body.material, "Body " + body.name + "/Material");
          if (body_material[m]->n_state_variables() > n_state)
            {
              n_state     = body_material[m]->n_state_variables();
              state_names = body_material[m]->state_variable_names();
            }
          consistent_tangent = consistent_tangent && body_material[m]->has_consistent_tangent();
          // Hooke's law and the continuum Bouc-Wen tangents are symmetric; the
          // algorithmic tangents of a general local Newton need not be.
          symmetric_tangent = symmetric_tangent && (body_material[m]->n_state_variables() == 0 ||
                                                    !body_material[m]->has_consistent_tangent());
        }

      const unsigned long n_dofs = dof_handler.n_dofs();
      LinearSolver        chosen = solver_type;
      if (chosen == LinearSolver::automatic)
        chosen = n_dofs <= direct_limit ? LinearSolver::direct :
                 symmetric_tangent      ? LinearSolver::cg :
                                          LinearSolver::gmres;
      solver_type = chosen;
      solver_name = chosen == LinearSolver::direct ? "direct (" + direct_package + ")" :
                    chosen == LinearSolver::cg     ? "CG + AMG" :
                                                     "GMRES + AMG";

      if (analysis != Analysis::explicit_dynamics)
        {
          // The constrained DoFs are the same in every step (only their values
          // change), so one sparsity pattern serves the whole run.
          make_constraints(0.0, false);
          DynamicSparsityPattern dsp(relevant_dofs);
          DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
          SparsityTools::distribute_sparsity_pattern(dsp, owned_dofs, comm, relevant_dofs);
          system_matrix.reinit(owned_dofs, owned_dofs, dsp, comm);
          system_rhs.reinit(owned_dofs, comm);
        }
    }



    template <int dim>
    void
    Solver<dim>::setup_history()
    {
      const auto &bodies = this->get_scene().body_descriptions();
      const unsigned int n_q = quadrature->size();
      dealii::FEValues<dim> fv(mapping, *fe, *quadrature,
                               dealii::update_quadrature_points | dealii::update_JxW_values);
      history.initialize(triangulation.begin_active(), triangulation.end(), 1);
      // Raw pointers by active cell index: get_data() returns a vector of shared
      // pointers (an allocation per call), too slow for the assembly loops.
      cell_history.assign(triangulation.n_active_cells(), nullptr);
      for (const auto &cell : triangulation.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            cell_history[cell->active_cell_index()] = history.get_data(cell)[0].get();
            auto &h     = *cell_history[cell->active_cell_index()];
            const unsigned int m = cell->material_id();
            h.material  = body_material[m];
            h.body      = mesh_to_body[m];
            h.thickness = dim == 2 ? bodies[h.body].thickness : 1.0;
            h.n_state   = h.material->n_state_variables();
            h.stress.assign(n_q, dealii::SymmetricTensor<2, dim>());
            h.strain        = h.stress;
            h.trial_stress  = h.stress;
            h.increment     = h.stress;
            h.state.resize(n_q * h.n_state);
            for (unsigned int q = 0; q < n_q; ++q)
              h.material->initialize_state(
                dealii::ArrayView<double>(h.state.data() + q * h.n_state, h.n_state));
            h.trial_state = h.state;
            h.weight.resize(n_q);
            h.point.resize(n_q);
            fv.reinit(cell);
            for (unsigned int q = 0; q < n_q; ++q)
              {
                h.weight[q] = fv.JxW(q) * h.thickness;
                h.point[q]  = fv.quadrature_point(q);
              }
            // Until a first evaluation: the elastic tangent (the first predictor).
            h.tangent.assign(n_q, h.material->elasticity().template stiffness<dim>());
          }
    }



    template <int dim>
    void
    Solver<dim>::setup_dirichlet()
    {
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      std::map<dealii::types::global_dof_index, dealii::Point<dim>> support;
      dealii::DoFTools::map_dofs_to_support_points(mapping, dof_handler, support);
      std::map<dealii::types::global_dof_index, unsigned int> component;
      std::vector<dealii::types::global_dof_index>            dofs(fe->n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (!cell->is_artificial())
          {
            cell->get_dof_indices(dofs);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              component[dofs[i]] = fe->system_to_component_index(i).first;
          }

      // Support point and component of every owned DoF (loads, walls, start vectors).
      owned_support.resize(owned_dofs.n_elements());
      owned_component.resize(owned_dofs.n_elements());
      for (const auto &[dof, p] : support)
        if (owned_dofs.is_element(dof))
          {
            owned_support[owned_dofs.index_within_set(dof)]   = p;
            owned_component[owned_dofs.index_within_set(dof)] = component[dof];
          }

      const double tolerance = 1e-9 * u_scale;
      dirichlet.clear();
      wall_forces.clear();
      walls.clear();
      std::map<dealii::types::global_dof_index, int> taken; // first set wins
      const auto add = [&](DirichletSet &set, const dealii::types::global_dof_index dof, const unsigned int c, const int index) {
        if (taken.count(dof))
          return;
        taken[dof] = index;
        set.dofs.push_back(dof);
        set.components.push_back(c);
      };
      for (unsigned int b = 0; b < scene.boundary_descriptions().size(); ++b)
        {
          const auto  &d = scene.boundary_descriptions()[b];
          DirichletSet set;
          set.name     = d.name;
          set.boundary = b;
          const int index = dirichlet.size();
          if (d.type == Type::wall)
            {
              // Unilateral: handled by the explicit step, not as a constraint.
              for (const unsigned int face : d.faces)
                {
                  Wall w;
                  w.set       = index;
                  w.direction = face / 2;
                  w.lower     = face % 2 == 0;
                  w.position  = w.lower ? mesh_box.lower_bound(w.direction) :
                                          mesh_box.upper_bound(w.direction);
                  walls.push_back(w);
                }
              dirichlet.push_back(set);
              continue;
            }
          for (const auto &[dof, p] : support)
            {
              const unsigned int c = component[dof];
              for (const unsigned int face : d.faces)
                {
                  const unsigned int dir = face / 2;
                  const double       x   = face % 2 == 0 ? mesh_box.lower_bound(dir) :
                                                            mesh_box.upper_bound(dir);
                  if (std::abs(p[dir] - x) <= tolerance &&
                      (d.type != Type::roller || c == dir) &&
                      (d.type == Type::fixed || d.type == Type::roller || d.components[c]))
                    add(set, dof, c, index);
                }
              if (d.has_region && d.region.contains(p, tolerance) &&
                  (d.type == Type::fixed || d.components[c]))
                add(set, dof, c, index);
            }
          const unsigned long n = dealii::Utilities::MPI::sum<unsigned long>(set.dofs.size(), scene.mpi_communicator());
          require(n > 0,
                  "Boundary " + d.name + (d.has_region ? "/Region" : "/Faces"),
                  "selects no node of the fem mesh (faces are those of the mesh's bounding "
                  "box; a region must contain mesh nodes)");
          dirichlet.push_back(std::move(set));
        }
      // Rigid bodies prescribe their motion on the mesh nodes inside them.
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          {
            DirichletSet set;
            set.name        = bodies[b].name;
            set.rigid       = b;
            const int index = dirichlet.size();
            for (const auto &[dof, p] : support)
              if (bodies[b].shape.contains(p, tolerance))
                add(set, dof, component[dof], index);
            const unsigned long n = dealii::Utilities::MPI::sum<unsigned long>(set.dofs.size(), scene.mpi_communicator());
            require(n > 0,
                    "Body " + bodies[b].name + "/Shape",
                    "the rigid body touches no node of the fem mesh (it acts on the nodes of "
                    "the deformable bodies that lie in its shape)");
            dirichlet.push_back(std::move(set));
          }

      constrained_list.clear();
      constrained_set.clear();
      constrained_component.clear();
      constrained_point.clear();
      for (unsigned int s = 0; s < dirichlet.size(); ++s)
        for (unsigned int k = 0; k < dirichlet[s].dofs.size(); ++k)
          {
            constrained_list.push_back(dirichlet[s].dofs[k]);
            constrained_set.push_back(s);
            constrained_component.push_back(dirichlet[s].components[k]);
            constrained_point.push_back(support[dirichlet[s].dofs[k]]);
          }

      // Walls act on the normal components of all owned DoFs.
      wall_dofs.clear();
      wall_reference.clear();
      wall_of_dof.clear();
      for (unsigned int w = 0; w < walls.size(); ++w)
        for (const auto &[dof, p] : support)
          if (owned_dofs.is_element(dof) && component[dof] == walls[w].direction && !taken.count(dof))
            {
              wall_dofs.push_back(dof);
              wall_reference.push_back(p[walls[w].direction]);
              wall_of_dof.push_back(w);
            }
      wall_forces.assign(dirichlet.size(), dealii::Tensor<1, dim>());
    }



    template <int dim>
    void
    Solver<dim>::make_constraints(const double t1, const bool predictor)
    {
      constraints.clear();
      constraints.reinit(relevant_dofs);
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        {
          constraints.add_line(constrained_list[k]);
          if (predictor)
            constraints.set_inhomogeneity(constrained_list[k],
                                          prescribed_increment(k, t1 - current_dt, t1));
        }
      constraints.close();
    }



    template <int dim>
    void
    Solver<dim>::setup_loads()
    {
      // A total force acts on the material in its region as a uniform body force
      // F / V (V: the volume of the quadrature points in the region, so that the
      // total is exact); a region without quadrature points shares F evenly among
      // the mesh nodes in it (a point load). A traction acts on the boundary faces
      // whose centre lies in the region.
      using Type              = typename LoadDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      MPI_Comm          comm  = scene.mpi_communicator();
      const auto       &loads = scene.load_descriptions();
      const double      tolerance = 1e-9 * u_scale;
      load_sets.clear();
      load_regions.clear();
      for (unsigned int l = 0; l < loads.size(); ++l)
        {
          LoadSet set;
          set.load = l;
          set.kind = loads[l].type == Type::traction ? LoadSet::Kind::traction : LoadSet::Kind::volume;
          load_sets.push_back(set);
          load_regions.push_back(&loads[l].region);
        }
      const unsigned int n_loads = load_sets.size();
      cell_in_load.assign(triangulation.n_active_cells() * n_loads, false);
      std::vector<double> selected(n_loads, 0.0);
      for (const auto &cell : triangulation.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h     = *cell_history[cell->active_cell_index()];
            const std::size_t       first = cell->active_cell_index() * n_loads;
            for (unsigned int l = 0; l < n_loads; ++l)
              if (load_sets[l].kind == LoadSet::Kind::volume)
                {
                  for (unsigned int q = 0; q < h.point.size(); ++q)
                    if (load_regions[l]->contains(h.point[q], tolerance))
                      {
                        selected[l] += h.weight[q];
                        cell_in_load[first + l] = true;
                      }
                }
              else
                for (const unsigned int f : cell->face_indices())
                  if (cell->face(f)->at_boundary() && load_regions[l]->contains(cell->face(f)->center(), tolerance))
                    {
                      selected[l] += cell->face(f)->measure() * h.thickness;
                      cell_in_load[first + l] = true;
                    }
          }
      dealii::Utilities::MPI::sum(selected, comm, selected);
      for (unsigned int l = 0; l < n_loads; ++l)
        {
          LoadSet &set = load_sets[l];
          if (set.kind == LoadSet::Kind::traction)
            {
              require(selected[l] > 0,
                      "Load " + loads[l].name + "/Region",
                      "contains the centre of no boundary face of the fem mesh");
              set.scale = 1.0;
              continue;
            }
          if (selected[l] > 0)
            {
              set.scale = 1.0 / selected[l];
              continue;
            }
          // A point load: the nodes in the region share the force evenly.
          set.kind = LoadSet::Kind::nodal;
          for (unsigned int k = 0; k < owned_dofs.n_elements(); ++k)
            if (load_regions[l]->contains(owned_support[k], tolerance))
              {
                set.nodal_dofs.push_back(owned_dofs.nth_index_in_set(k));
                set.nodal_components.push_back(owned_component[k]);
              }
          const double nodes =
            dealii::Utilities::MPI::sum<double>(set.nodal_dofs.size(), comm) / double(dim);
          require(nodes > 0,
                  "Load " + loads[l].name + "/Region",
                  "contains no quadrature point and no node of the fem mesh");
          set.scale = 1.0 / nodes;
        }
    }



    template <int dim>
    unsigned int
    Solver<dim>::solve_linear(Vector &du)
    {
      using namespace dealii;
      const double rhs_norm = system_rhs.l2_norm();
      if (solver_type == LinearSolver::direct)
        {
          SolverControl                    control(1, 0);
          TrilinosWrappers::SolverDirect   direct(control, TrilinosWrappers::SolverDirect::AdditionalData(false, direct_package));
          direct.solve(system_matrix, du, system_rhs);
          return 0;
        }
      TrilinosWrappers::PreconditionAMG                 amg;
      TrilinosWrappers::PreconditionAMG::AdditionalData data;
      std::vector<std::vector<bool>>                    modes;
      {
        const ComponentMask                           all(dim, true);
        DoFTools::extract_constant_modes(dof_handler, all, modes);
      }
      data.constant_modes        = modes;
      data.elliptic              = true;
      data.higher_order_elements = degree > 1;
      data.smoother_sweeps       = 2;
      data.aggregation_threshold = 0.02;
      amg.initialize(system_matrix, data);
      SolverControl control(solver_max_iterations, std::max(1e-300, solver_tolerance * rhs_norm));
      try
        {
          if (solver_type == LinearSolver::cg)
            {
              SolverCG<Vector> cg(control);
              cg.solve(system_matrix, du, system_rhs, amg);
            }
          else
            {
              // Right preconditioning: the convergence test sees the true residual.
              SolverGMRES<Vector> gmres(control, SolverGMRES<Vector>::AdditionalData(100, true));
              gmres.solve(system_matrix, du, system_rhs, amg);
            }
        }
      catch (const SolverControl::NoConvergence &e)
        {
          std::ostringstream m;
          m << "fem: the " << solver_name << " linear solver did not converge in " << e.last_step
            << " iterations (residual " << e.last_residual << ", target "
            << control.tolerance() << "); raise FEM/Linear solver/Maximum iterations or use "
            << "Type = direct";
          throw RuntimeError(m.str());
        }
      return control.last_step();
    }



    template <int dim>
    bool
    Solver<dim>::implicit_step(const double t, const double dt)
    {
      const Scene<dim> &scene = this->get_scene();
      MPI_Comm          comm  = scene.mpi_communicator();
      const double      t1    = t + dt;
      current_dt              = dt;
      material_failure.clear();
      Vector du(owned_dofs, comm), ghost(owned_dofs, relevant_dofs, comm);

      // Predictor: the tangent of the converged state, the prescribed increments
      // as inhomogeneous constraints (spreads the motion of the boundary over the body).
      make_constraints(t1, true);
      ghost = u;
      if (!assemble(ghost, t1, dt, Assemble::residual_and_matrix, false))
        return false;
      // The out-of-balance force of the prescribed increments: the force level of a
      // step that moves the body without loading it (a rigid motion).
      predictor_level = system_rhs.l2_norm();
      n_linear += solve_linear(du);
      constraints.distribute(du);
      make_constraints(t1, false);
      u_trial = u;
      u_trial += du;
      ghost = u_trial;
      if (!assemble(ghost, t1, dt, Assemble::residual_and_matrix))
        return false;
      log_newton(t1, dt, 0, system_rhs.l2_norm(), 1.0);

      // The iterations (line search, round-off floor): base/newton.h.
      struct Problem : NewtonProblem
      {
        Solver &s;
        double  t1, dt;
        Vector &du, &ghost;
        Vector  start;
        Problem(Solver &s, double t1, double dt, Vector &du, Vector &ghost)
          : s(s), t1(t1), dt(dt), du(du), ghost(ghost), start(du)
        {}
        bool
        evaluate(const bool matrix) override
        {
          ghost = s.u_trial;
          return s.assemble(ghost, t1, dt, matrix ? Assemble::residual_and_matrix : Assemble::forces);
        }
        double
        residual() const override
        {
          return s.system_rhs.l2_norm();
        }
        double
        force_level() const override
        {
          return s.force_level();
        }
        void
        solve_correction() override
        {
          du = 0;
          s.n_linear += s.solve_linear(du);
          s.constraints.distribute(du);
        }
        void
        remember_start() override
        {
          start = s.u_trial;
        }
        void
        move(const double alpha) override
        {
          s.u_trial = start;
          s.u_trial.add(alpha, du);
        }
        void
        log(const unsigned int iteration, const double residual, const double alpha) override
        {
          s.log_newton(t1, dt, iteration, residual, alpha);
        }
      } problem(*this, t1, dt, du, ghost);
      const unsigned int iterations = newton_iterate(problem, newton, residual_floor());
      n_newton += iterations > 0 ? iterations : newton.max_iterations;
      return iterations > 0;
    }



    template <int dim>
    void
    Solver<dim>::setup()
    {
      const Scene<dim> &scene = this->get_scene();
      const auto       &time  = scene.time_control();
      make_mesh();
      setup_system();
      setup_history();
      setup_dirichlet();
      setup_loads();
      setup_probes();
      setup_dynamics();
      const std::string analysis_name = analysis == Analysis::quasi_static      ? "quasi-static" :
                                        analysis == Analysis::implicit_dynamics ? "implicit dynamics" :
                                                                                  "explicit dynamics";
      scene.console() << "fem: " << triangulation.n_global_active_cells() << " cells, "
                      << dof_handler.n_dofs() << " DoFs (Q" << degree << "), " << analysis_name;
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
      increments   = IncrementControl(nominal, newton.max_cuts);
      step_checked = false;
    }



    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      open_tables();
    }



    template <int dim>
    double
    Solver<dim>::propose_step(const double t)
    {
      if (analysis == Analysis::explicit_dynamics && !step_checked)
        {
          step_checked = true;
          const double nominal = increments.nominal();
          if (nominal > maximum_cfl * critical_step)
            {
              std::ostringstream m;
              m << "fem: the time step " << nominal << " s is above the critical step "
                << critical_step << " s = 2 / omega_max of central differences times "
                << "FEM/Maximum CFL number = " << maximum_cfl
                << ": the explicit scheme would be unstable. Use a time step <= "
                << maximum_cfl * critical_step << " s or 0 (automatic).";
              throw Run::StepFailure(m.str());
            }
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
              std::ostringstream m;
              m << "fem: Newton did not converge in the increment from t = " << t << " s to "
                << t + dt << " s after " << newton.max_cuts << " cuts (increment " << dt
                << " s = " << increments.nominal() << " s / 2^" << newton.max_cuts << ")";
              m << ": the structure may have reached its limit load (use displacement "
                   "control), or the increments or the tangent are poor (newton.csv has "
                   "the residuals)";
              if (!material_failure.empty())
                m << "; the last failure was in the material: " << material_failure;
              else
                m << "; the last residual was " << system_rhs.l2_norm() / force_level()
                  << " of the force level (tolerance "
                  << std::max(newton.tolerance, residual_floor()) << ")";
              m << ".";
              throw Run::StepFailure(m.str());
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
