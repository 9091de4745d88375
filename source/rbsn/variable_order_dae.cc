#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include "rbsn/variable_order.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

// The DAE of the variable-order analysis (rbsn/variable_order.h): its Newton matrix's
// pattern and IDA's tolerances, F(t, y, y'), the Newton matrix and its solve, and the
// transfers between IDA's y and the model.

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      bool
      all_finite(const dealii::ArrayView<const double> values)
      {
        return std::all_of(values.begin(), values.end(), [](const double x) { return std::isfinite(x); });
      }
    } // namespace



    template <int dim>
    Model<dim>::VariableOrder::VariableOrder(Model<dim> &model)
      : m(model)
      , n(model.u.size())
    {
      state_offset.assign(n_dofs * m.springs.size(), -1);
      uniaxial.assign(n_dofs * m.springs.size(), typename SpringLaw<dim>::UniaxialSpring());
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        if (m.springs[e].hysteretic)
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              uniaxial[n_dofs * e + i] = m.spring_law->uniaxial_spring(e, i);
              if (uniaxial[n_dofs * e + i].law == nullptr)
                throw std::logic_error("rbsn: the spring law '" + m.spring_law_name +
                                       "' supports the variable-order analysis but gives no "
                                       "uniaxial law of a spring");
              state_offset[n_dofs * e + i] = n_states;
              n_states += law(e, i).n_state_variables();
            }
      n_total = 2 * n + n_states + 4;
      w.assign(n, 0.0);
      reaction.reinit(n);
      lu_rhs.reinit(n_total);
      lu_x.reinit(n_total);
      f_ext.reinit(m.partitioner);

      // The Newton matrix's pattern: kinematic rows (u_i, u_i), (u_i, v_i); the cells'
      // mass blocks; per facet the (v, u) and (v, v) blocks of its two cells, the
      // (v, z) columns of its springs, the (s, s) and (s, v) blocks of its springs.
      dealii::DynamicSparsityPattern dsp(n_total, n_total);
      for (unsigned int i = 0; i < n; ++i)
        {
          dsp.add(i, i);
          dsp.add(i, n + i);
        }
      for (unsigned int c = 0; c < m.n_owned_cells; ++c)
        for (unsigned int p = 0; p < n_dofs; ++p)
          for (unsigned int q = 0; q < n_dofs; ++q)
            dsp.add(n + n_dofs * c + p, n + n_dofs * c + q);
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        {
          const auto dofs = facet_dofs(e);
          for (const unsigned int p : dofs)
            for (const unsigned int q : dofs)
              {
                dsp.add(n + p, q);
                dsp.add(n + p, n + q);
              }
          if (state_offset[n_dofs * e] < 0)
            continue;
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              const unsigned int k = law(e, i).n_state_variables(), s0 = s_index(e, i);
              for (const unsigned int p : dofs)
                dsp.add(n + p, s0);
              for (unsigned int a = 0; a < k; ++a)
                {
                  for (unsigned int b = 0; b < k; ++b)
                    dsp.add(s0 + a, s0 + b);
                  for (const unsigned int q : dofs)
                    dsp.add(s0 + a, n + q);
                }
            }
        }
      for (unsigned int j = 2 * n + n_states; j < n_total; ++j)
        dsp.add(j, j);
      pattern.copy_from(dsp);
      jacobian.reinit(pattern);

      // Absolute tolerances (see the parameter's documentation).
      const auto  &p     = m.variable_order;
      const double atol  = p.absolute_tolerance > 0 ? p.absolute_tolerance : p.relative_tolerance * 1e-3 * m.scale;
      const double t_out = m.time_step > 0 ? m.time_step :
                           m.scene().time_control().time_step > 0 ? m.scene().time_control().time_step :
                                                                  m.scene().time_control().end_time / m.n_increments;
      tolerances.assign(n_total, 0.0);
      for (unsigned int i = 0; i < n; ++i)
        {
          tolerances[i]     = i % n_dofs >= dim ? atol / m.scale : atol;
          tolerances[n + i] = tolerances[i] / t_out;
        }
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        if (state_offset[n_dofs * e] >= 0)
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              const auto        &spring = law(e, i);
              const unsigned int s0     = s_index(e, i);
              tolerances[s0]            = i >= dim ? atol / m.scale : atol;
              if (spring.degradation())
                {
                  tolerances[s0 + Material::BoucWenUniaxial::eta_index]    = p.relative_tolerance;
                  tolerances[s0 + Material::BoucWenUniaxial::energy_index] = tolerances[s0] * spring.yield_value();
                }
            }
      // The works: 1e-2 k_max d atol, the work of the largest normal spring's force at
      // the displacement d = atol / rtol over atol, a hundredth of it (the smooth
      // quadratures cost few steps).
      double k_max = 0;
      for (const auto &sp : m.springs)
        k_max = std::max(k_max, sp.k[0]);
      for (unsigned int j = 2 * n + n_states; j < n_total; ++j)
        tolerances[j] = 1e-2 * k_max * atol * atol / p.relative_tolerance;
    }



    template <int dim>
    std::vector<double>
    Model<dim>::VariableOrder::differential_components() const
    {
      // All but the velocities of the prescribed DoFs.
      std::vector<double> differential(n_total, 1.0);
      for (unsigned int i = 0; i < n; ++i)
        if (m.dof_set[i] >= 0)
          differential[n + i] = 0.0;
      return differential;
    }



    template <int dim>
    void
    Model<dim>::VariableOrder::prescribed_velocities(const double t)
    {
      // IDA takes no steps of the model's: a prescribed displacement's rate is the mean
      // velocity of a step of 1e-8 of the end time from t (truncation and round-off of
      // about that order).
      const double h = 1e-8 * std::max(m.scene().time_control().end_time, 1e-300);
      for (unsigned int i = 0; i < n; ++i)
        w[i] = m.dof_set[i] >= 0 ? m.prescribed_velocity(m.dirichlet[m.dof_set[i]], i, t, h) : 0.0;
    }



    template <int dim>
    int
    Model<dim>::VariableOrder::residual(const double t, const ConstView y, const ConstView yp, const View F)
    {
      prescribed_velocities(t);
      m.external_forces(t, f_ext);
      const double a0 = m.dynamics.rayleigh_mass, a1 = m.dynamics.rayleigh_stiffness;
      std::fill(F.begin(), F.end(), 0.0);
      // Kinematics.
      for (unsigned int i = 0; i < n; ++i)
        if (m.dof_set[i] < 0)
          F[i] = yp[i] - y[n + i];
        else
          {
            F[i]     = yp[i] - w[i];
            F[n + i] = y[n + i] - w[i];
          }

      // reaction = M (v' + a0 v) + f_int + a1 K0 v - f_ext on every DoF.
      reaction = 0;
      for (unsigned int i = 0; i < n; ++i)
        reaction(i) -= f_ext.local_element(i);
      dealii::FullMatrix<double> M(n_dofs, n_dofs);
      for (unsigned int c = 0; c < m.n_owned_cells; ++c)
        {
          m.cell_mass_matrix(c, M);
          for (unsigned int p = 0; p < n_dofs; ++p)
            for (unsigned int q = 0; q < n_dofs; ++q)
              reaction(n_dofs * c + p) += M(p, q) * (yp[n + n_dofs * c + q] + a0 * y[n + n_dofs * c + q]);
        }
      // The damping's power v . C v: a0 v^T M v of the cells, a1 k delta'^2 of the springs.
      double power_int = 0, power_ext = 0, power_bnd = 0, power_damp = 0;
      for (unsigned int c = 0; c < m.n_owned_cells && a0 > 0; ++c)
        {
          m.cell_mass_matrix(c, M);
          for (unsigned int p = 0; p < n_dofs; ++p)
            for (unsigned int q = 0; q < n_dofs; ++q)
              power_damp += a0 * y[n + n_dofs * c + p] * M(p, q) * y[n + n_dofs * c + q];
        }
      std::array<double, 2 * n_dofs> U, V;
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        {
          const Springs<dim> &sp   = m.springs[e];
          const auto          dofs = facet_dofs(e);
          for (unsigned int k = 0; k < 2 * n_dofs; ++k)
            {
              U[k] = y[dofs[k]];
              V[k] = y[n + dofs[k]];
            }
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              const double delta = sp.deformation(i, U), rate = sp.deformation(i, V);
              double       force = sp.k[i] * delta;
              if (sp.hysteretic)
                {
                  // F = a k delta + (1 - a) k z, and s' = R(s, delta').
                  const auto        &spring = law(e, i);
                  const unsigned int s0 = s_index(e, i), k = spring.n_state_variables();
                  double             state[Material::BoucWenUniaxial::max_n_state_variables], R[3];
                  for (unsigned int j = 0; j < k; ++j)
                    state[j] = y[s0 + j];
                  force = spring.stress(delta, state);
                  spring.state_rate(state, rate, R);
                  for (unsigned int j = 0; j < k; ++j)
                    F[s0 + j] = yp[s0 + j] - R[j];
                }
              power_int += force * rate;
              power_damp += a1 * sp.k[i] * rate * rate;
              const double total = force + a1 * sp.k[i] * rate;
              for (unsigned int k = 0; k < 2 * n_dofs; ++k)
                reaction(dofs[k]) += sp.B[i][k] * total;
            }
        }
      for (unsigned int i = 0; i < n; ++i)
        {
          power_ext += f_ext.local_element(i) * y[n + i];
          if (m.dof_set[i] < 0)
            F[n + i] = reaction(i);
          else
            power_bnd += reaction(i) * w[i];
        }
      const unsigned int iw = 2 * n + n_states;
      F[iw]     = yp[iw] - power_int;
      F[iw + 1] = yp[iw + 1] - power_ext;
      F[iw + 2] = yp[iw + 2] - power_bnd;
      F[iw + 3] = yp[iw + 3] - power_damp;
      return all_finite(F) ? 0 : 1;
    }



    template <int dim>
    int
    Model<dim>::VariableOrder::setup_jacobian(const ConstView y, const double cj)
    {
      const double a0 = m.dynamics.rayleigh_mass, a1 = m.dynamics.rayleigh_stiffness;
      jacobian = 0;
      for (unsigned int i = 0; i < n; ++i)
        {
          jacobian.add(i, i, cj);
          if (m.dof_set[i] < 0)
            jacobian.add(i, n + i, -1.0);
          else
            jacobian.add(n + i, n + i, 1.0);
        }
      // The prescribed DoFs' v rows are v_i - w_i(t): only the rows of free DoFs get
      // the equation of motion's derivatives.
      const auto free = [&](const unsigned int i) { return m.dof_set[i] < 0; };
      dealii::FullMatrix<double> M(n_dofs, n_dofs);
      for (unsigned int c = 0; c < m.n_owned_cells; ++c)
        {
          m.cell_mass_matrix(c, M);
          for (unsigned int p = 0; p < n_dofs; ++p)
            if (free(n_dofs * c + p))
              for (unsigned int q = 0; q < n_dofs; ++q)
                jacobian.add(n + n_dofs * c + p, n + n_dofs * c + q, (cj + a0) * M(p, q));
        }
      std::array<double, 2 * n_dofs> V; // the facet's velocities (the rates' derivatives)
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        {
          const Springs<dim> &sp   = m.springs[e];
          const auto          dofs = facet_dofs(e);
          for (unsigned int k = 0; k < 2 * n_dofs; ++k)
            V[k] = y[n + dofs[k]];
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              // dF/d delta = a k (the z part is a state of its own), dF/dz = (1 - a) k.
              const double a  = sp.hysteretic ? law(e, i).parameters().post_yield_ratio : 1.0;
              const double ka = a * sp.k[i], kv = a1 * sp.k[i], kz = (1 - a) * sp.k[i];
              for (unsigned int p = 0; p < 2 * n_dofs; ++p)
                if (free(dofs[p]))
                  for (unsigned int q = 0; q < 2 * n_dofs; ++q)
                    {
                      const double BB = sp.B[i][p] * sp.B[i][q];
                      jacobian.add(n + dofs[p], dofs[q], ka * BB);
                      if (kv != 0)
                        jacobian.add(n + dofs[p], n + dofs[q], kv * BB);
                    }
              if (!sp.hysteretic)
                continue;
              const auto        &spring = law(e, i);
              const unsigned int s0 = s_index(e, i), k = spring.n_state_variables();
              for (unsigned int p = 0; p < 2 * n_dofs; ++p)
                if (free(dofs[p]))
                  jacobian.add(n + dofs[p], s0, sp.B[i][p] * kz);
              // s' - R(s, B_i v): c_j I - dR/ds, and -dR/d delta' B_i in the v columns.
              double state[3], dR_ds[9], dR_dr[3];
              for (unsigned int j = 0; j < k; ++j)
                state[j] = y[s0 + j];
              spring.state_rate_derivatives(state, sp.deformation(i, V), dR_ds, dR_dr);
              for (unsigned int r = 0; r < k; ++r)
                {
                  for (unsigned int j = 0; j < k; ++j)
                    jacobian.add(s0 + r, s0 + j, (r == j ? cj : 0.0) - dR_ds[r * k + j]);
                  for (unsigned int q = 0; q < 2 * n_dofs; ++q)
                    if (sp.B[i][q] != 0)
                      jacobian.add(s0 + r, n + dofs[q], -dR_dr[r] * sp.B[i][q]);
                }
            }
        }
      for (unsigned int j = 2 * n + n_states; j < n_total; ++j)
        jacobian.add(j, j, cj);
      try
        {
          direct.factorize(jacobian);
        }
      catch (const std::runtime_error &)
        {
          return -1; // singular: an unsupported network (IDA stops, run() reports it)
        }
      return 0;
    }



    template <int dim>
    int
    Model<dim>::VariableOrder::solve(const ConstView rhs, const View x)
    {
      std::copy(rhs.begin(), rhs.end(), lu_rhs.begin());
      try
        {
          direct.solve(lu_x, lu_rhs);
        }
      catch (const std::runtime_error &)
        {
          return 1; // recoverable: IDA retries with a smaller step
        }
      std::copy(lu_x.begin(), lu_x.end(), x.begin());
      return all_finite(x) ? 0 : 1;
    }



    template <int dim>
    void
    Model<dim>::VariableOrder::initial_values(Vector &y, Vector &yp)
    {
      // y(0): the model's initial state, the prescribed velocities w(0); y'(0): the
      // rates of the residual at y' = 0 (F = y' - rate for u, s and W), the
      // accelerations of initial_state() (M a = f_ext - f_int - C v on the free DoFs).
      prescribed_velocities(0);
      y.reinit(n_total);
      yp.reinit(n_total);
      for (unsigned int i = 0; i < n; ++i)
        {
          y(i)     = m.u.local_element(i);
          y(n + i) = m.dof_set[i] < 0 ? m.v.local_element(i) : w[i];
        }
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        if (state_offset[n_dofs * e] >= 0)
          for (unsigned int i = 0; i < n_dofs; ++i)
            for (unsigned int j = 0; j < law(e, i).n_state_variables(); ++j)
              y(s_index(e, i) + j) = m.springs[e].state[facet_offset(e, i) + j];
      const unsigned int iw = 2 * n + n_states;
      y(iw)     = m.internal_work;
      y(iw + 1) = m.external_work;
      y(iw + 2) = m.boundary_work;
      y(iw + 3) = m.damping_work;
      Vector F(n_total);
      residual(0, dealii::make_array_view(y), dealii::make_array_view(yp), dealii::make_array_view(F));
      for (unsigned int j = 0; j < n_total; ++j)
        yp(j) = j >= n && j < 2 * n ? (m.dof_set[j - n] < 0 ? m.a.local_element(j - n) : 0.0) : -F(j);
    }



    template <int dim>
    void
    Model<dim>::VariableOrder::to_model(const double t, const Vector &y, const Vector &yp)
    {
      // The residual leaves reaction = f_int + M v' + C v - f_ext and f_ext at t.
      Vector F(n_total);
      residual(t, dealii::make_array_view(y), dealii::make_array_view(yp), dealii::make_array_view(F));
      m.f_ext = f_ext;
      m.f_ext_old = f_ext; // the converged external force (history tables)
      std::array<double, 2 * n_dofs> U;
      for (unsigned int i = 0; i < n; ++i)
        {
          m.u.local_element(i) = y(i);
          m.v.local_element(i) = y(n + i);
          m.a.local_element(i) = yp(n + i);
        }
      for (unsigned int e = 0; e < m.springs.size(); ++e)
        {
          Springs<dim> &sp   = m.springs[e];
          const auto    dofs = facet_dofs(e);
          for (unsigned int k = 0; k < 2 * n_dofs; ++k)
            U[k] = y(dofs[k]);
          for (unsigned int i = 0; i < n_dofs; ++i)
            {
              sp.delta[i] = sp.deformation(i, U);
              if (sp.hysteretic)
                {
                  const auto &spring = law(e, i);
                  for (unsigned int j = 0; j < spring.n_state_variables(); ++j)
                    sp.state[facet_offset(e, i) + j] = y(s_index(e, i) + j);
                  sp.force[i] = spring.stress(sp.delta[i], sp.state.data() + facet_offset(e, i));
                }
              else
                sp.force[i] = sp.k[i] * sp.delta[i];
            }
          sp.trial_delta = sp.delta;
          sp.trial_force = sp.force;
          sp.trial_state = sp.state;
        }
      // The output's reactions: f_int + M v' + C v - f_ext.
      for (unsigned int i = 0; i < n; ++i)
        m.reaction_old.local_element(i) = reaction(i);
      m.u_trial = m.u;
      const unsigned int iw = 2 * n + n_states;
      m.internal_work       = y(iw);
      m.external_work       = y(iw + 1);
      m.boundary_work       = y(iw + 2);
      m.damping_work        = y(iw + 3);
    }

    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
