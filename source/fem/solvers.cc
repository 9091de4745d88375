// The FEM's linear solvers and the implicit (quasi-static, Newmark/HHT) step with Newton.
#include <deal.II/base/timer.h>
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
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_solver.h>

#include <hysteron/base/newton.h>
#include <hysteron/base/parameters.h>
#include "fem/fem.h"
#include <hysteron/geometry/mesh.h>

#include "base/implicit_step.h"

#include <Epetra_Map.h>
#include <Epetra_MultiVector.h>
#include <Teuchos_ParameterList.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>
namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    unsigned int
    Solver<dim>::solve_linear(Vector &du)
    {
      using namespace dealii;
      TimerOutput::Scope timing(this->get_scene().timer(), "FEM linear solve");
      const double rhs_norm = system_rhs.l2_norm();
      if (solver_type == LinearSolver::direct)
        {
          // The pattern is that of the whole run: its analysis is done once.
          if (!direct_solver)
            direct_solver = std::make_unique<KeptDirectSolver>(direct_package);
          direct_solver->solve(system_matrix, du, system_rhs);
          return 0;
        }
      const bool reused = amg != nullptr && reuse_preconditioner;
      if (!reused)
        setup_amg();
      // A solve with a kept hierarchy that fails or slows down sets it up again and
      // repeats (the first solve after a set-up is the reference).
      const auto attempt = [&](const double tolerance) {
        SolverControl control(solver_max_iterations, tolerance);
        if (solver_type == LinearSolver::cg)
          SolverCG<Vector>(control).solve(system_matrix, du, system_rhs, *amg);
        else
          // Right preconditioning: the convergence test sees the true residual.
          SolverGMRES<Vector>(control, SolverGMRES<Vector>::AdditionalData(100, true))
            .solve(system_matrix, du, system_rhs, *amg);
        return control.last_step();
      };
      const double tolerance = std::max(1e-300, solver_tolerance * rhs_norm);
      const Vector start     = du;
      unsigned int iterations = 0;
      try
        {
          try
            {
              iterations = attempt(tolerance);
            }
          catch (const SolverControl::NoConvergence &)
            {
              if (!reused)
                throw;
              iterations = solver_max_iterations;
            }
          if (!reused)
            amg_reference_iterations = iterations;
          else if (iterations > 2 * amg_reference_iterations + 10)
            {
              setup_amg();
              du                       = start;
              iterations              += attempt(tolerance);
              amg_reference_iterations = iterations;
            }
        }
      catch (const SolverControl::NoConvergence &e)
        {
          std::ostringstream m;
          m << "fem: the " << solver_name << " linear solver did not converge in " << e.last_step
            << " iterations (residual " << e.last_residual << ", target " << tolerance
            << "); raise FEM/Linear solver/Maximum iterations or use Type = direct";
          throw RuntimeError(m.str());
        }
      return iterations;
    }



    template <int dim>
    void
    Solver<dim>::setup_amg()
    {
      // ML smoothed aggregation on the null space of elasticity: per owned row (DoF of
      // component c at support point x) the translations e_c and the rotations omega x
      // (x - x_0) about the mesh's centre, scaled by its size (1 in 2D, 3 in 3D).
      using namespace dealii;
      TrilinosWrappers::PreconditionAMG::AdditionalData data;
      data.elliptic              = true;
      data.higher_order_elements = degree > 1;
      data.smoother_sweeps       = 2;
      data.aggregation_threshold = 0.02;
      Teuchos::ParameterList              list;
      std::unique_ptr<Epetra_MultiVector> constant_modes;
      data.set_parameters(list, constant_modes, system_matrix);
      const Epetra_Map  &map      = system_matrix.trilinos_matrix().RowMap();
      const int          n_local  = map.NumMyElements();
      const unsigned int n_modes  = dim == 2 ? 3 : 6;
      const Point<dim>   centre   = mesh_box.center();
      amg_null_space.assign(n_modes * n_local, 0.0);
      for (int i = 0; i < n_local; ++i)
        {
          const auto         g = TrilinosWrappers::global_index(map, i);
          const unsigned int k = owned_dofs.index_within_set(g);
          const unsigned int c = owned_component[k];
          const Tensor<1, dim> r = (owned_support[k] - centre) / u_scale;
          amg_null_space[c * n_local + i] = 1.0;
          if constexpr (dim == 2)
            amg_null_space[2 * n_local + i] = c == 0 ? -r[1] : r[0];
          else
            {
              // Rotations about x, y, z: e_a x r has component c equal to eps_{c a b} r_b.
              for (unsigned int a = 0; a < 3; ++a)
                {
                  const unsigned int b = 3 - a - c;
                  const double       value =
                    a == c ? 0.0 : ((a - c + 3) % 3 == 1 ? r[b] : -r[b]);
                  amg_null_space[(3 + a) * n_local + i] = value;
                }
            }
        }
      list.set("PDE equations", dim);
      list.set("null space: type", "pre-computed");
      list.set("null space: dimension", static_cast<int>(n_modes));
      list.set("null space: vectors", amg_null_space.data());
      amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
      amg->initialize(system_matrix.trilinos_matrix(), list);
      ++n_amg_setups;
    }






    template <int dim>
    bool
    Solver<dim>::implicit_step(const double t, const double dt)
    {
      MPI_Comm     comm = this->get_scene().mpi_communicator();
      const double t1   = t + dt;
      current_dt        = dt;
      material_failure.clear();
      Vector ghost(owned_dofs, relevant_dofs, comm);
      // The predictor and Newton's iterations: base/implicit_step.h.
      ImplicitIncrement<Vector> step;
      step.newton = {[&](const bool matrix) {
                       ghost = u_trial;
                       return assemble(ghost, t1, dt, matrix ? Assemble::residual_and_matrix : Assemble::forces);
                     },
                     [&]() { return system_rhs.l2_norm(); },
                     [&]() { return force_level(); },
                     [&](Vector &correction) {
                       correction = 0;
                       n_linear += solve_linear(correction);
                       constraints.distribute(correction);
                     },
                     [&](const unsigned int iteration, const double residual, const double alpha) {
                       log_newton(t1, dt, iteration, residual, alpha);
                     }};
      step.constrain          = [&](const bool predictor) { make_constraints(t1, predictor); };
      step.evaluate_predictor = [&]() {
        ghost = u_trial;
        return assemble(ghost, t1, dt, Assemble::residual_and_matrix, false);
      };
      // The round-off of the residual that the iterate carries (base/newton.h): eps |K| |u|
      // (a free flight: rigid motion, no force). Updated Lagrangian: the strains are
      // differences of gradients of the full motion x = X + u, eps |K| (u_scale + |u|).
      step.floor = [&]() {
        return std::max(residual_floor(),
                        iterate_floor(dof_handler.n_dofs(),
                                      system_matrix.linfty_norm(),
                                      (finite_strain ? u_scale : 0.0) + u_trial.linfty_norm(),
                                      force_level()));
      };
      return implicit_increment(u, u_trial, Vector(owned_dofs, comm), step, newton, predictor_level, n_newton);
    }



    template void Solver<2>::setup_amg();
    template void Solver<3>::setup_amg();
    template unsigned int Solver<2>::solve_linear(Vector &);
    template unsigned int Solver<3>::solve_linear(Vector &);
    template bool Solver<2>::implicit_step(const double, const double);
    template bool Solver<3>::implicit_step(const double, const double);
  } // namespace FEM
} // namespace hysteron
