#include "cell_kernels.h"

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    CellKernels<dim>::converged_state_terms(const CellHistory<dim> &h, CellScratch<dim> &scratch) const
    {
      // The mass of the reference configuration; the damping's K0 in the step's (midpoint)
      // configuration and f_int(u_n) in the converged one. Axisymmetric: the hoop terms of
      // both with Hooke's law (S = H = lambda I, C_tt = lambda + 2 mu).
      using namespace dealii;
      const FEValues<dim> &fv = scratch.fv;
      const auto          &fs = scratch.finite;
      auto                &d  = scratch.dynamics;
      const auto          &B  = scratch.B;
      const double         rho = h.material->density();
      d.M                      = 0;
      d.K0                     = 0;
      const SymmetricTensor<4, dim> D  = h.material->elasticity().template stiffness<dim>();
      const auto                   &el = h.material->elasticity();
      Material::HoopTangent<dim>    elastic;
      elastic.stress_by_hoop = el.lame_lambda() * unit_symmetric_tensor<dim>();
      elastic.hoop_by_strain = elastic.stress_by_hoop;
      elastic.hoop_by_hoop   = el.lame_lambda() + 2.0 * el.shear_modulus();
      const bool damping     = solver.dynamics.rayleigh_stiffness > 0;
      d.fi0                  = 0;
      for (unsigned int q = 0; q < n_q; ++q)
        {
          const double w = h.weight[q];
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              if (comp[i] == comp[j])
                d.M(i, j) += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * w;
          const double wK = finite_strain ? fs.wm[q] : w;
          if (damping)
            for (unsigned int j = 0; j < n; ++j)
              {
                const SymmetricTensor<2, dim> DB = D * B[q][j];
                for (unsigned int i = 0; i < n; ++i)
                  d.K0(i, j) += (B[q][i] * DB) * wK;
              }
          if (finite_strain)
            for (unsigned int i = 0; i < n; ++i)
              d.fi0[i] += (b_bar ? fs.B0[q][i] * h.stress[q] : component_gradient(comp[i], fs.G0[q][i]) * h.stress[q]) *
                          fs.w0[q];
          else
            for (unsigned int i = 0; i < n; ++i)
              d.fi0[i] += (B[q][i] * h.stress[q]) * w;
          if (axisymmetric)
            add_hoop_terms(elastic, h, q, false, scratch, damping ? &d.K0 : nullptr, d.fi0);
        }
    }



    template <int dim>
    void
    CellKernels<dim>::hht_terms(const CellIterator     &cell,
                                const CellHistory<dim> &h,
                                CellScratch<dim>       &scratch,
                                CellCopy               &copy) const
    {
      // r = M a1 + (1 + alpha)(C v1 + f_int(u1) - f_ext(t1)) - alpha (C v0 + f_int(u0) - f_ext(t0)),
      // dr/du1 = M / (beta dt^2) + (1 + alpha) gamma / (beta dt) C + (1 + alpha) K,
      // with the Newmark a1, v1 of the cell's nodes and C = a0 M + a1 K0 + C_b (C_b: the
      // dashpots of the cell's absorbing faces, absorbing.cc).
      const auto &rayleigh = solver.dynamics;
      auto       &d        = scratch.dynamics;
      const auto &du       = scratch.du;
      converged_state_terms(h, scratch);
      external_forces(cell, h, body0, load0, d.fx0, scratch);
      for (unsigned int i = 0; i < n; ++i)
        {
          d.v0[i] = solver.v_ghost(copy.dofs[i]);
          d.a0[i] = solver.a_ghost(copy.dofs[i]);
          d.a1[i] = (du[i] - dt * d.v0[i]) / (beta * dt * dt) - (1 - 2 * beta) / (2 * beta) * d.a0[i];
          d.v1[i] = d.v0[i] + dt * ((1 - gamma) * d.a0[i] + gamma * d.a1[i]);
        }
      d.M.vmult(copy.Mv, d.a1);
      d.M.vmult(d.Cv0, d.v0);
      d.M.vmult(d.Cv1, d.v1);
      d.Cv0 *= rayleigh.rayleigh_mass;
      d.Cv1 *= rayleigh.rayleigh_mass;
      if (rayleigh.rayleigh_stiffness > 0)
        {
          d.K0.vmult(d.tmp, d.v0);
          d.Cv0.add(rayleigh.rayleigh_stiffness, d.tmp);
          d.K0.vmult(d.tmp, d.v1);
          d.Cv1.add(rayleigh.rayleigh_stiffness, d.tmp);
        }
      const bool absorbing = solver.absorbing_matrix(cell, scratch.ffv, d.Cb);
      if (absorbing)
        {
          d.Cb.vmult(d.Cv0, d.v0, true);
          d.Cb.vmult(d.Cv1, d.v1, true);
        }
      for (unsigned int i = 0; i < n; ++i)
        copy.r[i] = copy.Mv[i] + (1 + alpha) * (d.Cv1[i] + copy.fi[i] - copy.fx[i]) -
                    alpha * (d.Cv0[i] + d.fi0[i] - d.fx0[i]);
      if (matrix)
        {
          const double c_M  = 1 / (beta * dt * dt) + (1 + alpha) * gamma / (beta * dt) * rayleigh.rayleigh_mass;
          const double c_K0 = (1 + alpha) * gamma / (beta * dt) * rayleigh.rayleigh_stiffness;
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              copy.A(i, j) = (1 + alpha) * copy.A(i, j) + c_M * d.M(i, j) + c_K0 * d.K0(i, j);
          if (absorbing)
            copy.A.add((1 + alpha) * gamma / (beta * dt), d.Cb);
        }
      for (unsigned int i = 0; i < n; ++i)
        copy.Mv[i] += d.Cv1[i];
    }



    template class CellKernels<2>;
    template class CellKernels<3>;
  } // namespace FEM
} // namespace hysteron
