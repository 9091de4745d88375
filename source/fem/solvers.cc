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
    template <int dim>
    unsigned int
    Solver<dim>::solve_linear(Vector &du)
    {
      using namespace dealii;
      TimerOutput::Scope timing(this->get_scene().timer(), "FEM linear solve");
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
      VectorNewtonProblem<Vector> problem(
        u_trial,
        du,
        {[&](const bool matrix) {
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
         }});
      const unsigned int iterations = newton_iterate(problem, newton, residual_floor());
      n_newton += iterations > 0 ? iterations : newton.max_iterations;
      return iterations > 0;
    }



    template unsigned int Solver<2>::solve_linear(Vector &);
    template unsigned int Solver<3>::solve_linear(Vector &);
    template bool Solver<2>::implicit_step(const double, const double);
    template bool Solver<3>::implicit_step(const double, const double);
  } // namespace FEM
} // namespace hysteron
