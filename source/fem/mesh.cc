// The FEM mesh of the scene's bodies, the DoFs and vectors, and the quadrature-point history.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
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

#include <hysteron/base/memory.h>
#include <hysteron/base/newton.h>
#include <hysteron/base/parameters.h>
#include "fem/fem.h"
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
      /// Coarse meshes of structured meshes stay below this many cells: p4est and deal.II
      /// keep every coarse cell on every rank (a few MB).
      constexpr double max_coarse_cells = 4096;

      /// Structured meshes may round their counts up to coarsen if that adds at most 20 %
      /// of cells; else they are made whole on rank 0 and distributed.
      constexpr double max_growth = 1.2;

      /// Bytes per cell of rank 0's serial triangulation (refined, partitioned, described)
      /// while it makes the meshes of parallel::fullydistributed (measured, rounded up).
      constexpr double serial_bytes_per_cell[2] = {1.5e3, 4e3};
    } // namespace



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
      cell_group.clear();
      physical_names.clear();

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
      // Quadrilaterals and hexahedra of a structured mesh: a small coarse mesh on every rank
      // (p4est) and global refinements. Everything else is made whole on rank 0, which keeps
      // only its part of it (parallel::fullydistributed).
      bool made = false;
      if (kind == "structured" && !generate_simplices)
        {
          made = make_structured_mesh(shapes);
          if (!made)
            scene.console() << "fem: the structured mesh has no coarse mesh of at most " << max_coarse_cells
                            << " cells (odd cell counts, or bodies that are not rectangles/boxes): "
                               "rank 0 makes it whole and distributes it"
                            << std::endl;
        }
      if (!made)
        make_distributed_mesh(shapes, kind);
      set_mesh_box();
    }



    template <int dim>
    Geometry::CoarseMesh<dim>
    Solver<dim>::generated_mesh(const std::vector<const Geometry::Region<dim> *> &shapes,
                                const std::string                                &kind) const
    {
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
        check_staircase(shapes, mesh.volume());
      return mesh;
    }



    template <int dim>
    void
    Solver<dim>::check_staircase(const std::vector<const Geometry::Region<dim> *> &shapes,
                                 const double                                      volume) const
    {
      // A staircase approximation of a curved or oblique body is refused.
      double body_volume = 0;
      for (const auto *shape : shapes)
        body_volume += shape->volume_estimate();
      const double mismatch = std::abs(volume - body_volume) / body_volume;
      require(mismatch < 2e-3,
              "FEM/Mesh/Generator",
              "the structured mesh misses " + std::to_string(100 * mismatch) +
                " % of the bodies' volume (a body is not made of rectangles/boxes): "
                "use Generator = unstructured (2D) or a Gmsh file");
    }



    template <int dim>
    bool
    Solver<dim>::make_structured_mesh(const std::vector<const Geometry::Region<dim> *> &shapes)
    {
      auto structured = Geometry::coarse_structured_mesh<dim>(shapes, cell_size, "FEM/Mesh/Cell size",
                                                              max_coarse_cells, max_growth);
      if (structured.coarse.cells.empty())
        return false;
      check_staircase(shapes, structured.coarse.volume());
      auto &mesh = structured.coarse;
      AssertThrow(Geometry::check_cells(mesh.vertices, mesh.cells).valid, dealii::ExcInternalError());
      if (!structured.note.empty())
        this->get_scene().console() << "fem: " << structured.note << std::endl;
      simplex = false;
      check_memory(mesh.cells.size(), structured.levels, false);
      triangulation = std::make_unique<dealii::parallel::distributed::Triangulation<dim>>(
        this->get_scene().mpi_communicator());
      triangulation->create_triangulation(mesh.vertices, mesh.cells, dealii::SubCellData());
      triangulation->refine_global(structured.levels + refinements);
      return true;
    }



    template <int dim>
    void
    Solver<dim>::check_memory(const double coarse_cells, const unsigned int levels, const bool serial) const
    {
      // Each refinement multiplies the cells by 2^dim: refuse a mesh that cannot fit in the
      // ranks' memory before making it (it would end in std::bad_alloc after minutes). Each
      // rank holds its share of the cells with their ghosts (Memory::largest_share), and
      // rank 0, while it makes a whole mesh (serial), the serial triangulation too. A cell
      // brings dim degree^dim DoFs (a node per cell of a large Q mesh; a simplex mesh has
      // about 1/2 (2D) and 1/5 (3D) of that). The resident bytes per DoF (matrix rows,
      // vectors, history and tangents at the quadrature points, the ML hierarchy) are the
      // slopes of the peak RSS of one increment solved by CG + ML on unit squares and cubes,
      // rounded up: 2D 2.2 kB (Q1, 3.3e4 ... 1.3e5 DoFs), 1.8 kB (Q2); 3D 4.9 kB (Q1,
      // 1.5e4 ... 2.8e4 DoFs), 7.0 kB (Q2), measured by
      //   benchmarks/memory_estimate.py --hysteron build/hysteron --only fem
      // (each run /usr/bin/time -v hysteron scene.prm).
      constexpr double   bytes_per_dof[2] = {2.2e3, 7e3};
      const MPI_Comm     comm               = this->get_scene().mpi_communicator();
      const unsigned int n_ranks            = dealii::Utilities::MPI::n_mpi_processes(comm);
      const double       given = coarse_cells * std::pow(2.0, dim * static_cast<double>(levels));
      const double       cells = given * std::pow(2.0, dim * static_cast<double>(refinements));
      const double       per_cell =
        dim * std::pow(degree, dim) / (simplex ? (dim == 2 ? 2.0 : 5.0) : 1.0) * bytes_per_dof[dim - 2];
      const double       on_root  = serial ? cells * serial_bytes_per_cell[dim - 2] : 0.0;
      const bool         root     = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
      std::ostringstream m;
      m.precision(3);
      if (refinements > 0)
        m << "refining the mesh of " << Memory::count(given) << " cells " << refinements << " times gives "
          << Memory::count(cells) << " cells";
      else
        m << "the mesh has " << Memory::count(cells) << " cells";
      m << " (" << per_cell << " B each with " << (simplex ? "P" : "Q") << degree << ")";
      if (serial)
        m << ", and " << serial_bytes_per_cell[dim - 2] << " B each on rank 0 while it makes the whole mesh";
      Memory::require_fits(comm, Memory::largest_share(cells, n_ranks, dim) * per_cell + (root ? on_root : 0.0),
                           refinements > 0       ? "FEM/Mesh/Refinements" :
                           generator == "file" ? "FEM/Mesh/Mesh file" :
                                                 "FEM/Mesh/Cell size",
                           m.str(),
                           "use fewer refinements, a coarser FEM/Mesh/Cell size or more machines");
    }



    template <int dim>
    void
    Solver<dim>::set_mesh_box()
    {
      const Scene<dim> &scene = this->get_scene();
      // The bounding box of the mesh (faces of boundary conditions) and its scale.
      dealii::Point<dim> lo, hi;
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::numeric_limits<double>::max();
          hi[d] = -std::numeric_limits<double>::max();
        }
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int d = 0; d < dim; ++d)
              {
                lo[d] = std::min(lo[d], cell->vertex(v)[d]);
                hi[d] = std::max(hi[d], cell->vertex(v)[d]);
              }
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = dealii::Utilities::MPI::min(lo[d], scene.mpi_communicator());
          hi[d] = dealii::Utilities::MPI::max(hi[d], scene.mpi_communicator());
        }
      mesh_box = dealii::BoundingBox<dim>(std::make_pair(lo, hi));
      if (scene.axisymmetric())
        {
          // x is the radius: no node at r < 0, and nodes on the axis need u_r = 0 (else
          // the hoop strain u_r / r is unbounded next to them).
          const double tol = 1e-9 * lo.distance(hi);
          require(lo[0] >= -tol,
                  "Method fem",
                  "the mesh reaches x = " + std::to_string(lo[0]) +
                    ", but x is the radius r >= 0 in an axisymmetric scene");
          if (lo[0] <= tol)
            {
              dealii::Point<dim> on_axis = lo;
              on_axis[1]                 = 0.5 * (lo[1] + hi[1]);
              bool held                  = false;
              // A physical group's nodes are known after the DoFs: trust a group that prescribes u_r.
              for (const auto &b : scene.boundary_descriptions())
                held = held || b.prescribes(on_axis, 0, lo, hi, tol) ||
                       (!b.physical_group.empty() &&
                        (b.type == BoundaryDescription<dim>::Type::fixed || b.components[0]));
              require(held,
                      "Boundary names",
                      "the axisymmetric mesh reaches the axis x = 0 but no boundary condition "
                      "holds the radial displacement there: add a Boundary with Type = roller "
                      "and Faces = x- (u_r = 0 on the axis)");
            }
        }
      u_scale = 0;
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
      if (simplex)
        {
          // Gauss rules on the simplex exact to degree 2 p + 1 (the mass matrix of P_p).
          fe              = std::make_unique<FESystem<dim>>(FE_SimplexP<dim>(degree), dim);
          quadrature      = std::make_unique<QGaussSimplex<dim>>(degree + 1);
          face_quadrature = std::make_unique<QGaussSimplex<dim - 1>>(degree + 1);
          mapping         = std::make_unique<MappingFE<dim>>(FE_SimplexP<dim>(1));
        }
      else
        {
          fe              = std::make_unique<FESystem<dim>>(FE_Q<dim>(degree), dim);
          quadrature      = std::make_unique<QGauss<dim>>(degree + 1);
          face_quadrature = std::make_unique<QGauss<dim - 1>>(degree + 1);
          mapping         = std::make_unique<MappingQ<dim>>(1);
        }
      dof_handler.reinit(*triangulation);
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
          symmetric_tangent = symmetric_tangent && body_material[m]->has_symmetric_tangent();
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
          direct_solver.reset(); // a new pattern: a new analysis
          system_rhs.reinit(owned_dofs, comm);
        }
    }



    template <int dim>
    void
    Solver<dim>::setup_history()
    {
      const auto &bodies = this->get_scene().body_descriptions();
      const unsigned int n_q = quadrature->size();
      dealii::FEValues<dim> fv(*mapping, *fe, *quadrature,
                               dealii::update_quadrature_points | dealii::update_JxW_values);
      history.initialize(triangulation->begin_active(), triangulation->end(), 1);
      // Raw pointers by active cell index: get_data() returns a vector of shared
      // pointers (an allocation per call), too slow for the assembly loops.
      cell_history.assign(triangulation->n_active_cells(), nullptr);
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            cell_history[cell->active_cell_index()] = history.get_data(cell)[0].get();
            auto &h     = *cell_history[cell->active_cell_index()];
            const unsigned int m = cell->material_id();
            h.material  = body_material[m];
            h.body      = mesh_to_body[m];
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
                h.point[q]  = fv.quadrature_point(q);
                h.weight[q] = fv.JxW(q) * this->get_scene().thickness_at(bodies[h.body], h.point[q]);
              }
            h.volume       = h.weight;
            h.trial_volume = h.weight;
            // Until a first evaluation: the elastic tangent (the first predictor).
            h.tangent.assign(n_q, h.material->elasticity().template stiffness<dim>());
            if (this->get_scene().axisymmetric())
              {
                // Hooke's law with eps_tt the third normal strain.
                const auto                &el = h.material->elasticity();
                Material::HoopTangent<dim> elastic;
                elastic.stress_by_hoop = el.lame_lambda() * dealii::unit_symmetric_tensor<dim>();
                elastic.hoop_by_strain = elastic.stress_by_hoop;
                elastic.hoop_by_hoop   = el.lame_lambda() + 2.0 * el.shear_modulus();
                h.hoop_tangent.assign(n_q, elastic);
                h.hoop_increment.assign(n_q, 0.0);
              }
          }
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron
