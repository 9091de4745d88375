#include "cell_kernels.h"

#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /**
       * Half of the Hughes-Winget rotation (I - W/2)^{-1} (I + W/2) of the spin W: that
       * rotation turns about the axial vector w of W by 2 atan(|w|/2), so its half turns by
       * a = atan(|w|/2), by Rodrigues' formula R = I + (sin a / |w|) W + (2 sin^2(a/2) / |w|^2) W^2
       * (in 2D W^2 = -|w|^2 I and R is the plane rotation by a). |W|_F = sqrt(2) |w|.
       */
      template <int dim>
      dealii::Tensor<2, dim>
      half_rotation(const dealii::Tensor<2, dim> &W)
      {
        const double w  = W.norm() / std::sqrt(2.0);
        const double a  = std::atan(0.5 * w);
        const double s1 = w > 0 ? std::sin(a) / w : 0.5;
        const double s2 = w > 0 ? 2.0 * dealii::Utilities::fixed_power<2>(std::sin(0.5 * a) / w) : 0.125;
        return dealii::Tensor<2, dim>(dealii::unit_symmetric_tensor<dim>()) + s1 * W + s2 * (W * W);
      }
    } // namespace



    template <int dim>
    bool
    CellKernels<dim>::finite_strain_kinematics(const CellIterator &cell,
                                               CellHistory<dim>   &h,
                                               CellScratch<dim>   &scratch,
                                               CellCopy           &copy) const
    {
      // F = I + grad_X u in the converged (0), trial (1) and midpoint (m) configurations,
      // the gradients and volumes there, L = grad_X du F_m^{-1}, R_h and P = I - L/2.
      using namespace dealii;
      const dealii::FEValues<dim> &fv = scratch.fv;
      const auto                  &du = scratch.du;
      auto                        &fs = scratch.finite;
      auto                        &B  = scratch.B;
      for (unsigned int i = 0; i < n; ++i)
        fs.u0[i] = solver.u_ghost(copy.dofs[i]);
      const Tensor<2, dim> I = unit_symmetric_tensor<dim>();
      for (unsigned int q = 0; q < n_q; ++q)
        {
          Tensor<2, dim> grad_u0, grad_du;
          for (unsigned int i = 0; i < n; ++i)
            {
              const Tensor<1, dim> &g = fv.shape_grad(i, q);
              grad_u0[comp[i]] += fs.u0[i] * g;
              grad_du[comp[i]] += du[i] * g;
            }
          const Tensor<2, dim> F0 = I + grad_u0, F1 = F0 + grad_du, Fm = F0 + 0.5 * grad_du;
          const double         J0 = determinant(F0), J1 = determinant(F1), Jm = determinant(Fm);
          if (!(J1 > 0 && Jm > 0))
            {
              copy.failed = true;
              std::ostringstream m;
              m << "the element at " << cell->center() << " (body '" << scene.body_descriptions()[h.body].name
                << "') turns inside out in the step to t = " << t1 << " s (det F = " << J1
                << " at a quadrature point): the increment is too large for the mesh";
              copy.message = m.str();
              return false;
            }
          // The converged configuration only serves f_int(u_n) of HHT-alpha.
          const Tensor<2, dim> inv0T = dynamic ? transpose(invert(F0)) : Tensor<2, dim>(),
                               inv1T = transpose(invert(F1)), invmT = transpose(invert(Fm));
          for (unsigned int i = 0; i < n; ++i)
            {
              const Tensor<1, dim> &g = fv.shape_grad(i, q);
              fs.Gs[q][i]             = invmT * g;
              fs.Gf[q][i]             = inv1T * g;
              if (dynamic)
                fs.G0[q][i] = inv0T * g;
              B[q][i] = component_gradient(comp[i], fs.Gs[q][i]);
              if (b_bar)
                fs.Bf[q][i] = component_gradient(comp[i], fs.Gf[q][i]);
              if (b_bar && dynamic)
                fs.B0[q][i] = component_gradient(comp[i], fs.G0[q][i]);
            }
          fs.w0[q]          = h.weight[q] * J0;
          fs.wm[q]          = h.weight[q] * Jm;
          fs.w1[q]          = h.weight[q] * J1;
          h.trial_volume[q] = fs.w1[q];
          const Tensor<2, dim> L = grad_du * transpose(invmT);
          const Tensor<2, dim> W = 0.5 * (L - transpose(L));
          fs.R[q]                = half_rotation(W);
          fs.P[q]                = I - 0.5 * L;
        }
      if (b_bar)
        {
          mean_dilatation(B, fs.wm);
          mean_dilatation(fs.Bf, fs.w1);
          if (dynamic)
            mean_dilatation(fs.B0, fs.w0);
        }
      return true;
    }



    template <int dim>
    void
    CellKernels<dim>::rotate_trial_state(CellHistory<dim>                                   &h,
                                         const std::vector<dealii::SymmetricTensor<2, dim>> &stress,
                                         const std::vector<dealii::Tensor<2, dim>>          &R) const
    {
      for (unsigned int q = 0; q < n_q; ++q)
        {
          h.trial_stress[q] = dealii::symmetrize(R[q] * dealii::Tensor<2, dim>(stress[q]) * dealii::transpose(R[q]));
          h.material->rotate_state(R[q], dealii::ArrayView<double>(h.trial_state.data() + q * h.n_state, h.n_state));
        }
    }



    template <int dim>
    void
    CellKernels<dim>::finite_strain_forces(const CellHistory<dim> &h, CellScratch<dim> &scratch, CellCopy &copy) const
    {
      // In the trial configuration: f_i = sum_q B_i^1 : sigma_1 w_q det F_1, and K_ij the
      // material part B_i^1 : C : B_j^m plus the initial-stress part, point by point.
      const auto &fs = scratch.finite;
      auto       &C = scratch.material.C, &H = scratch.material.H;
      for (unsigned int q = 0; q < n_q; ++q)
        {
          const double                           w  = fs.w1[q];
          const dealii::SymmetricTensor<2, dim> &s  = h.trial_stress[q];
          const auto                            &Gf = fs.Gf[q];
          if (matrix)
            {
              // The initial-stress stiffness delta(c_i, c_j) grad N_i . sigma grad N_j w.
              auto &sG = scratch.finite.sG;
              for (unsigned int j = 0; j < n; ++j)
                sG[j] = s * Gf[j];
              for (unsigned int i = 0; i < n; ++i)
                for (unsigned int j = 0; j < n; ++j)
                  if (comp[i] == comp[j])
                    copy.A(i, j) += (Gf[i] * sG[j]) * w;
            }
          if (b_bar)
            {
              add_b_bar_terms(fs.Bf[q], scratch.B[q], h, q, &fs.R[q], w, copy);
              continue;
            }
          // The forces' gradients (trial configuration) and the strains' (midpoint).
          add_component_forces(Gf, s, w, copy.fi);
          if (!matrix)
            continue;
          // sigma_1 = R_h S R_h^T: the tangent turned in its stress indices,
          // C'_{abkd} = R_ai R_bj C_ijkd (H holds the plain copy of C; its use at q comes later).
          plain_tangent(h.tangent[q], H);
          const dealii::Tensor<2, dim> &R = fs.R[q];
          for (unsigned int a = 0; a < dim; ++a)
            for (unsigned int b = 0; b < dim; ++b)
              for (unsigned int kd = 0; kd < dim * dim; ++kd)
                {
                  double v = 0;
                  for (unsigned int i = 0; i < dim; ++i)
                    for (unsigned int j = 0; j < dim; ++j)
                      v += R[a][i] * R[b][j] * H[(i * dim + j) * dim * dim + kd];
                  C[(a * dim + b) * dim * dim + kd] = v;
                }
          // d(d eps) / du_j = sym((I - L/2) e_{c_j} (x) grad_m N_j) (F_m moves with u_1):
          // H_j[c][b] = w C_{c b k d} P_{k c_j} g_j[d] with P = I - L/2.
          const dealii::Tensor<2, dim> &P  = fs.P[q];
          const auto                   &Gj = fs.Gs[q];
          for (unsigned int j = 0; j < n; ++j)
            for (unsigned int c = 0; c < dim; ++c)
              for (unsigned int b = 0; b < dim; ++b)
                {
                  double v = 0;
                  for (unsigned int k = 0; k < dim; ++k)
                    {
                      const double *row = &C[((c * dim + b) * dim + k) * dim];
                      double        r   = 0;
                      for (unsigned int d = 0; d < dim; ++d)
                        r += row[d] * Gj[j][d];
                      v += P[k][comp[j]] * r;
                    }
                  H[(j * dim + c) * dim + b] = w * v;
                }
          add_component_tangent(Gf, H, copy.A);
        }
    }



    template class CellKernels<2>;
    template class CellKernels<3>;
  } // namespace FEM
} // namespace hysteron
