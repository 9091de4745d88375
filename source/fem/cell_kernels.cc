#include <hysteron/base/exceptions.h>

#include "cell_kernels.h"

#include <chrono>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    CellKernels<dim>::CellKernels(const Solver<dim> &solver,
                                  const Scene<dim>  &scene,
                                  const Vector      &u_iterate,
                                  const double       t1,
                                  const double       dt,
                                  const bool         matrix,
                                  const bool         update_material)
      : matrix(matrix)
      , dynamic(solver.analysis == Analysis::implicit_dynamics && dt > 0)
      , load1(solver.load_sets.size())
      , load0(solver.load_sets.size())
      , solver(solver)
      , scene(scene)
      , u_iterate(u_iterate)
      , t1(t1)
      , dt(dt)
      , update_material(update_material)
      , finite_strain(solver.finite_strain)
      , b_bar(solver.b_bar)
      , axisymmetric(scene.axisymmetric())
      , alpha(solver.dynamics.hht_alpha)
      , beta(solver.dynamics.beta())
      , gamma(solver.dynamics.gamma())
      , n(solver.fe->n_dofs_per_cell())
      , n_q(solver.quadrature->size())
      , comp(n)
    {
      for (unsigned int i = 0; i < n; ++i)
        comp[i] = solver.fe->system_to_component_index(i).first;
      // Body force densities and tractions at t1 (and t0 for HHT).
      const double t0    = t1 - dt;
      const auto  &loads = scene.load_descriptions();
      body1              = scene.body_acceleration(t1);
      body0              = scene.body_acceleration(t0);
      for (unsigned int l = 0; l < solver.load_sets.size(); ++l)
        {
          load1[l] = loads[solver.load_sets[l].load].value_at(t1) * solver.load_sets[l].scale;
          if (dynamic)
            load0[l] = loads[solver.load_sets[l].load].value_at(t0) * solver.load_sets[l].scale;
        }
    }



    template <int dim>
    void
    CellKernels<dim>::assemble(const CellIterator &cell, CellScratch<dim> &scratch, CellCopy &copy) const
    {
      copy.active = copy.failed = false;
      copy.Mv                   = 0;
      scratch.fv.reinit(cell);
      cell->get_dof_indices(copy.dofs);
      copy.active         = true;
      CellHistory<dim> &h = *solver.cell_history[cell->active_cell_index()];
      for (unsigned int i = 0; i < n; ++i)
        scratch.du[i] = u_iterate(copy.dofs[i]) - solver.u_ghost(copy.dofs[i]);

      if (finite_strain)
        {
          if (!finite_strain_kinematics(cell, h, scratch, copy))
            return;
        }
      else
        small_strain_operator(scratch.fv, h.weight, b_bar, scratch.B);
      strain_increments(scratch, h);
      if (!update_material_points(cell, h, scratch, copy))
        return;

      copy.fi = 0;
      if (matrix)
        copy.A = 0;
      if (finite_strain)
        finite_strain_forces(h, scratch, copy);
      else
        small_strain_forces(h, scratch, copy);
      external_forces(cell, h, body1, load1, copy.fx, scratch);
      if (dynamic)
        hht_terms(cell, h, scratch, copy);
      else
        for (unsigned int i = 0; i < n; ++i)
          copy.r[i] = copy.fi[i] - copy.fx[i];
      copy.r *= -1.0;
    }



    template <int dim>
    void
    CellKernels<dim>::strain_increments(CellScratch<dim> &scratch, CellHistory<dim> &h) const
    {
      // d eps = sum_i du_i B_i; axisymmetric: d eps_tt = du_r / r.
      const auto &du = scratch.du;
      for (unsigned int q = 0; q < n_q; ++q)
        {
          dealii::SymmetricTensor<2, dim> e;
          for (unsigned int i = 0; i < n; ++i)
            if (du[i] != 0)
              e += du[i] * scratch.B[q][i];
          h.increment[q] = e;
          if (axisymmetric)
            {
              double u_r = 0;
              for (unsigned int i = 0; i < n; ++i)
                if (comp[i] == 0 && du[i] != 0)
                  u_r += du[i] * scratch.fv.shape_value(i, q);
              h.hoop_increment[q] = u_r / h.point[q][0];
            }
        }
    }



    template <int dim>
    bool
    CellKernels<dim>::update_material_points(const CellIterator     &cell,
                                             CellHistory<dim>       &h,
                                             const CellScratch<dim> &scratch,
                                             CellCopy               &copy) const
    {
      using namespace dealii;
      // From the converged state to the trial state; updated Lagrangian: between the two
      // halves of the Jaumann rotation of the stress and the material's tensor state (the
      // tangent is turned where it is used).
      h.trial_stress = h.stress;
      h.trial_state  = h.state;
      if (finite_strain)
        rotate_trial_state(h, h.stress, scratch.finite.R);
      const auto material_start = std::chrono::steady_clock::now();
      if (update_material)
        try
          {
            if (axisymmetric)
              h.material->update_axisymmetric(
                make_array_view(std::as_const(h.increment)),
                make_array_view(std::as_const(h.hoop_increment)),
                make_array_view(h.trial_stress),
                make_array_view(h.trial_state),
                matrix ? make_array_view(h.tangent) : ArrayView<SymmetricTensor<4, dim>>(),
                matrix ? make_array_view(h.hoop_tangent) : ArrayView<Material::HoopTangent<dim>>());
            else
              h.material->update(make_array_view(std::as_const(h.increment)),
                                 make_array_view(h.trial_stress),
                                 make_array_view(h.trial_state),
                                 matrix ? make_array_view(h.tangent) : ArrayView<SymmetricTensor<4, dim>>());
          }
        catch (const RuntimeError &e)
          {
            copy.failed = true;
            std::ostringstream m;
            m << e.what() << " (in the cell at " << cell->center() << ", body '"
              << scene.body_descriptions()[h.body].name << "', step to t = " << t1 << " s)";
            copy.message = m.str();
          }
      copy.material_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - material_start).count();
      if (copy.failed)
        return false;
      if (finite_strain)
        rotate_trial_state(h, h.trial_stress, scratch.finite.R);
      return true;
    }



    // Shape function i moves component c_i only, with the gradient g_i of its scalar shape
    // function: B_i = sym(e_{c_i} (x) g_i), so (with the minor symmetries of sigma and C)
    // B_i : sigma = sigma_{c_i b} g_i[b] and B_i : C : B_j = g_i[b] C_{c_i b c_j d} g_j[d],
    // dim^2 products per pair instead of a contraction of two symmetric tensors.
    template <int dim>
    void
    CellKernels<dim>::add_component_forces(const std::vector<dealii::Tensor<1, dim>> &G,
                                           const dealii::SymmetricTensor<2, dim>     &s,
                                           const double                               w,
                                           dealii::Vector<double>                    &fi) const
    {
      for (unsigned int i = 0; i < n; ++i)
        {
          double v = 0;
          for (unsigned int b = 0; b < dim; ++b)
            v += s[comp[i]][b] * G[i][b];
          fi[i] += v * w;
        }
    }



    template <int dim>
    void
    CellKernels<dim>::add_component_tangent(const std::vector<dealii::Tensor<1, dim>> &G,
                                            const std::vector<double>                 &H,
                                            dealii::FullMatrix<double>                &A) const
    {
      // H_j[c][b] = w C_{c b c_j d} g_j[d] (or its updated-Lagrangian form) at H[(j dim + c) dim + b].
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int j = 0; j < n; ++j)
          {
            const double *hj = &H[(j * dim + comp[i]) * dim];
            double        v  = 0;
            for (unsigned int b = 0; b < dim; ++b)
              v += G[i][b] * hj[b];
            A(i, j) += v;
          }
    }



    template <int dim>
    void
    CellKernels<dim>::add_b_bar_terms(const std::vector<dealii::SymmetricTensor<2, dim>> &Bf,
                                      const std::vector<dealii::SymmetricTensor<2, dim>> &B,
                                      const CellHistory<dim>                             &h,
                                      const unsigned int                                  q,
                                      const dealii::Tensor<2, dim>                       *R,
                                      const double                                        w,
                                      CellCopy                                           &copy) const
    {
      // The B-bar matrices are not those of one component: contract in full.
      const dealii::SymmetricTensor<2, dim> &s = h.trial_stress[q];
      for (unsigned int i = 0; i < n; ++i)
        copy.fi[i] += (Bf[i] * s) * w;
      if (matrix)
        for (unsigned int j = 0; j < n; ++j)
          {
            dealii::SymmetricTensor<2, dim> CB = h.tangent[q] * B[j];
            if (R)
              CB = dealii::symmetrize(*R * dealii::Tensor<2, dim>(CB) * dealii::transpose(*R));
            for (unsigned int i = 0; i < n; ++i)
              copy.A(i, j) += (Bf[i] * CB) * w;
          }
    }



    template class CellKernels<2>;
    template class CellKernels<3>;
  } // namespace FEM
} // namespace hysteron
