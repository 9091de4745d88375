#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/full_matrix.h>

#include <hysteron/rbsn/model.h>
#include <hysteron/run/stepping_method.h>

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
    /*
     * The equations. For facet e between cells a and b with U_e = (U_a, U_b) the two
     * cells' DoFs (2D: u, v, theta; 3D: u, theta, three each), the springs' deformations
     * are delta = B U_e (2D: delta_n, delta_t, theta_b - theta_a; 3D: the normal and two
     * shear displacements and the two bending and the torsion rotations in the facet's
     * axes) and their forces F(delta) (linear, or the spring law from the converged
     * state, e.g. the uniaxial Bouc-Wen law, eq. 3.32, or the coupled law, eq. 3.38-3.42);
     *   f_int = sum_e B^T F,   K = sum_e B^T D_t B,   D_t = dF / d delta   (eq. 3.10, 3.31),
     * with only the diagonal of D_t for linear springs and laws of independent springs.
     * Quasi-static: r = f_int(u) - f_ext(t). Dynamics (HHT-alpha, Newmark for
     * alpha = 0, as the FEM): with the cell mass matrices M_c of eq. 3.12 and
     * C = a0 M + a1 K0 (K0: the elastic springs),
     *   r = M a1 + (1 + alpha)(C v1 + f_int(u1) - f_ext(t1)) - alpha (C v0 + f_int(u0) - f_ext(t0)).
     * Each rank assembles its own facets and cells; the contributions to the rows of its
     * ghost cells go to their owners.
     */
    template <int dim>
    bool
    Model<dim>::assemble(const double t1, const double dt, const bool with_matrix, const bool update_springs)
    {
      constexpr unsigned int n_e     = 2 * n_dofs; // a facet's DoFs
      const bool             dynamic = analysis == Analysis::implicit_dynamics && dt > 0;
      const double alpha = dynamics.hht_alpha, beta = dynamics.beta(), gamma = dynamics.gamma();
      // The matrix is updated rather than rebuilt if it holds the facets' tangents for the
      // current constrained DoFs and (dynamics) the same step.
      const double key         = dynamic ? dt : 0.0;
      const bool   incremental = with_matrix && incremental_assembly && matrix_current && matrix_dt == key &&
                               incremental_updates < max_incremental_updates;
      if (with_matrix)
        {
          ++n_matrix_assemblies;
          if (incremental)
            ++incremental_updates;
          else
            {
              ++n_full_assemblies;
              incremental_updates = 0;
              if (trilinos_system())
                parallel_matrix = 0;
              else
                matrix = 0;
              assembled_tangent.resize(springs.size());
              facet_in_matrix.assign(springs.size(), false);
            }
          matrix_current = true;
          matrix_dt      = key;
        }
      rhs     = 0;
      f_int   = 0;
      inertia = 0;
      external_forces(t1, f_ext);

      dealii::FullMatrix<double>   K(n_e, n_e), K0(n_e, n_e);
      dealii::Vector<double>       r(n_e), fe(n_e), fe0(n_e), ue(n_e), ve0(n_e), ve1(n_e), tmp(n_e);
      std::vector<dof_index>       dofs(n_e);
      bool                         failed = false;
      std::string                  message;
      const bool                   diagonal_law = spring_law->diagonal_tangent();
      // K0 = B^T diag(k) B: the elastic springs (stiffness-proportional damping).
      const auto elastic_matrix = [](const Springs<dim> &sp, dealii::FullMatrix<double> &M) {
        for (unsigned int p = 0; p < n_e; ++p)
          for (unsigned int q = 0; q < n_e; ++q)
            {
              M(p, q) = 0;
              for (unsigned int i = 0; i < n_dofs; ++i)
                M(p, q) += sp.B[i][p] * sp.k[i] * sp.B[i][q];
            }
      };
      // The springs' matrix for the tangent D: B^T D B (the diagonal of D only, for linear
      // springs and laws of independent springs; else the full, not necessarily symmetric
      // D), in dynamics times 1 + alpha. Linear in D.
      // As B^T (D B): n_s n_e (n_s + n_e) products instead of n_e^2 n_s^2.
      double     DB[n_dofs][n_e];
      const auto spring_matrix = [&](const Springs<dim> &sp, const SpringMatrix &D, dealii::FullMatrix<double> &M) {
        const bool diagonal = diagonal_law || !sp.hysteretic;
        for (unsigned int i = 0; i < n_dofs; ++i)
          for (unsigned int q = 0; q < n_e; ++q)
            if (diagonal)
              DB[i][q] = D[i][i] * sp.B[i][q];
            else
              {
                DB[i][q] = 0;
                for (unsigned int j = 0; j < n_dofs; ++j)
                  DB[i][q] += D[i][j] * sp.B[j][q];
              }
        for (unsigned int p = 0; p < n_e; ++p)
          for (unsigned int q = 0; q < n_e; ++q)
            {
              M(p, q) = 0;
              for (unsigned int i = 0; i < n_dofs; ++i)
                M(p, q) += sp.B[i][p] * DB[i][q];
            }
        if (dynamic)
          M *= 1 + alpha;
      };
      // The facet's matrix: the springs' and, in dynamics, the damping (1 + alpha) gamma /
      // (beta dt) a1 K0.
      const auto facet_matrix = [&](const Springs<dim> &sp, const SpringMatrix &D, dealii::FullMatrix<double> &M) {
        spring_matrix(sp, D, M);
        if (dynamic && dynamics.rayleigh_stiffness > 0)
          {
            elastic_matrix(sp, K0);
            M.add((1 + alpha) * gamma / (beta * dt) * dynamics.rayleigh_stiffness, K0);
          }
      };
      const auto any_constrained = [&](const std::vector<dof_index> &indices) {
        return std::any_of(indices.begin(), indices.end(), [&](const auto i) { return constraints.is_constrained(i); });
      };
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          Springs<dim>     &sp = springs[e];
          const Facet<dim> &f  = network.facets[e];
          facet_dofs(e, dofs);
          const auto ld = facet_local_dofs(e);
          if (sp.broken)
            {
              // Broken since the matrix was assembled: its springs are taken out of it.
              if (incremental && facet_in_matrix[e])
                {
                  facet_matrix(sp, assembled_tangent[e], K);
                  K *= -1.0;
                  add_local_change(K, dofs);
                  facet_in_matrix[e] = false;
                  ++n_facet_updates;
                }
              continue;
            }
          for (unsigned int k = 0; k < n_e; ++k)
            ue[k] = u_trial.local_element(ld[k]);
          SpringVector increment;
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              sp.trial_delta[i] = sp.deformation(i, ue);
              increment[i]      = sp.trial_delta[i] - sp.delta[i];
              if (!update_springs || sp.hysteretic)
                sp.trial_force[i] = sp.force[i];
              else
                {
                  sp.trial_force[i] = sp.k[i] * sp.trial_delta[i];
                  sp.tangent[i][i]  = sp.k[i];
                }
            }
          if (update_springs && sp.hysteretic)
            {
              // The spring law from the converged forces and state: one call per facet.
              std::copy(sp.state.begin(), sp.state.end(), sp.trial_state.begin());
              try
                {
                  spring_law->update(e, increment, sp.trial_force, sp.trial_state.data(),
                                     with_matrix ? &sp.tangent : nullptr);
                }
              catch (const SpringFailure &error)
                {
                  failed = true;
                  std::ostringstream m;
                  m << error.what() << " (" << error.springs << " of the facet at " << f.midpoint
                    << ", step to t = " << t1 << " s)";
                  message = m.str();
                }
            }
          if (failed)
            continue;
          for (unsigned int k = 0; k < n_e; ++k)
            {
              fe[k] = 0;
              for (unsigned int i = 0; i < n_dofs; ++i)
                fe[k] += sp.B[i][k] * sp.trial_force[i];
            }
          r = fe;
          if (dynamic)
            {
              // HHT weights of the springs, and the stiffness-proportional damping a1 K0 v.
              for (unsigned int k = 0; k < n_e; ++k)
                {
                  fe0[k] = 0;
                  for (unsigned int i = 0; i < n_dofs; ++i)
                    fe0[k] += sp.B[i][k] * sp.force[i];
                }
              r *= 1 + alpha;
              r.add(-alpha, fe0);
              if (dynamics.rayleigh_stiffness > 0)
                {
                  elastic_matrix(sp, K0);
                  for (unsigned int k = 0; k < n_e; ++k)
                    {
                      ve0[k]          = v.local_element(ld[k]);
                      const double a0 = a.local_element(ld[k]);
                      const double a1 = (ue[k] - u.local_element(ld[k]) - dt * ve0[k]) / (beta * dt * dt) -
                                        (1 - 2 * beta) / (2 * beta) * a0;
                      ve1[k] = ve0[k] + dt * ((1 - gamma) * a0 + gamma * a1);
                    }
                  K0.vmult(tmp, ve1);
                  r.add((1 + alpha) * dynamics.rayleigh_stiffness, tmp);
                  for (unsigned int k = 0; k < n_e; ++k)
                    inertia.local_element(ld[k]) += dynamics.rayleigh_stiffness * tmp[k];
                  K0.vmult(tmp, ve0);
                  r.add(-alpha * dynamics.rayleigh_stiffness, tmp);
                }
            }
          for (unsigned int k = 0; k < n_e; ++k)
            f_int.local_element(ld[k]) += fe[k];
          r *= -1.0;
          if (!with_matrix)
            {
              add_local(K, r, dofs, false);
              continue;
            }
          ++n_facet_evaluations;
          if (!incremental)
            {
              facet_matrix(sp, sp.tangent, K);
              add_local(K, r, dofs, true);
            }
          else
            {
              // Only a facet whose tangent changed adds to the matrix: B^T (D - D_old) B
              // (the damping part stays). Its full matrix is needed for the right-hand side
              // where it meets prescribed DoFs.
              const bool changed = !facet_in_matrix[e] || sp.tangent != assembled_tangent[e];
              if (any_constrained(dofs))
                {
                  facet_matrix(sp, sp.tangent, K);
                  add_local_rhs(K, r, dofs);
                }
              else
                add_local(K, r, dofs, false);
              if (!changed)
                continue;
              if (facet_in_matrix[e])
                spring_matrix(sp, sp.tangent - assembled_tangent[e], K);
              else
                facet_matrix(sp, sp.tangent, K);
              add_local_change(K, dofs);
            }
          assembled_tangent[e] = sp.tangent;
          facet_in_matrix[e]   = true;
          ++n_facet_updates;
        }

      if (with_matrix && !incremental && !dynamic && !lone_cells.empty())
        {
          // A cell without an intact facet (constrained: released or held in full) has
          // no matrix entry: a diagonal of the springs' scale keeps the matrix regular.
          // The scale is the first facet's normal stiffness (the same on every rank).
          dealii::FullMatrix<double> D(n_dofs, n_dofs);
          dealii::Vector<double>     zero(n_dofs);
          std::vector<dof_index>     cd(n_dofs);
          double                     k_first = springs.empty() || facet_id[0] != 0 ? 0.0 : springs[0].k[0];
          k_first = dealii::Utilities::MPI::max(k_first, network_communicator());
          for (unsigned int k = 0; k < n_dofs; ++k)
            D(k, k) = k_first > 0 ? k_first : 1.0;
          for (const unsigned int c : lone_cells)
            if (c < n_owned_cells)
              {
                for (unsigned int k = 0; k < n_dofs; ++k)
                  cd[k] = global_dof(n_dofs * c + k);
                add_local(D, zero, cd, true);
              }
        }

      if (dynamic)
        {
          // The cells: M a1 + (1 + alpha) a0 M v1 - alpha a0 M v0, tangent c_M M (which an
          // incremental assembly already holds).
          dealii::FullMatrix<double> M(n_dofs, n_dofs), A(n_dofs, n_dofs);
          dealii::Vector<double>     a1(n_dofs), v1(n_dofs), v0(n_dofs), rc(n_dofs), Mx(n_dofs);
          std::vector<dof_index>     cd(n_dofs);
          const double c_M = 1 / (beta * dt * dt) + (1 + alpha) * gamma / (beta * dt) * dynamics.rayleigh_mass;
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            {
              cell_mass_matrix(c, M);
              for (unsigned int k = 0; k < n_dofs; ++k)
                {
                  const unsigned int i = n_dofs * c + k;
                  cd[k]                = global_dof(i);
                  v0[k]                = v.local_element(i);
                  const double du      = u_trial.local_element(i) - u.local_element(i);
                  a1[k] = (du - dt * v0[k]) / (beta * dt * dt) - (1 - 2 * beta) / (2 * beta) * a.local_element(i);
                  v1[k] = v0[k] + dt * ((1 - gamma) * a.local_element(i) + gamma * a1[k]);
                }
              M.vmult(rc, a1);
              M.vmult(Mx, v1);
              for (unsigned int k = 0; k < n_dofs; ++k)
                inertia.local_element(n_dofs * c + k) += rc[k] + dynamics.rayleigh_mass * Mx[k];
              rc.add((1 + alpha) * dynamics.rayleigh_mass, Mx);
              M.vmult(Mx, v0);
              rc.add(-alpha * dynamics.rayleigh_mass, Mx);
              rc *= -1.0;
              A = 0;
              A.add(c_M, M);
              if (incremental && any_constrained(cd))
                add_local_rhs(A, rc, cd);
              else
                add_local(A, rc, cd, with_matrix && !incremental);
            }
        }

      if (with_matrix && trilinos_system())
        parallel_matrix.compress(dealii::VectorOperation::add);
      // The rows of ghost cells to their owners.
      for (Vector *x : {&rhs, &f_int, &inertia})
        x->compress(dealii::VectorOperation::add);
      if (distributed())
        {
          // Whether a spring failed on any rank, and the first rank's message.
          const MPI_Comm comm = network_communicator();
          if (dealii::Utilities::MPI::logical_or(failed, comm))
            {
              failed = true;
              for (const auto &m : dealii::Utilities::MPI::all_gather(comm, message))
                if (!m.empty())
                  {
                    message = m;
                    break;
                  }
            }
        }

      // The external forces (HHT-weighted) on the free DoFs.
      for (unsigned int i = 0; i < rhs.locally_owned_size(); ++i)
        if (!constraints.is_constrained(global_dof(i)))
          rhs.local_element(i) += dynamic ? (1 + alpha) * f_ext.local_element(i) - alpha * f_ext_old.local_element(i) :
                                            f_ext.local_element(i);

      if (failed)
        {
          spring_failure = message;
          return false;
        }
      last_force_level = std::max({f_int.l2_norm(), f_ext.l2_norm(), inertia.l2_norm()});
      return std::isfinite(last_force_level) && std::isfinite(rhs.l2_norm());
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
      Vector du(partitioner);
      // Predictor: the tangent of the converged state, the prescribed increments as
      // inhomogeneous constraints.
      make_constraints(t, t1, true);
      u_trial           = u;
      previous_residual = std::numeric_limits<double>::infinity(); // a new step's predictor
      // (Bouc-Wen springs keep the tangents of their last evaluation.)
      if (!assemble(t1, dt, true, analysis == Analysis::linear_static))
        return false;
      // The out-of-balance force of the prescribed increments: the force level of a
      // step that moves the network without loading it (a rigid motion).
      predictor_level = rhs.l2_norm();
      solve_linear(du);
      constraints.distribute(du);
      make_constraints(t, t1, false);
      u_trial += du;
      u_trial.update_ghost_values();
      if (!assemble(t1, dt, true, true))
        return false;
      const double first_residual = rhs.l2_norm(); // on every rank (a collective norm)
      if (newton_table)
        newton_table->add_row(newton_row(t1, dt, 0, first_residual, force_level(), 1.0));

      Vector     correction(partitioner);
      const auto log = [&](const unsigned int iteration, const double residual, const double alpha) {
        if (newton_table)
          newton_table->add_row(newton_row(t1, dt, iteration, residual, force_level(), alpha));
      };
      VectorNewtonProblem<Vector> problem(u_trial,
                                          correction,
                                          {[&](const bool matrix) {
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
                                           log});
      // The round-off the iterate carries, eps |K| |u| (a free flight: base/newton.h).
      const double floor = std::max(residual_floor(u.size()),
                                    iterate_floor(u.size(),
                                                  trilinos_system() ? parallel_matrix.linfty_norm() : matrix.linfty_norm(),
                                                  u_trial.linfty_norm(),
                                                  force_level()));
      const unsigned int iterations = newton_iterate(problem, newton, floor);
      n_newton += iterations > 0 ? iterations : newton.max_iterations;
      u_trial.update_ghost_values();
      return iterations > 0;
    }



    template <int dim>
    void
    Model<dim>::commit(const double dt, const bool broke)
    {
      const MPI_Comm comm = network_communicator();
      double         work = 0; // of the intact springs in the step (trapezoidal rule)
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
    std::array<double, 3>
    Model<dim>::fracture_ratio(const unsigned int e) const
    {
      // R = max(s_n / f_t, (|s_t| + tan(phi) s_n) / c): the distance to the Mohr-Coulomb
      // surface with a tension cut-off along the ray from the origin (eq. 3.50-3.51), on
      // the facet's normal stress and (3D) its resultant shear stress.
      const Springs<dim> &sp   = springs[e];
      const double        area = sp.area;
      const double        s_n  = sp.trial_force[0] / area;
      const double s_t = dim == 2 ? sp.trial_force[1] / area : std::hypot(sp.trial_force[1], sp.trial_force[dim - 1]) / area;
      const double R   = std::max(s_n / fracture.tensile_strength, (std::abs(s_t) + fracture.friction * s_n) / fracture.cohesion);
      return {{R, s_n, s_t}};
    }



    template <int dim>
    typename Model<dim>::Break
    Model<dim>::facet_to_break() const
    {
      Break  mine;
      double R_max = 1;
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          if (springs[e].broken)
            continue;
          const double R = fracture_ratio(e)[0];
          if (R > R_max)
            {
              R_max       = R;
              mine.local  = e;
              mine.facet  = facet_id[e];
            }
        }
      mine.R = R_max;
      if (!distributed())
        return mine;
      // The largest R over the ranks (MAXLOC: the lowest facet number among equal R,
      // as one rank's loop over the facets in their order would take), and its owner.
      const MPI_Comm comm = network_communicator();
      struct
      {
        double R;
        int    facet;
      } local{R_max, mine.facet < 0 ? std::numeric_limits<int>::max() : static_cast<int>(mine.facet)}, all{};
      int ierr = MPI_Allreduce(&local, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
      AssertThrowMPI(ierr);
      Break result;
      if (!(all.R > 1))
        return result;
      result.R     = all.R;
      result.facet = all.facet;
      const int owner = dealii::Utilities::MPI::max(mine.facet == all.facet ? int(part) : -1, comm);
      result.owner    = owner;
      result.local    = owner == int(part) ? mine.local : -1;
      return result;
    }



    template <int dim>
    void
    Model<dim>::initial_state()
    {
      // Velocities of the nuclei from the bodies' initial velocity (the cells
      // translate; prescribed DoFs move with their conditions), and M a0 = f_ext(0)
      // - f_int(0) - C v0 on the free DoFs.
      const auto        &bodies  = scene.body_descriptions();
      const unsigned int n_owned = u.locally_owned_size();
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const auto w = bodies[cell_body[c]].velocity_at(local_nuclei[c]);
          for (unsigned int d = 0; d < dim; ++d)
            v.local_element(n_dofs * c + d) = w[d];
        }
      // Prescribed DoFs start with the velocity of their condition: with v = 0 under
      // a moving condition the Newmark recursion a1 = 4 (du - dt v0) / dt^2 - a0 on
      // that DoF alternates with a growing amplitude, and its inertia enters the reaction.
      for (unsigned int i = 0; i < n_owned; ++i)
        if (dof_set[i] >= 0)
          v.local_element(i) = prescribed_velocity(dirichlet[dof_set[i]], i, 0);
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
      const double h = 1e-4 * scene.time_control().end_time;
      for (unsigned int i = 0; i < n_owned; ++i)
        if (dof_set[i] >= 0)
          a.local_element(i) = (prescribed_velocity(dirichlet[dof_set[i]], i, h) - v.local_element(i)) / h;
      a.update_ghost_values();
    }



    template <int dim>
    void
    Model<dim>::setup()
    {
      // A large network reports each stage (build_network(): nuclei and cells).
      build_network();
      StageReport stage(scene.console(), spacing.predicted_points > (dim == 2 ? 5e4 : 1e4));
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
          const MPI_Comm     comm = scene.mpi_communicator();
          const double       mb   = memory.VmHWM / 1024.0;
          std::ostringstream line;
          line << std::fixed << std::setprecision(0) << "rbsn: set-up peak memory per rank "
               << dealii::Utilities::MPI::min(mb, comm) << " ... " << dealii::Utilities::MPI::max(mb, comm) << " MB";
          scene.console() << line.str() << std::endl;
        }
      scene.console() << "rbsn: " << n_cells << " cells, " << n_global_facets << " facets (";
      if (spacing.is_constant())
        scene.console() << "d_m = " << d_m;
      else
        scene.console() << "d = " << spacing.min << " ... " << spacing.max;
      scene.console() << " m";
      if (n_blocks > 1)
        scene.console() << ", sampled in " << n_blocks << " blocks";
      scene.console() << "), " << n_dofs * n_cells << " DoFs" << std::endl;
      if ((analysis == Analysis::quasi_static || analysis == Analysis::implicit_dynamics) &&
          !consistent_tangent && scene.is_root())
        std::cerr << "hysteron: warning: RBSN: the springs' tangent is not the algorithmic one "
                     "(Bouc-Wen: Integrator = adaptive or forward euler), so Newton converges "
                     "linearly; Integrator = backward euler gives quadratic convergence"
                  << std::endl;
      const auto &time    = scene.time_control();
      double      nominal = time_step > 0 ? time_step : time.time_step;
      if (nominal == 0)
        nominal = time.end_time / n_increments;
      increments = IncrementControl(nominal, newton.max_cuts);
      if (analysis != Analysis::variable_order && !time.steps.empty())
        {
          std::vector<double> ends, nominals;
          time.step_grid(ends, nominals);
          increments.set_steps(ends, nominals);
        }
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
      const double end_time = scene.time_control().end_time;
      if (analysis == Analysis::variable_order)
        return end_time - t;
      return increments.step(t, end_time);
    }



    template <int dim>
    bool
    Model<dim>::advance(double &t, const double dt, const std::function<void(double)> &step_finished)
    {
      if (analysis == Analysis::variable_order)
        {
          // IDA chooses its steps; the driver's work follows each output time.
          t = integrate_variable_order(increments.nominal(), step_finished);
          return false;
        }
      const MPI_Comm comm = network_communicator();
      // The facets broken since the converged state t in this attempt of the increment
      // (their number on every rank; the local ones on their owners), with their
      // fracture.csv rows. They are intact again when the increment is cut (a break
      // decided at a load the shorter step does not reach) and in the last good state a
      // failing run writes; their rows are written when the increment converges, and by a
      // failing run (what broke in the failed attempt).
      unsigned int                     n_broken_since_t = 0;
      std::vector<unsigned int>        broken_since_t; // local facets
      std::vector<std::vector<double>> break_rows;
      std::vector<std::string>         break_messages; // of released fragments
      const auto                       restore_t = [&]() {
        for (const unsigned int e : broken_since_t)
          springs[e].broken = false;
        n_broken -= n_broken_since_t;
        if (n_broken_since_t > 0)
          update_fragments();
        broken_since_t.clear();
        n_broken_since_t = 0;
        break_messages.clear();
      };
      const auto write_breaks = [&]() {
        if (fracture_table)
          for (const auto &row : break_rows)
            fracture_table->add_row(row);
        break_rows.clear();
        if (scene.is_root())
          for (const auto &m : break_messages)
            std::cerr << "hysteron: warning: " << m << std::endl;
        break_messages.clear();
      };
      const auto fail_at_t = [&](const std::string &what) {
        restore_t();
        write_breaks();
        throw Run::StepFailure(what);
      };
      const auto xyz = [](const dealii::Point<dim> &p) {
        std::ostringstream s;
        s << "(" << p[0];
        for (unsigned int d = 1; d < dim; ++d)
          s << ", " << p[d];
        s << ")";
        return s.str();
      };

      bool converged = false;
      try
        {
          converged = solve_step(t, dt);
        }
      catch (const RuntimeError &error)
        {
          fail_at_t(std::string(error.what()) + " (step to t = " + std::to_string(t + dt) + " s).");
        }
      // Fracture: break the facet with the largest R > 1, solve the step again.
      for (unsigned int cycle = 0; converged && fracture.enabled; ++cycle)
        {
          const Break broken = facet_to_break();
          if (broken.facet < 0)
            break;
          if (cycle >= fracture.max_cycles)
            fail_at_t("rbsn: more than " + std::to_string(fracture.max_cycles) +
                      " facets break in the step to t = " + std::to_string(t + dt) +
                      " s: the network falls apart.");
          // The facet's owner: its midpoint, stresses and cells for every rank.
          std::array<double, dim + 5> facet{};
          if (broken.local >= 0)
            {
              const unsigned int e     = broken.local;
              const auto         ratio = fracture_ratio(e);
              for (unsigned int d = 0; d < dim; ++d)
                facet[d] = network.facets[e].midpoint[d];
              facet[dim]     = ratio[1];
              facet[dim + 1] = ratio[2];
              facet[dim + 2] = ratio[0];
              facet[dim + 3] = cell_id[network.facets[e].a];
              facet[dim + 4] = cell_id[network.facets[e].b];
              springs[e].broken = true;
              broken_since_t.push_back(e);
            }
          if (distributed())
            {
              const int ierr = MPI_Bcast(facet.data(), facet.size(), MPI_DOUBLE, broken.owner, comm);
              AssertThrowMPI(ierr);
            }
          ++n_broken;
          ++n_broken_since_t;
          dealii::Point<dim> midpoint;
          for (unsigned int d = 0; d < dim; ++d)
            midpoint[d] = facet[d];
          const std::vector<bool> released_before = released;
          update_fragments();
          const Separation separated = separation(facet[dim + 3], facet[dim + 4], released_before);
          {
            // The fracture.csv row: time, facet, midpoint, s_n, s_t, R, fragments, the
            // separated piece's cells and centroid, the released cells.
            std::vector<double> row{t + dt, double(broken.facet)};
            row.insert(row.end(), facet.begin(), facet.begin() + dim + 3);
            row.push_back(n_fragments);
            row.push_back(separated.cells);
            for (unsigned int d = 0; d < dim; ++d)
              row.push_back(separated.centroid[d]);
            row.push_back(separated.released);
            break_rows.push_back(row);
          }
          if (separated.released > 0)
            {
              const bool         one = separated.released == 1;
              std::ostringstream m;
              m << "rbsn: t = " << t + dt << " s: the facet at " << xyz(midpoint) << " broke and cut off "
                << separated.released << (one ? " cell" : " cells") << " around "
                << xyz(separated.released_centroid) << " that nothing holds: "
                << (one ? "it keeps its last state and leaves" : "they keep their last state and leave")
                << " the static system";
              if (separated.load.norm() > 1e-12 * std::max(force_scale, last_force_level))
                m << "; the load on " << (one ? "it" : "them") << ", "
                  << xyz(dealii::Point<dim>(separated.load)) << " N, is no longer carried";
              break_messages.push_back(m.str() + ".");
            }
          try
            {
              converged = solve_step(t, dt);
            }
          catch (const RuntimeError &error)
            {
              fail_at_t(std::string(error.what()) + " after the facet at " + xyz(midpoint) +
                        " broke at t = " + std::to_string(t + dt) + " s: the structure has fallen apart.");
            }
        }
      if (!converged)
        {
          if (!increments.cut())
            {
              n_cuts = increments.cuts();
              std::ostringstream m;
              m << "rbsn: Newton did not converge in the increment from t = " << t << " s to "
                << t + dt << " s (increment " << dt << " s = " << increments.nominal()
                << " s / 2^" << newton.max_cuts << ") after " << newton.max_cuts
                << " cuts: the structure may have reached its limit load (use displacement "
                << "control)";
              if (n_broken_since_t > 0)
                m << "; " << n_broken_since_t << " facets broke in its last attempt, "
                  << "the network may have fallen apart";
              if (!solver_failure.empty())
                m << "; the last attempt failed: " << solver_failure;
              else if (!spring_failure.empty())
                m << "; the last failure was in a spring: " << spring_failure;
              else
                m << "; the last residual was " << rhs.l2_norm() / force_level()
                  << " of the force level (tolerance " << newton.tolerance << ")";
              m << ".";
              fail_at_t(m.str());
            }
          restore_t();
          break_rows.clear();
          return false;
        }
      commit(dt, n_broken_since_t > 0);
      write_breaks();
      increments.accept(t, dt);
      n_cuts = increments.cuts();
      return true;
    }



    template <int dim>
    void
    Model<dim>::finish()
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
