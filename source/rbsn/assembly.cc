// The assembly of the RBSN's residual and tangent (assembly.h).
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include "rbsn/assembly.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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
      return Assembly(*this, t1, dt, with_matrix, update_springs).run();
    }



    template <int dim>
    Model<dim>::Assembly::Assembly(Model &model, const double t1, const double dt, const bool with_matrix,
                                   const bool update_springs)
      : m(model)
      , t1(t1)
      , dt(dt)
      , with_matrix(with_matrix)
      , update_springs(update_springs)
      , dynamic(model.analysis == Analysis::implicit_dynamics && dt > 0)
    {
      // A facet's local matrices and vectors (its two cells' DoFs).
      K.reinit(2 * n_dofs, 2 * n_dofs);
      K0.reinit(2 * n_dofs, 2 * n_dofs);
      for (dealii::Vector<double> *x : {&r, &fe, &fe0, &ve0, &ve1, &tmp})
        x->reinit(2 * n_dofs);
      dofs.resize(2 * n_dofs);
    }



    template <int dim>
    bool
    Model<dim>::Assembly::run()
    {
      begin();
      m.rhs     = 0;
      m.f_int   = 0;
      m.inertia = 0;
      m.external_forces(t1, m.f_ext);
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        {
          m.facet_dofs(e, dofs);
          if (m.springs[e].broken)
            {
              // Broken since the matrix was assembled: its springs are taken out of it.
              if (incremental && m.facet_in_matrix[e])
                remove_facet(e);
              continue;
            }
          // After a failure the remaining facets' springs are evaluated, not assembled.
          failed = !update_facet_springs(e) || failed;
          if (failed)
            continue;
          facet_residual(e);
          add_facet(e);
        }
      if (with_matrix && !incremental && !dynamic && !m.lone_cells.empty())
        hold_lone_cells();
      if (dynamic)
        add_cell_inertia();
      return finish();
    }



    template <int dim>
    void
    Model<dim>::Assembly::begin()
    {
      // The matrix is updated rather than rebuilt if it holds the facets' tangents for the
      // current constrained DoFs and (dynamics) the same step.
      const double key = dynamic ? dt : 0.0;
      incremental      = with_matrix && m.incremental_assembly && m.matrix_current && m.matrix_dt == key &&
                    m.incremental_updates < m.max_incremental_updates;
      if (with_matrix)
        {
          ++m.n_matrix_assemblies;
          if (incremental)
            ++m.incremental_updates;
          else
            {
              ++m.n_full_assemblies;
              m.incremental_updates = 0;
              if (m.trilinos_system())
                m.parallel_matrix = 0;
              else
                m.matrix = 0;
              m.assembled_tangent.resize(m.springs.size());
              m.facet_in_matrix.assign(m.springs.size(), false);
            }
          m.matrix_current = true;
          m.matrix_dt      = key;
        }
    }



    template <int dim>
    void
    Model<dim>::Assembly::elastic_matrix(const Springs<dim> &sp, dealii::FullMatrix<double> &M)
    {
      // K0 = B^T diag(k) B: the elastic springs (stiffness-proportional damping).
      for (unsigned int p = 0; p < 2 * n_dofs; ++p)
        for (unsigned int q = 0; q < 2 * n_dofs; ++q)
          {
            M(p, q) = 0;
            for (unsigned int i = 0; i < n_dofs; ++i)
              M(p, q) += sp.B[i][p] * sp.k[i] * sp.B[i][q];
          }
    }



    template <int dim>
    void
    Model<dim>::Assembly::spring_matrix(const Springs<dim> &sp, const SpringMatrix &D, dealii::FullMatrix<double> &M) const
    {
      // B^T D B (the diagonal of D only, for linear springs and laws of independent
      // springs; else the full, not necessarily symmetric D), in dynamics times 1 + alpha.
      // Linear in D. As B^T (D B): n_s n_e (n_s + n_e) products instead of n_e^2 n_s^2.
      constexpr unsigned int n_e      = 2 * n_dofs;
      const bool             diagonal = m.spring_law->diagonal_tangent() || !sp.hysteretic;
      double                 DB[n_dofs][n_e];
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
        M *= 1 + m.dynamics.hht_alpha;
    }



    template <int dim>
    void
    Model<dim>::Assembly::facet_matrix(const Springs<dim> &sp, const SpringMatrix &D)
    {
      // The springs' matrix and, in dynamics, the damping (1 + alpha) gamma / (beta dt) a1 K0.
      spring_matrix(sp, D, K);
      if (dynamic && m.dynamics.rayleigh_stiffness > 0)
        {
          elastic_matrix(sp, K0);
          K.add((1 + m.dynamics.hht_alpha) * m.dynamics.gamma() / (m.dynamics.beta() * dt) * m.dynamics.rayleigh_stiffness,
                        K0);
        }
    }



    template <int dim>
    void
    Model<dim>::Assembly::remove_facet(const unsigned int e)
    {
      facet_matrix(m.springs[e], m.assembled_tangent[e]);
      K *= -1.0;
      m.add_local_change(K, dofs);
      m.facet_in_matrix[e] = false;
      ++m.n_facet_updates;
    }



    template <int dim>
    bool
    Model<dim>::Assembly::update_facet_springs(const unsigned int e)
    {
      // delta = B U_e at u_trial; linear springs F = k delta, the spring law from the
      // converged forces and state (one call per facet); without @p update_springs the
      // converged forces.
      Springs<dim> &sp = m.springs[e];
      const auto    ld = m.facet_local_dofs(e);
      std::array<double, 2 * n_dofs> ue;
      for (unsigned int k = 0; k < 2 * n_dofs; ++k)
        ue[k] = m.u_trial.local_element(ld[k]);
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
      if (!update_springs || !sp.hysteretic)
        return true;
      std::copy(sp.state.begin(), sp.state.end(), sp.trial_state.begin());
      try
        {
          m.spring_law->update(e, increment, sp.trial_force, sp.trial_state.data(), with_matrix ? &sp.tangent : nullptr);
        }
      catch (const SpringFailure &error)
        {
          std::ostringstream text;
          text << error.what() << " (" << error.springs << " of the facet at " << m.network.facets[e].midpoint
            << ", step to t = " << t1 << " s)";
          message = text.str();
          return false;
        }
      return true;
    }



    template <int dim>
    void
    Model<dim>::Assembly::facet_residual(const unsigned int e)
    {
      // -r_e: B^T F into f_int; in dynamics the HHT weights and the stiffness-proportional
      // damping a1 K0 v (into the inertia forces).
      const Springs<dim>    &sp = m.springs[e];
      const auto             ld = m.facet_local_dofs(e);
      const double           alpha = m.dynamics.hht_alpha, beta = m.dynamics.beta(), gamma = m.dynamics.gamma();
      constexpr unsigned int n_e = 2 * n_dofs;
            for (unsigned int k = 0; k < n_e; ++k)
        {
          fe[k] = 0;
          for (unsigned int i = 0; i < n_dofs; ++i)
            fe[k] += sp.B[i][k] * sp.trial_force[i];
        }
      r = fe;
      if (dynamic)
        {
          for (unsigned int k = 0; k < n_e; ++k)
            {
              fe0[k] = 0;
              for (unsigned int i = 0; i < n_dofs; ++i)
                fe0[k] += sp.B[i][k] * sp.force[i];
            }
          r *= 1 + alpha;
          r.add(-alpha, fe0);
          if (m.dynamics.rayleigh_stiffness > 0)
            {
              elastic_matrix(sp, K0);
              for (unsigned int k = 0; k < n_e; ++k)
                {
                  ve0[k]  = m.v.local_element(ld[k]);
                  const double a0 = m.a.local_element(ld[k]);
                  const double a1 = (m.u_trial.local_element(ld[k]) - m.u.local_element(ld[k]) - dt * ve0[k]) /
                                      (beta * dt * dt) -
                                    (1 - 2 * beta) / (2 * beta) * a0;
                  ve1[k] = ve0[k] + dt * ((1 - gamma) * a0 + gamma * a1);
                }
              K0.vmult(tmp, ve1);
              r.add((1 + alpha) * m.dynamics.rayleigh_stiffness, tmp);
              for (unsigned int k = 0; k < n_e; ++k)
                m.inertia.local_element(ld[k]) += m.dynamics.rayleigh_stiffness * tmp[k];
              K0.vmult(tmp, ve0);
              r.add(-alpha * m.dynamics.rayleigh_stiffness, tmp);
            }
        }
      for (unsigned int k = 0; k < n_e; ++k)
        m.f_int.local_element(ld[k]) += fe[k];
      r *= -1.0;
    }



    template <int dim>
    void
    Model<dim>::Assembly::add_facet(const unsigned int e)
    {
      Springs<dim> &sp = m.springs[e];
      if (!with_matrix)
        {
          m.add_local(K, r, dofs, false);
          return;
        }
      ++m.n_facet_evaluations;
      if (!incremental)
        {
          facet_matrix(sp, sp.tangent);
          m.add_local(K, r, dofs, true);
        }
      else
        {
          // Only a facet whose tangent changed adds to the matrix: B^T (D - D_old) B (the
          // damping part stays). Its full matrix is needed for the right-hand side where it
          // meets prescribed DoFs.
          const bool changed = !m.facet_in_matrix[e] || sp.tangent != m.assembled_tangent[e];
          if (any_constrained(dofs))
            {
              facet_matrix(sp, sp.tangent);
              m.add_local_rhs(K, r, dofs);
            }
          else
            m.add_local(K, r, dofs, false);
          if (!changed)
            return;
          if (m.facet_in_matrix[e])
            spring_matrix(sp, sp.tangent - m.assembled_tangent[e], K);
          else
            facet_matrix(sp, sp.tangent);
          m.add_local_change(K, dofs);
        }
      m.assembled_tangent[e] = sp.tangent;
      m.facet_in_matrix[e]   = true;
      ++m.n_facet_updates;
    }



    template <int dim>
    void
    Model<dim>::Assembly::hold_lone_cells()
    {
      // A cell without an intact facet (constrained: released or held in full) has no
      // matrix entry: a diagonal of the springs' scale keeps the matrix regular. The scale
      // is the first facet's normal stiffness (the same on every rank).
      dealii::FullMatrix<double> D(n_dofs, n_dofs);
      dealii::Vector<double>     zero(n_dofs);
      std::vector<dof_index>     cd(n_dofs);
      double                     k_first = m.springs.empty() || m.facet_id[0] != 0 ? 0.0 : m.springs[0].k[0];
      k_first = dealii::Utilities::MPI::max(k_first, m.network_communicator());
      for (unsigned int k = 0; k < n_dofs; ++k)
        D(k, k) = k_first > 0 ? k_first : 1.0;
      for (const unsigned int c : m.lone_cells)
        if (c < m.n_owned_cells)
          {
            for (unsigned int k = 0; k < n_dofs; ++k)
              cd[k] = m.global_dof(n_dofs * c + k);
            m.add_local(D, zero, cd, true);
          }
    }



    template <int dim>
    void
    Model<dim>::Assembly::add_cell_inertia()
    {
      // The cells: M a1 + (1 + alpha) a0 M v1 - alpha a0 M v0, tangent c_M M (which an
      // incremental assembly already holds).
      const double alpha = m.dynamics.hht_alpha, beta = m.dynamics.beta(), gamma = m.dynamics.gamma();
      dealii::FullMatrix<double> M(n_dofs, n_dofs), A(n_dofs, n_dofs);
      dealii::Vector<double>     a1(n_dofs), v1(n_dofs), v0(n_dofs), rc(n_dofs), Mx(n_dofs);
      std::vector<dof_index>     cd(n_dofs);
      const double c_M = 1 / (beta * dt * dt) + (1 + alpha) * gamma / (beta * dt) * m.dynamics.rayleigh_mass;
      for (unsigned int c = 0; c < m.n_owned_cells; ++c)
        {
          m.cell_mass_matrix(c, M);
          for (unsigned int k = 0; k < n_dofs; ++k)
            {
              const unsigned int i = n_dofs * c + k;
              cd[k]                = m.global_dof(i);
              v0[k]                = m.v.local_element(i);
              const double du      = m.u_trial.local_element(i) - m.u.local_element(i);
              a1[k] = (du - dt * v0[k]) / (beta * dt * dt) - (1 - 2 * beta) / (2 * beta) * m.a.local_element(i);
              v1[k] = v0[k] + dt * ((1 - gamma) * m.a.local_element(i) + gamma * a1[k]);
            }
          M.vmult(rc, a1);
          M.vmult(Mx, v1);
          for (unsigned int k = 0; k < n_dofs; ++k)
            m.inertia.local_element(n_dofs * c + k) += rc[k] + m.dynamics.rayleigh_mass * Mx[k];
          rc.add((1 + alpha) * m.dynamics.rayleigh_mass, Mx);
          M.vmult(Mx, v0);
          rc.add(-alpha * m.dynamics.rayleigh_mass, Mx);
          rc *= -1.0;
          A = 0;
          A.add(c_M, M);
          if (incremental && any_constrained(cd))
            m.add_local_rhs(A, rc, cd);
          else
            m.add_local(A, rc, cd, with_matrix && !incremental);
        }
    }



    template <int dim>
    bool
    Model<dim>::Assembly::finish()
    {
      const double alpha = m.dynamics.hht_alpha;
      if (with_matrix && m.trilinos_system())
        m.parallel_matrix.compress(dealii::VectorOperation::add);
      // The rows of ghost cells to their owners.
      for (Vector *x : {&m.rhs, &m.f_int, &m.inertia})
        x->compress(dealii::VectorOperation::add);
      if (m.distributed())
        {
          // Whether a spring failed on any rank, and the first rank's message.
          const MPI_Comm comm = m.network_communicator();
          if (dealii::Utilities::MPI::logical_or(failed, comm))
            {
              failed = true;
              for (const auto &text : dealii::Utilities::MPI::all_gather(comm, message))
                if (!text.empty())
                  {
                    message = text;
                    break;
                  }
            }
        }

      // The external forces (HHT-weighted) on the free DoFs.
      for (unsigned int i = 0; i < m.rhs.locally_owned_size(); ++i)
        if (!m.constraints.is_constrained(m.global_dof(i)))
          m.rhs.local_element(i) +=
            dynamic ? (1 + alpha) * m.f_ext.local_element(i) - alpha * m.f_ext_old.local_element(i) : m.f_ext.local_element(i);

      if (failed)
        {
          m.spring_failure = message;
          return false;
        }
      m.last_force_level = std::max({m.f_int.l2_norm(), m.f_ext.l2_norm(), m.inertia.l2_norm()});
      return std::isfinite(m.last_force_level) && std::isfinite(m.rhs.l2_norm());
    }



    template <int dim>
    bool
    Model<dim>::Assembly::any_constrained(const std::vector<dof_index> &indices) const
    {
      return std::any_of(indices.begin(), indices.end(), [&](const auto i) { return m.constraints.is_constrained(i); });
    }



    template class Model<2>::Assembly;
    template class Model<3>::Assembly;
    template bool Model<2>::assemble(double, double, bool, bool);
    template bool Model<3>::assemble(double, double, bool, bool);
  } // namespace RBSN
} // namespace hysteron
