// The FEM's global assembly: the discrete equations below, the WorkStream loop over the
// locally owned cells that runs the cell kernels of cell_kernels.h on each and adds their
// matrices and vectors into the global system, and the commit of a converged step.
#include <deal.II/base/exceptions.h>
#include <deal.II/base/multithread_info.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/work_stream.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include "fem/fem.h"

#include "cell_kernels.h"

#include <cmath>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /// MPI_InitFinalize gives every method one thread; the guard raises the limit for the
      /// assembly loop only.
      struct ThreadLimit
      {
        explicit ThreadLimit(const unsigned int n)
          : raised(n > 1)
        {
          if (raised)
            dealii::MultithreadInfo::set_thread_limit(n);
        }
        ~ThreadLimit()
        {
          if (raised)
            dealii::MultithreadInfo::set_thread_limit(1);
        }
        const bool raised;
      };
    } // namespace



    /*
     * The discrete equations. With N_i the vector shape functions, B_i their
     * symmetric gradients, w_q = JxW_q t (t: the thickness in 2D) and the
     * stresses sigma_q of the material update from the converged state,
     *   f_int,i = sum_q B_i(x_q) : sigma_q w_q,
     *   K_ij    = sum_q B_i : C_q : B_j w_q        (C_q: the material's tangent),
     *   M_ij    = sum_q rho N_i . N_j w_q,   K0_ij = sum_q B_i : D : B_j w_q (elastic),
     *   f_ext,i = sum_q N_i . (rho g + F_l(t) / V_l) w_q + sum_faces N_i . t_l(t) w_f,
     * for body loads F_l (a total force spread over the volume V_l of the
     * material in the load's region) and tractions t_l on the boundary faces in
     * the region.
     *
     * Axisymmetric (x = r, w_q = JxW_q 2 pi r_q): the hoop strain eps_tt = u_r / r is a
     * fourth strain component with the "B" of shape function i equal to
     * n_i = N_i delta(c_i, x) / r, so that
     *   f_int,i += sum_q n_i sigma_tt w_q,
     *   K_ij    += sum_q (B_i : S n_j + n_i H : B_j + n_i C_tt n_j) w_q,
     * with S = d sigma / d eps_tt, H = d sigma_tt / d eps and C_tt = d sigma_tt / d eps_tt
     * (Material::HoopTangent; S = H = lambda I and C_tt = lambda + 2 mu for Hooke's law).
     * The Gauss points lie inside the cells, so r_q > 0 also next to the axis.
     *
     * Quasi-static: r = f_int(u) - f_ext(t1), tangent K.
     * HHT-alpha (Newmark for alpha = 0), beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha:
     *   a1 = (u1 - u0 - dt v0) / (beta dt^2) - (1 - 2 beta) / (2 beta) a0,
     *   v1 = v0 + dt ((1 - gamma) a0 + gamma a1),
     *   r  = M a1 + (1 + alpha)(C v1 + f_int(u1) - f_ext(t1)) - alpha (C v0 + f_int(u0) - f_ext(t0)),
     *   dr/du1 = M / (beta dt^2) + (1 + alpha) gamma / (beta dt) C + (1 + alpha) K,
     * with Rayleigh damping C = a0 M + a1 K0. Everything is formed cell by cell,
     * so that AffineConstraints condenses the prescribed DoFs (and, in the
     * predictor, moves the prescribed increments to the right-hand side).
     *
     * Updated Lagrangian (`Kinematics = updated Lagrangian`): x = X + u. With
     * F = I + grad_X u in the converged (F_n), trial (F_1) and midpoint (F_m = (F_n + F_1)/2)
     * configurations, a gradient in configuration k is grad_k N = F_k^{-T} grad_X N and a
     * volume w det F_k. The increment's velocity gradient at the midpoint,
     * L = grad_X du F_m^{-1}, gives the strain increment d eps = sym L and the spin
     * W = skew L. The Jaumann rate sigma' = C : d + W sigma - sigma W is C : d in a frame
     * that turns with the spin: over the step sigma_1 = Q sigma_n Q^T + Q_h (C : d eps) Q_h^T
     * to second order, with Q the step's rotation and Q_h its half. Hence the stress (and
     * the material's tensor state) is turned by half the step's rotation, updated, and
     * turned by the other half,
     *   sigma_1 = R_h update(R_h sigma_n R_h^T, d eps) R_h^T,   R_h^2 = (I - W/2)^{-1} (I + W/2),
     * which is exact for rigid rotations: u_1 - u_n = (Q - I) x_n gives L = 2 (Q - I)(Q + I)^{-1},
     * a skew tensor, so d eps = 0, and the Cayley transform of W/2 is Q itself. Equilibrium holds in the trial configuration,
     *   f_int,i = sum_q B_i^1 : sigma_1 w_q det F_1,
     * and the tangent is the material one plus the initial-stress (geometric) stiffness,
     *   K_ij = sum_q (B_i^1 : C : B_j^m + delta(c_i, c_j) grad_1 N_i . sigma_1 grad_1 N_j) w_q det F_1,
     * with B_j^m = sym((I - L/2) e_{c_j} (x) grad_m N_j) the derivative of d eps (with B-bar
     * the mean-dilatation B of the midpoint), and C the material's tangent turned by R_h in its
     * stress indices; the derivatives of R_h and of the volume, of order sigma / E, are
     * left out. The
     * mass, loads (dead loads) and thickness stay those of the reference configuration.
     */
    template <int dim>
    bool
    Solver<dim>::assemble(const Vector  &u_iterate,
                          const double   t1,
                          const double   dt,
                          const Assemble what,
                          const bool     update_material)
    {
      using namespace dealii;
      const Scene<dim> &scene = this->get_scene();
      TimerOutput::Scope timing(scene.timer(), "FEM assembly");
      // dt = 0: the forces of the state u_iterate only (the initial state).
      const CellKernels<dim> kernels(
        *this, scene, u_iterate, t1, dt, what == Assemble::residual_and_matrix, update_material);
      const bool matrix = kernels.matrix, dynamic = kernels.dynamic;
      const bool system = analysis != Analysis::explicit_dynamics;

      if (matrix)
        system_matrix = 0;
      if (system)
        system_rhs = 0;
      f_int   = 0;
      f_ext   = 0;
      inertia = 0;

      // Cell by cell, in parallel threads (`FEM/Threads`): the worker forms a cell's
      // matrix and vectors (and updates its material points, which only it touches); the
      // copier adds them to the global system in the order of the cells, so that the
      // sums, and the first failure reported, do not depend on the number of threads.
      bool        failed = false;
      std::string message;
      const auto  copier = [&](const CellCopy &c) {
        if (!c.active)
          return;
        material_seconds += c.material_seconds;
        if (c.failed)
          {
            if (!failed)
              message = c.message;
            failed = true;
          }
        if (failed)
          return;
        if (system)
          {
            if (matrix)
              constraints.distribute_local_to_global(c.A, c.r, c.dofs, system_matrix, system_rhs, true);
            else
              constraints.distribute_local_to_global(c.r, c.dofs, system_rhs);
          }
        f_int.add(c.dofs, c.fi);
        f_ext.add(c.dofs, c.fx);
        if (dynamic)
          inertia.add(c.dofs, c.Mv);
      };
      // Threads for this loop only (deal.II's other operations keep one). With more than one,
      // FEValues computes every cell's geometry afresh instead of reusing that of a translated
      // neighbour, so the results differ from one thread's at round-off; they are the same
      // for any number of threads above one.
      using Filtered = FilteredIterator<typename CellKernels<dim>::CellIterator>;
      const ThreadLimit limit(threads);
      WorkStream::run(
        Filtered(IteratorFilters::LocallyOwnedCell(), dof_handler.begin_active()),
        Filtered(IteratorFilters::LocallyOwnedCell(), dof_handler.end()),
        [&kernels](const auto &cell, CellScratch<dim> &scratch, CellCopy &copy) { kernels.assemble(cell, scratch, copy); },
        copier,
        CellScratch<dim>(*mapping, *fe, *quadrature, *face_quadrature),
        CellCopy(fe->n_dofs_per_cell()));

      // Forces shared by nodes (a load region without quadrature points).
      const auto &load1 = kernels.load1, &load0 = kernels.load0;
      const double alpha = dynamics.hht_alpha;
      for (unsigned int l = 0; l < load_sets.size(); ++l)
        if (load_sets[l].kind == LoadSet::Kind::nodal)
          for (unsigned int k = 0; k < load_sets[l].nodal_dofs.size(); ++k)
            {
              const auto         dof = load_sets[l].nodal_dofs[k];
              const unsigned int c   = load_sets[l].nodal_components[k];
              f_ext(dof) += load1[l][c];
              if (system && !constraints.is_constrained(dof))
                system_rhs(dof) += dynamic ? (1 + alpha) * load1[l][c] - alpha * load0[l][c] : load1[l][c];
            }

      if (matrix)
        system_matrix.compress(VectorOperation::add);
      if (system)
        system_rhs.compress(VectorOperation::add);
      f_int.compress(VectorOperation::add);
      f_ext.compress(VectorOperation::add);
      inertia.compress(VectorOperation::add);

      // A failure on any rank is a failure everywhere (with the first message).
      MPI_Comm comm = scene.mpi_communicator();
      if (dealii::Utilities::MPI::logical_or(failed, comm))
        {
          const unsigned int rank  = dealii::Utilities::MPI::this_mpi_process(comm);
          const unsigned int first = dealii::Utilities::MPI::min(failed ? rank : dealii::numbers::invalid_unsigned_int, comm);
          material_failure         = dealii::Utilities::MPI::broadcast(comm, message, first);
          return false;
        }
      last_force_level = std::max({f_int.l2_norm(), f_ext.l2_norm(), inertia.l2_norm()});
      return std::isfinite(last_force_level) && (!system || std::isfinite(system_rhs.l2_norm()));
    }





    template <int dim>
    void
    Solver<dim>::commit(const double t1, const double dt)
    {
      (void)t1;
      using namespace dealii;
      double     work         = 0;
      const bool axisymmetric = this->get_scene().axisymmetric();
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            for (unsigned int q = 0; q < h.stress.size(); ++q)
              {
                // Trapezoidal internal work 1/2 (sigma_n + sigma_n+1) : d eps (+ the hoop part),
                // over the volume of the step's midpoint.
                work += 0.5 * ((h.stress[q] + h.trial_stress[q]) * h.increment[q]) *
                        (finite_strain ? 0.5 * (h.volume[q] + h.trial_volume[q]) : h.weight[q]);
                if (axisymmetric)
                  work += 0.5 * (h.out_of_plane_stress(q, false) + h.out_of_plane_stress(q, true)) *
                          h.hoop_increment[q] * h.weight[q];
                h.strain[q] += h.increment[q];
              }
            h.stress.swap(h.trial_stress);
            h.state.swap(h.trial_state);
            if (finite_strain)
              h.volume = h.trial_volume;
          }
      internal_work += work; // this rank's part (summed when a table row is written)

      Vector increment = u_trial;
      increment -= u;
      if (analysis == Analysis::implicit_dynamics)
        {
          // The dashpots of absorbing boundaries do the work -1/2 (C_b v_n + C_b v_n+1) . du on
          // the body (trapezoidal like the other works, so that Newmark's balance stays exact).
          Vector dashpot  = absorbers.empty() ? Vector() : absorbing_force(v_ghost);
          Vector rayleigh = has_rayleigh_damping() ? rayleigh_force(v_ghost) : Vector();
          dynamics.update(increment, dt, v, a);
          v_ghost = v;
          a_ghost = a;
          // Likewise the Rayleigh forces do -1/2 (C v_n + C v_n+1) . du: dissipated.
          if (has_rayleigh_damping())
            {
              rayleigh += rayleigh_force(v_ghost);
              for (const auto i : owned_dofs)
                damping_work += 0.5 * rayleigh(i) * increment(i);
            }
          if (!absorbers.empty())
            {
              dashpot += absorbing_force(v_ghost);
              for (const auto i : owned_dofs)
                boundary_work -= 0.5 * dashpot(i) * increment(i);
            }
        }
      else if (analysis == Analysis::quasi_static && dt > 0)
        {
          // The rate of the load path (t is the load parameter): what the probes
          // report as velocity, comparable with a slow dynamic run. No kinetic energy.
          v = increment;
          v *= 1 / dt;
          v_ghost = v;
        }

      // External and boundary work (trapezoidal, this rank's DoFs), the reactions of the new state.
      for (const auto i : owned_dofs)
        external_work += 0.5 * (f_ext_old(i) + f_ext(i)) * increment(i);
      Vector r = f_int;
      r += inertia;
      r -= f_ext;
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        if (owned_dofs.is_element(constrained_list[k]))
          boundary_work += 0.5 * (reaction_old(constrained_list[k]) + r(constrained_list[k])) *
                           increment(constrained_list[k]);
      reaction_old = r;
      f_int_old    = f_int;
      f_ext_old    = f_ext;
      force_scale  = std::max(force_scale, last_force_level);
      u            = u_trial;
      u_ghost      = u;
    }



    template <int dim>
    void
    Solver<dim>::elastic_stiffness_product(const Vector &x, Vector &y) const
    {
      // y = K0 x = sum_q B_i : D : eps(x) w_q, matrix-free (explicit damping, power iteration).
      using namespace dealii;
      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      FEValues<dim>      fv(*mapping, *fe, *quadrature, update_gradients);
      std::vector<types::global_dof_index> dofs(n);
      dealii::Vector<double>               xe(n), ye(n);
      StrainOperator<dim>                  B(n_q, std::vector<SymmetricTensor<2, dim>>(n));
      y = 0;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fv.reinit(cell);
            cell->get_dof_indices(dofs);
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            const SymmetricTensor<4, dim> D = h.material->elasticity().template stiffness<dim>();
            for (unsigned int i = 0; i < n; ++i)
              xe[i] = x(dofs[i]);
            small_strain_operator(fv, h.weight, b_bar, B);
            ye = 0;
            for (unsigned int q = 0; q < n_q; ++q)
              {
                SymmetricTensor<2, dim> e;
                for (unsigned int i = 0; i < n; ++i)
                  e += xe[i] * B[q][i];
                const SymmetricTensor<2, dim> s = D * e;
                for (unsigned int i = 0; i < n; ++i)
                  ye[i] += (B[q][i] * s) * h.weight[q];
              }
            y.add(dofs, ye);
          }
      y.compress(VectorOperation::add);
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron
