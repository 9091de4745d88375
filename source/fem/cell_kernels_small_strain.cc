#include "cell_kernels.h"

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    mean_dilatation(StrainOperator<dim> &B, const std::vector<double> &weights)
    {
      const unsigned int n_q = weights.size(), n = B[0].size();
      double             volume = 0;
      for (unsigned int q = 0; q < n_q; ++q)
        volume += weights[q];
      const dealii::SymmetricTensor<2, dim> I = dealii::unit_symmetric_tensor<dim>();
      for (unsigned int i = 0; i < n; ++i)
        {
          double mean = 0;
          for (unsigned int q = 0; q < n_q; ++q)
            mean += dealii::trace(B[q][i]) * weights[q];
          mean /= volume;
          for (unsigned int q = 0; q < n_q; ++q)
            B[q][i] += (mean - dealii::trace(B[q][i])) / dim * I;
        }
    }



    template <int dim>
    void
    small_strain_operator(const dealii::FEValues<dim> &fv,
                          const std::vector<double>   &weights,
                          const bool                   b_bar,
                          StrainOperator<dim>         &B)
    {
      const dealii::FEValuesExtractors::Vector displacement(0);
      for (unsigned int q = 0; q < B.size(); ++q)
        for (unsigned int i = 0; i < B[q].size(); ++i)
          B[q][i] = fv[displacement].symmetric_gradient(i, q);
      if (b_bar)
        mean_dilatation(B, weights);
    }



    template <int dim>
    void
    CellKernels<dim>::small_strain_forces(const CellHistory<dim> &h, CellScratch<dim> &scratch, CellCopy &copy) const
    {
      // f_i = sum_q B_i : sigma_q w_q, K_ij = sum_q B_i : C_q : B_j w_q, point by point.
      const dealii::FEValues<dim> &fv = scratch.fv;
      auto                        &G  = scratch.material.G;
      auto                        &C = scratch.material.C, &H = scratch.material.H;
      for (unsigned int q = 0; q < n_q; ++q)
        {
          const double                           w = h.weight[q];
          const dealii::SymmetricTensor<2, dim> &s = h.trial_stress[q];
          if (b_bar)
            {
              add_b_bar_terms(scratch.B[q], scratch.B[q], h, q, nullptr, w, copy);
              continue;
            }
          for (unsigned int i = 0; i < n; ++i)
            G[i] = fv.shape_grad(i, q);
          add_component_forces(G, s, w, copy.fi);
          if (matrix)
            {
              // C as a plain array, then H_j[c][b] = w C_{c b c_j d} g_j[d].
              plain_tangent(h.tangent[q], C);
              for (unsigned int j = 0; j < n; ++j)
                for (unsigned int c = 0; c < dim; ++c)
                  for (unsigned int b = 0; b < dim; ++b)
                    {
                      const double *row = &C[((c * dim + b) * dim + comp[j]) * dim];
                      double        v   = 0;
                      for (unsigned int d = 0; d < dim; ++d)
                        v += row[d] * G[j][d];
                      H[(j * dim + c) * dim + b] = w * v;
                    }
              add_component_tangent(G, H, copy.A);
            }
          if (axisymmetric)
            add_hoop_terms(h.hoop_tangent[q], h, q, true, scratch, matrix ? &copy.A : nullptr, copy.fi);
        }
    }



    template <int dim>
    void
    CellKernels<dim>::add_hoop_terms(const Material::HoopTangent<dim> &T,
                                     const CellHistory<dim>           &h,
                                     const unsigned int                q,
                                     const bool                        trial,
                                     CellScratch<dim>                 &scratch,
                                     dealii::FullMatrix<double>       *K,
                                     dealii::Vector<double>           &f) const
    {
      // S = T.stress_by_hoop, H = T.hoop_by_strain, C_tt = T.hoop_by_hoop:
      // K_ij += (B_i : S n_j + n_i H : B_j + n_i C_tt n_j) w.
      const dealii::FEValues<dim> &fv       = scratch.fv;
      std::vector<double>         &nbh      = scratch.material.H;
      const double                 sigma_tt = h.out_of_plane_stress(q, trial);
      const double                 w        = h.weight[q];
      const double                 inv_r    = 1.0 / h.point[q][0];
      for (unsigned int i = 0; i < n; ++i)
        {
          // nr: n_i; bs: B_i : S; hb: H : B_i.
          const double nr = comp[i] == 0 ? fv.shape_value(i, q) * inv_r : 0.0;
          double       bs = 0, hb = 0;
          const auto   g  = fv.shape_grad(i, q);
          for (unsigned int b = 0; b < dim; ++b)
            {
              bs += T.stress_by_hoop[comp[i]][b] * g[b];
              hb += T.hoop_by_strain[comp[i]][b] * g[b];
            }
          f[i] += nr * sigma_tt * w;
          if (K)
            {
              // (n_i, B_i : S, H : B_i) in the material scratch's H (its use at q is done)
              nbh[3 * i]     = nr;
              nbh[3 * i + 1] = bs;
              nbh[3 * i + 2] = hb;
            }
        }
      if (K)
        for (unsigned int i = 0; i < n; ++i)
          for (unsigned int j = 0; j < n; ++j)
            (*K)(i, j) += (nbh[3 * i + 1] * nbh[3 * j] + nbh[3 * i] * nbh[3 * j + 2] +
                           nbh[3 * i] * T.hoop_by_hoop * nbh[3 * j]) * w;
    }



    template void
    mean_dilatation<2>(StrainOperator<2> &, const std::vector<double> &);
    template void
    mean_dilatation<3>(StrainOperator<3> &, const std::vector<double> &);
    template void
    small_strain_operator<2>(const dealii::FEValues<2> &, const std::vector<double> &, const bool, StrainOperator<2> &);
    template void
    small_strain_operator<3>(const dealii::FEValues<3> &, const std::vector<double> &, const bool, StrainOperator<3> &);
    template class CellKernels<2>;
    template class CellKernels<3>;
  } // namespace FEM
} // namespace hysteron
