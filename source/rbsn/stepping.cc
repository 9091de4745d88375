// The RBSN's stepping: set-up, the initial state, the implicit increments (Newton, cuts) and the commit.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/full_matrix.h>

#include "rbsn/model.h"
#include <hysteron/run/stepping_method.h>

#include "base/implicit_step.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::setup()
    {
      // A large network reports each stage (build_network(): nuclei and cells).
      build_network();
      StageReport stage(scene().console(), spacing.predicted_points > (dim == 2 ? 5e4 : 1e4));
      setup_springs();
      stage(StageReport::count(n_global_facets) + " facets' springs");
      setup_system();
      stage("sparsity pattern of " + StageReport::count(n_dofs * n_cells) + " DoFs");
      setup_conditions();
      check_supports();
      update_fragments();
      locate_probes();
      stage("supports, loads and probes");
      if (stage.enabled())
        {
          // The set-up's peak resident memory of the ranks (VmHWM), the least and the most.
          dealii::Utilities::System::MemoryStats memory;
          dealii::Utilities::System::get_memory_stats(memory);
          const MPI_Comm     comm = scene().mpi_communicator();
          const double       mb   = memory.VmHWM / 1024.0;
          std::ostringstream line;
          line << std::fixed << std::setprecision(0) << "rbsn: set-up peak memory per rank "
               << dealii::Utilities::MPI::min(mb, comm) << " ... " << dealii::Utilities::MPI::max(mb, comm) << " MB";
          scene().console() << line.str() << std::endl;
        }
      scene().console() << "rbsn: " << n_cells << " cells, " << n_global_facets << " facets (";
      if (spacing.is_constant())
        scene().console() << "d_m = " << d_m;
      else
        scene().console() << "d = " << spacing.min << " ... " << spacing.max;
      scene().console() << " m";
      if (n_blocks > 1)
        scene().console() << ", sampled in " << n_blocks << " blocks";
      scene().console() << "), " << n_dofs * n_cells << " DoFs" << std::endl;
      if ((analysis == Analysis::quasi_static || analysis == Analysis::implicit_dynamics) &&
          !consistent_tangent && scene().is_root())
        std::cerr << "hysteron: warning: RBSN: the springs' tangent is not the algorithmic one "
                     "(Bouc-Wen: Integrator = adaptive or forward euler), so Newton converges "
                     "linearly; Integrator = backward euler gives quadratic convergence"
                  << std::endl;
      const auto &time    = scene().time_control();
      double      nominal = time_step > 0 ? time_step : time.time_step;
      if (nominal == 0)
        nominal = time.end_time / n_increments;
      increments = increment_control(nominal, newton.max_cuts, time, analysis != Analysis::variable_order);
    }



    template <int dim>
    void
    Model<dim>::open_outputs()
    {
      open_tables();
    }



    template <int dim>
    void
    Model<dim>::initialize()
    {
      // The initial state: forces at t = 0, and the initial acceleration in dynamics.
      make_constraints(0, 0, false);
      u_trial = u;
      assemble(0, 0, false, true);
      f_ext_old    = f_ext;
      reaction_old = f_int;
      reaction_old -= f_ext;
      if (dynamic())
        initial_state();
    }



    template <int dim>
    void
    Model<dim>::initial_state()
    {
      // Velocities of the nuclei from the bodies' initial velocity (the cells
      // translate; prescribed DoFs move with their conditions), and M a0 = f_ext(0)
      // - f_int(0) - C v0 on the free DoFs.
      const auto        &bodies  = scene().body_descriptions();
      const unsigned int n_owned = u.locally_owned_size();
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const auto w = bodies[cell_body[c]].velocity_at(local_nuclei[c]);
          for (unsigned int d = 0; d < dim; ++d)
            v.local_element(n_dofs * c + d) = w[d];
        }
      // Prescribed DoFs start with the velocity of their condition (a displacement: the
      // mean velocity of the first step): with v = 0 under a moving condition the Newmark
      // recursion a1 = 4 (du - dt v0) / dt^2 - a0 on that DoF alternates with a growing
      // amplitude, and its inertia enters the reaction.
      const double first_step = increments.step(0, scene().time_control().end_time);
      for (unsigned int i = 0; i < n_owned; ++i)
        if (dof_set[i] >= 0)
          v.local_element(i) = prescribed_velocity(dirichlet[dof_set[i]], i, 0, first_step);
      v.update_ghost_values();
      make_constraints(0, 0, false);
      matrix_current = false; // the mass matrix alone
      if (trilinos_system())
        parallel_matrix = 0;
      else
        matrix = 0;
      rhs = 0;
      dealii::FullMatrix<double> M(n_dofs, n_dofs);
      dealii::Vector<double>     zero(n_dofs), vc(n_dofs), Mvc(n_dofs);
      std::vector<dof_index>     cd(n_dofs);
      Vector                     Mv(partitioner);
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          cell_mass_matrix(c, M);
          for (unsigned int k = 0; k < n_dofs; ++k)
            {
              cd[k] = global_dof(n_dofs * c + k);
              vc[k] = v.local_element(n_dofs * c + k);
            }
          M.vmult(Mvc, vc); // M v, cell by cell (M is block diagonal)
          for (unsigned int k = 0; k < n_dofs; ++k)
            Mv.local_element(n_dofs * c + k) = Mvc[k];
          add_local(M, zero, cd, true);
        }
      if (trilinos_system())
        parallel_matrix.compress(dealii::VectorOperation::add);
      rhs.compress(dealii::VectorOperation::add);
      // C v0 = a0 M v0 + a1 K0 v0 (the facets' part on the ghost cells goes to their owners).
      Vector force(partitioner);
      force = f_ext;
      force -= f_int;
      force.add(-dynamics.rayleigh_mass, Mv);
      if (dynamics.rayleigh_stiffness > 0)
        for (unsigned int e = 0; e < springs.size(); ++e)
          {
            const Springs<dim> &sp = springs[e];
            const auto          ld = facet_local_dofs(e);
            std::array<double, 2 * n_dofs> U;
            for (unsigned int k = 0; k < 2 * n_dofs; ++k)
              U[k] = v.local_element(ld[k]);
            for (unsigned int i = 0; i < n_dofs; ++i)
              {
                const double kv = sp.k[i] * sp.deformation(i, U);
                for (unsigned int k = 0; k < 2 * n_dofs; ++k)
                  force.local_element(ld[k]) -= dynamics.rayleigh_stiffness * sp.B[i][k] * kv;
              }
          }
      force.compress(dealii::VectorOperation::add);
      for (unsigned int i = 0; i < n_owned; ++i)
        if (!constraints.is_constrained(global_dof(i)))
          rhs.local_element(i) = force.local_element(i);
      solve_linear(a);
      constraints.distribute(a);
      // ... and its acceleration, g''(0) by a difference of the velocities.
      const double h = 1e-4 * scene().time_control().end_time;
      for (unsigned int i = 0; i < n_owned; ++i)
        if (dof_set[i] >= 0)
          a.local_element(i) = (prescribed_velocity(dirichlet[dof_set[i]], i, h, first_step) - v.local_element(i)) / h;
      a.update_ghost_values();
    }



    template <int dim>
    std::string
    Model<dim>::checkpoint_unsupported() const
    {
      if (analysis == Analysis::variable_order)
        return "Analysis = variable order keeps SUNDIALS IDA's multistep history, which a "
               "checkpoint cannot hold; Analysis = implicit dynamics (Newmark / HHT) can be "
               "checkpointed";
      return "";
    }



    template <int dim>
    double
    Model<dim>::propose_step(const double t)
    {
      const double end_time = scene().time_control().end_time;
      if (analysis == Analysis::variable_order)
        return end_time - t;
      return increments.step(t, end_time);
    }



    template <int dim>
    bool
    Model<dim>::advance(double &t, const double dt)
    {
      if (analysis == Analysis::variable_order)
        {
          // IDA chooses its steps; the driver's work follows each output time.
          t = integrate_variable_order(increments.nominal());
          return false;
        }
      // The facets broken since the converged state t in this attempt of the increment
      // are intact again when the increment is cut (a break decided at a load the shorter
      // step does not reach) and in the last good state a failing run writes; their rows
      // are written when the increment converges, and by a failing run (what broke in the
      // failed attempt).
      Breaks breaks;
      bool   converged = false;
      try
        {
          converged = solve_step(t, dt);
        }
      catch (const RuntimeError &error)
        {
          fail_at_t(breaks, std::string(error.what()) + " (step to t = " + std::to_string(t + dt) + " s).");
        }
      if (converged && fracture.enabled)
        converged = fracture_cycles(t, dt, breaks);
      if (!converged)
        {
          if (!increments.cut())
            {
              n_cuts = increments.cuts();
              std::vector<std::string> causes;
              if (breaks.n > 0)
                causes.push_back(std::to_string(breaks.n) +
                                 " facets broke in its last attempt, the network may have fallen apart");
              if (!solver_failure.empty())
                causes.push_back("the last attempt failed: " + solver_failure);
              else if (!spring_failure.empty())
                causes.push_back("the last failure was in a spring: " + spring_failure);
              else
                causes.push_back(residual_cause(rhs.l2_norm() / force_level(),
                                                std::max(newton.tolerance, residual_floor(u.size()))));
              fail_at_t(breaks, increment_failure("rbsn", t, dt, increments, causes));
            }
          undo_breaks(breaks);
          breaks.rows.clear();
          return false;
        }
      commit(dt, breaks.n > 0);
      write_breaks(breaks);
      increments.accept(t, dt);
      n_cuts = increments.cuts();
      return true;
    }



    template <int dim>
    bool
    Model<dim>::solve_step(const double t, const double dt)
    {
      // A singular tangent (a plastic mechanism, a = 0) fails the attempt like a Newton
      // failure: a shorter increment may pass it; the run's message gives the reason.
      const auto attempt = [&]() {
        try
          {
            return newton_step(t, dt);
          }
        catch (const RuntimeError &error)
          {
            spring_failure.clear();
            solver_failure = error.what();
            return false;
          }
      };
      solver_failure.clear();
      if (const bool converged = attempt(); converged || reuse_tolerance == 0)
        return converged;
      // Modified Newton failed (stale factors can overshoot where springs unload): the
      // step again with a fresh factorization in every iteration.
      const double tolerance = reuse_tolerance;
      reuse_tolerance        = 0;
      factorized             = false;
      solver_failure.clear();
      const bool converged = attempt();
      reuse_tolerance      = tolerance;
      ++n_exact_retries;
      return converged;
    }



    template <int dim>
    bool
    Model<dim>::newton_step(const double t, const double dt)
    {
      const double t1 = t + dt;
      spring_failure.clear();
      // The predictor and Newton's iterations: base/implicit_step.h.
      ImplicitIncrement<Vector> step;
      step.newton = {[&](const bool matrix) {
                       // The line search moved the owned entries.
                       u_trial.update_ghost_values();
                       return assemble(t1, dt, matrix, true);
                     },
                     [&]() { return rhs.l2_norm(); },
                     [&]() { return force_level(); },
                     [&](Vector &x) {
                       solve_linear(x);
                       constraints.distribute(x);
                     },
                     [&](const unsigned int iteration, const double residual, const double alpha) {
                       if (newton_table)
                         newton_table->add_row(newton_row(t1, dt, iteration, residual, force_level(), alpha));
                     }};
      step.constrain          = [&](const bool predictor) { make_constraints(t, t1, predictor); };
      step.evaluate_predictor = [&]() {
        previous_residual = std::numeric_limits<double>::infinity(); // a new step's predictor
        // (Bouc-Wen springs keep the tangents of their last evaluation.)
        return assemble(t1, dt, true, analysis == Analysis::linear_static);
      };
      // The round-off the iterate carries, eps |K| |u| (a free flight: base/newton.h).
      step.floor = [&]() {
        return std::max(residual_floor(u.size()),
                        iterate_floor(u.size(),
                                      trilinos_system() ? parallel_matrix.linfty_norm() : matrix.linfty_norm(),
                                      u_trial.linfty_norm(),
                                      force_level()));
      };
      const bool converged = implicit_increment(u, u_trial, Vector(partitioner), step, newton, predictor_level, n_newton);
      u_trial.update_ghost_values();
      return converged;
    }



    template <int dim>
    void
    Model<dim>::commit(const double dt, const bool broke)
    {
      const MPI_Comm comm = network_communicator();
      // A damped step's work of C v needs its deformation increments and v0.
      const bool          damped_step = damped() && analysis == Analysis::implicit_dynamics && dt > 0;
      std::vector<double> d_delta;
      Vector              v0;
      if (damped_step)
        {
          d_delta = deformation_increments();
          v0.reinit(partitioner);
          v0 = v;
          v0.update_ghost_values();
        }
      double work = 0; // of the intact springs in the step (trapezoidal rule)
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          Springs<dim> &sp = springs[e];
          if (sp.broken)
            continue;
          for (unsigned int i = 0; i < n_dofs; ++i)
            work += 0.5 * (sp.force[i] + sp.trial_force[i]) * (sp.trial_delta[i] - sp.delta[i]);
          sp.delta = sp.trial_delta;
          sp.force = sp.trial_force;
          sp.state = sp.trial_state;
        }
      work = dealii::Utilities::MPI::sum(work, comm);
      Vector increment(partitioner);
      increment = u_trial;
      increment -= u;
      if (analysis == Analysis::implicit_dynamics && dt > 0)
        {
          dynamics.update(increment, dt, v, a);
        }
      else if (dt > 0)
        {
          v = increment;
          v /= dt;
        }
      v.update_ghost_values();
      a.update_ghost_values();
      if (damped_step)
        damping_work += dealii::Utilities::MPI::sum(step_damping_work(v0, d_delta), comm);
      double       external = 0, boundary = 0;
      const unsigned int n_owned = u.locally_owned_size();
      for (unsigned int i = 0; i < n_owned; ++i)
        external += 0.5 * (f_ext_old.local_element(i) + f_ext.local_element(i)) * increment.local_element(i);
      Vector reaction(partitioner);
      reaction = f_int;
      reaction += inertia;
      reaction -= f_ext;
      for (unsigned int i = 0; i < n_owned; ++i)
        if (dof_set[i] >= 0)
          boundary += 0.5 * (reaction_old.local_element(i) + reaction.local_element(i)) * increment.local_element(i);
      external = dealii::Utilities::MPI::sum(external, comm);
      boundary = dealii::Utilities::MPI::sum(boundary, comm);
      external_work += external;
      boundary_work += boundary;
      // A brittle break in a static step has no quasi-static path: the intact springs
      // unload at once and the energy they give back, with the broken springs' own, is
      // spent in the fracture. Its measure is what the step's loads and supports did
      // beyond the springs' work; the internal work takes it, so that the dissipation
      // (internal work - strain energy) includes the fracture energy.
      if (broke && !dynamic())
        {
          fracture_energy += external + boundary - work;
          work = external + boundary;
        }
      internal_work += work;
      reaction_old = reaction;
      f_ext_old    = f_ext;
      force_scale  = std::max(force_scale, last_force_level);
      u            = u_trial;
    }



    template <int dim>
    std::vector<double>
    Model<dim>::deformation_increments() const
    {
      std::vector<double> d(n_dofs * springs.size(), 0.0);
      for (unsigned int e = 0; e < springs.size(); ++e)
        if (!springs[e].broken)
          for (unsigned int i = 0; i < n_dofs; ++i)
            d[n_dofs * e + i] = springs[e].trial_delta[i] - springs[e].delta[i];
      return d;
    }



    template <int dim>
    double
    Model<dim>::step_damping_work(const Vector &v0, const std::vector<double> &d_delta) const
    {
      // 1/2 du^T C (v0 + v1) with C = a0 M + a1 K0: the cells' a0 du_c^T M_c (v0 + v1)_c and
      // the intact facets' a1 k_i (B_i du) (B_i (v0 + v1)) (B du = the springs' increments).
      // With Newmark's average acceleration the energy balance then closes exactly.
      const double               a0 = dynamics.rayleigh_mass, a1 = dynamics.rayleigh_stiffness;
      double                     work = 0;
      dealii::FullMatrix<double> M(n_dofs, n_dofs);
      for (unsigned int c = 0; c < n_owned_cells && a0 > 0; ++c)
        {
          cell_mass_matrix(c, M);
          for (unsigned int p = 0; p < n_dofs; ++p)
            for (unsigned int q = 0; q < n_dofs; ++q)
              {
                const unsigned int ip = n_dofs * c + p, iq = n_dofs * c + q;
                work += 0.5 * a0 * (u_trial.local_element(ip) - u.local_element(ip)) * M(p, q) *
                        (v0.local_element(iq) + v.local_element(iq));
              }
        }
      std::array<double, 2 * n_dofs> W;
      for (unsigned int e = 0; e < springs.size() && a1 > 0; ++e)
        if (!springs[e].broken)
          {
            const auto ld = facet_local_dofs(e);
            for (unsigned int k = 0; k < 2 * n_dofs; ++k)
              W[k] = v0.local_element(ld[k]) + v.local_element(ld[k]);
            for (unsigned int i = 0; i < n_dofs; ++i)
              work += 0.5 * a1 * springs[e].k[i] * d_delta[n_dofs * e + i] * springs[e].deformation(i, W);
          }
      return work;
    }



    template <int dim>
    void
    Model<dim>::finish(const double)
    {
      if (spring_table)
        write_spring_table();
      if (cell_table)
        write_cell_table();
      // The load-displacement curves of the history sets (rank 0; a warning, never an error).
      tables.flush();
      for (const auto &warning : tables.draw_histories())
        std::cerr << "hysteron: warning: " << warning << std::endl;
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
