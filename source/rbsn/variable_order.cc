#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <hysteron/base/parameters.h>
#include "base/ida_integrator.h"
#include "base/sparse_lu.h"
#include <hysteron/rbsn/model.h>
#include <hysteron/run/stepping_method.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

/*
 * Analysis = variable order: the state-space form of eq. 3.43-3.48 as an
 * implicit DAE F(t, y, y') = 0 in y = (u, v, s, W), integrated by SUNDIALS IDA
 * (variable-order, variable-step BDF with local error control; base/ida_integrator.h).
 * With n = 3 (2D) or 6 (3D) DoFs per cell, s the Bouc-Wen states of the hysteretic
 * springs (z, and eta, e_h with degradation), and W three work quadratures:
 *
 *   free DoF i:        u_i' - v_i = 0,
 *                      (M v' + C v + f_int(u, s) - f_ext(t))_i = 0,
 *   prescribed DoF i:  u_i' - w_i(t) = 0,   v_i - w_i(t) = 0   (algebraic),
 *   spring states:     s' - R(s, delta') = 0,   delta' = B v   (the Bouc-Wen rates),
 *   works:             W_int' = f_int . v,  W_ext' = f_ext . v,  W_bnd' = r . w,
 *
 * with M the cell mass matrices (eq. 3.12), C = a0 M + a1 K0 (K0: the elastic
 * springs, as in the Newmark analysis), f_int = sum_e B^T F, F_i = a k delta_i +
 * (1 - a) k z_i (linear springs: k delta_i), w the prescribed velocities and r
 * the reactions f_int + M v' + C v - f_ext on the prescribed DoFs. IDA's Newton
 * matrix dF/dy + c_j dF/dy' is assembled exactly (the quadratures' rows keep only
 * c_j: they do not feed back) and factorised by UMFPACK. Fracture is refused at
 * parse time: a break is a discontinuity of the right-hand side.
 */

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
    void
    Model<dim>::declare_variable_order_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Variable order");
      {
        prm.declare_entry("Relative tolerance",
                          "1e-6",
                          Patterns::Double(),
                          "IDA's relative tolerance of the local error, in (0, 1).");
        prm.declare_entry("Absolute tolerance",
                          "0",
                          Patterns::Double(),
                          "IDA's absolute tolerance [m] on the displacements, >= 0; 0: the relative "
                          "tolerance times 1e-3 of the network's size. Rotations and the rotational "
                          "springs' z get it divided by the network's size, velocities divided by "
                          "the output interval (Time step), eta the relative tolerance, e_h it times "
                          "the spring's yield force, the work quadratures 1e-2 k_n atol^2 / rtol (k_n: the "
                          "stiffest normal spring).");
        prm.declare_entry("Maximum order", "5", Patterns::Integer(), "Of the BDF, 1..5.");
        prm.declare_entry("Maximum step", "0", Patterns::Double(), "[s], >= 0; 0: unlimited.");
        prm.declare_entry("Initial step", "0", Patterns::Double(), "[s], >= 0; 0: IDA's estimate.");
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Model<dim>::parse_variable_order_parameters(dealii::ParameterHandler &prm)
    {
      Section s(prm, {"RBSN", "Variable order"});
      auto   &p            = variable_order;
      p.relative_tolerance = s.get_in_open_interval("Relative tolerance", 0, 1);
      p.absolute_tolerance = s.get_non_negative("Absolute tolerance");
      const long order     = s.get_integer("Maximum order");
      require(order >= 1 && order <= 5, s.where("Maximum order"),
              "must be 1, 2, 3, 4 or 5 (got " + s.get("Maximum order") + ")");
      p.maximum_order = order;
      p.maximum_step  = s.get_non_negative("Maximum step");
      p.initial_step  = s.get_non_negative("Initial step");
      require(p.maximum_step == 0 || p.initial_step <= p.maximum_step, s.where("Initial step"),
              "must not exceed the Maximum step (got " + s.get("Initial step") + " > " +
                s.get("Maximum step") + ")");
      if (analysis == Analysis::variable_order)
        require(!fracture.enabled, "RBSN/Fracture/Enabled",
                "the variable-order analysis has no fracture (a break is a discontinuity of the "
                "DAE that IDA integrates): use Analysis = implicit dynamics, or switch fracture off");
      if (analysis == Analysis::variable_order)
        {
          const std::string why = spring_law->variable_order_unsupported();
          require(why.empty(), "RBSN/Spring law", why);
        }
    }



    /// The DAE of the variable-order analysis and its Newton matrix (see the top of the file).
    template <int dim>
    class Model<dim>::VariableOrder
    {
    public:
      // IDA's vectors: the whole network on every rank.
      using Vector    = dealii::Vector<double>;
      using ConstView = IdaIntegrator::ConstView;
      using View      = IdaIntegrator::View;
      static constexpr unsigned int n_dofs = Model<dim>::n_dofs;

      explicit VariableOrder(Model<dim> &model);

      /// F(t, y, y'); returns 0, or 1 (recoverable: IDA retries with a smaller step).
      int
      residual(const double t, const ConstView y, const ConstView yp, const View F);
      /// Assemble dF/dy + cj dF/dy' at y (it does not depend on t and y') and factorise it.
      int
      setup_jacobian(const ConstView y, const double cj);
      /// x = J^-1 rhs with the factorisation of the last setup_jacobian().
      int
      solve(const ConstView rhs, const View x);

      /// The initial y and a consistent y' from the model's initial state.
      void
      initial_values(Vector &y, Vector &yp);
      /// y (and y') into the model's vectors and springs, for its output.
      void
      to_model(const double t, const Vector &y, const Vector &yp);

      /// Per component: 1 differential, 0 algebraic (the prescribed DoFs' velocities).
      std::vector<double>
      differential_components() const;

      std::vector<double> tolerances; ///< IDA's absolute tolerances

    private:
      Model<dim>  &m;
      unsigned int n = 0, n_states = 0, n_total = 0;
      /// Per spring (index 3 e + i): the offset of its Bouc-Wen state within s, -1 if linear.
      std::vector<int>              state_offset;
      /// Per spring (index 3 e + i) of a hysteretic facet: its uniaxial law and the
      /// offset of its state in the facet's state (SpringLaw<2>::uniaxial_spring()).
      std::vector<typename SpringLaw<dim>::UniaxialSpring> uniaxial;
      std::vector<double>           w; ///< prescribed velocities at the last t
      Vector                        reaction;
      Vector                        lu_rhs, lu_x; ///< the direct solver's vectors
      typename Model<dim>::Vector   f_ext; ///< the model's layout (one part: all DoFs)
      dealii::SparsityPattern       pattern;
      dealii::SparseMatrix<double>  jacobian;
      SparseLU                      direct; ///< the symbolic analysis kept over the Jacobians

      const Material::BoucWenUniaxial &
      law(const unsigned int e, const unsigned int i) const
      {
        return *uniaxial[n_dofs * e + i].law;
      }
      /// Spring i's state in the facet's state.
      unsigned int
      facet_offset(const unsigned int e, const unsigned int i) const
      {
        return uniaxial[n_dofs * e + i].offset;
      }
      unsigned int
      s_index(const unsigned int e, const unsigned int i) const
      {
        return 2 * n + state_offset[n_dofs * e + i];
      }
      void
      prescribed_velocities(const double t);
      /// The facet's DoF indices (a's, then b's).
      std::array<unsigned int, 2 * n_dofs>
      facet_dofs(const unsigned int e) const
      {
        return m.facet_local_dofs(e);
      }
    };



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
      n_total = 2 * n + n_states + 3;
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
                           m.scene.time_control().time_step > 0 ? m.scene.time_control().time_step :
                                                                  m.scene.time_control().end_time / m.n_increments;
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
      for (unsigned int i = 0; i < n; ++i)
        w[i] = m.dof_set[i] >= 0 ? m.prescribed_velocity(m.dirichlet[m.dof_set[i]], i, t) : 0.0;
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
      double power_int = 0, power_ext = 0, power_bnd = 0;
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
    }



    template <int dim>
    double
    Model<dim>::integrate_variable_order(const double                       output_interval,
                                         const std::function<void(double)> &step_finished)
    {
      const auto  &p        = variable_order;
      const double end_time = scene.time_control().end_time;
      VariableOrder dae(*this);
      dealii::Vector<double> y, yp;
      dae.initial_values(y, yp);

      IdaIntegrator::Settings settings;
      settings.relative_tolerance  = p.relative_tolerance;
      settings.absolute_tolerances = dae.tolerances;
      settings.differential        = dae.differential_components();
      // The prescribed velocities (algebraic) stay out of the error test.
      settings.suppress_algebraic_errors = true;
      settings.initial_step              = p.initial_step;
      settings.maximum_step              = p.maximum_step;
      settings.stop_time                 = end_time;
      settings.maximum_order             = p.maximum_order;
      settings.maximum_newton_iterations = 10; // IDA's default is 4
      settings.maximum_steps             = 1000000;
      IdaIntegrator ida(settings, 0, dealii::make_array_view(y), dealii::make_array_view(yp));
      ida.residual = [&](const double t, const auto values, const auto rates, const auto F) {
        return dae.residual(t, values, rates, F);
      };
      ida.setup_jacobian = [&](const double, const auto values, const auto, const double cj) {
        return dae.setup_jacobian(values, cj);
      };
      ida.solve_jacobian = [&](const auto rhs, const auto x) { return dae.solve(rhs, x); };

      // The output times are sums of output intervals, which accumulate round-off: the
      // tables get the nominal time k output_interval, and a last interval of round-off
      // length is not written again. t = 0 is written by run().
      const double eps = 1e-12 * end_time;
      double       t = 0, t_out = 0, last_good = 0;
      for (unsigned int k = 1; t < end_time; ++k)
        {
          t_out += output_interval;
          const bool   reached  = ida.advance(t_out, t);
          const double expected = std::min(k * output_interval, end_time);
          const auto   stats    = ida.statistics();
          n_steps               = stats.steps;
          n_newton              = stats.newton_iterations;
          if (!reached || std::abs(t - expected) > eps)
            {
              std::ostringstream s;
              s << "rbsn: IDA did not reach t = " << expected << " s (it stopped at t = " << stats.time
                << " s with the step " << stats.step << " s after " << stats.steps << " steps, "
                << stats.error_test_failures << " error test and " << stats.convergence_failures
                << " convergence failures): a stiff or non-smooth response beyond the tolerances, an "
                << "unsupported network, or too many steps (1e6 per output interval).";
              if (!ida.error().empty())
                s << " IDA: " << ida.error();
              throw Run::StepFailure(s.str());
            }
          if (expected - last_good < eps)
            continue;
          dae.to_model(expected, y, yp);
          last_good = expected;
          if (newton_table)
            newton_table->add_row({expected, double(stats.steps), double(stats.order), stats.step,
                                   double(stats.residuals), double(stats.jacobians),
                                   double(stats.newton_iterations), double(stats.error_test_failures),
                                   double(stats.convergence_failures)});
          step_finished(expected);
        }
      return end_time;
    }

    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron
