#ifndef hysteron_source_mpm_support_h
#define hysteron_source_mpm_support_h

// The tensor-product support of a material point (the 1D basis values and gradients
// per direction) and the gathers the step kernels share. Included by step.h.

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include "mpm/grid.h"

#include <array>

namespace hysteron
{
  namespace MPM
  {
    namespace internal
    {
      /**
       * The tensor-product support of one point: the 1D values and derivatives
       * per direction and the local grid node of the first support node. The
       * node of entry (a, b, c) is base + a + b s1 + c s2.
       */
      template <int dim, typename Basis>
      struct Support
      {
        static constexpr unsigned int n1 = Basis::n_support;
        double                        w[dim][n1];
        double                        g[dim][n1];
        unsigned int                  base;

        DEAL_II_ALWAYS_INLINE inline void
        reinit(const Lattice<dim>            &lattice,
               const BackgroundGrid<dim>     &grid,
               const dealii::Point<dim>      &x,
               const std::array<double, dim> &inv_h)
        {
          base = 0;
          for (unsigned int d = 0; d < dim; ++d)
            {
              int first;
              Basis::evaluate((x[d] - lattice.origin[d]) * inv_h[d],
                              lattice.n_cells[d],
                              first,
                              w[d],
                              g[d]);
              for (unsigned int k = 0; k < n1; ++k)
                g[d][k] *= inv_h[d];
              base += (first - grid.box_lower(d)) * grid.stride(d);
            }
        }

        /// Call f(node, N, grad N) for every support node.
        template <typename Function>
        DEAL_II_ALWAYS_INLINE inline void
        for_each(const unsigned int s1, const unsigned int s2, const Function &f) const
        {
          dealii::Tensor<1, dim> grad;
          if constexpr (dim == 2)
            {
              for (unsigned int b = 0; b < n1; ++b)
                for (unsigned int a = 0; a < n1; ++a)
                  {
                    grad[0] = g[0][a] * w[1][b];
                    grad[1] = w[0][a] * g[1][b];
                    f(base + a + b * s1, w[0][a] * w[1][b], grad);
                  }
            }
          else
            {
              (void)s2;
              for (unsigned int c = 0; c < n1; ++c)
                for (unsigned int b = 0; b < n1; ++b)
                  {
                    const double wbc = w[1][b] * w[2][c];
                    for (unsigned int a = 0; a < n1; ++a)
                      {
                        grad[0] = g[0][a] * wbc;
                        grad[1] = w[0][a] * g[1][b] * w[2][c];
                        grad[2] = w[0][a] * w[1][b] * g[2][c];
                        f(base + a + b * s1 + c * s2, w[0][a] * wbc, grad);
                      }
                  }
            }
        }
      };

      /// The lattice and the node strides the kernels need, read once per phase.
      template <int dim>
      struct GridGeometry
      {
        explicit GridGeometry(const BackgroundGrid<dim> &grid)
          : lattice(grid.lattice())
          , s1(grid.stride(1))
          , s2(dim == 3 ? grid.stride(dim - 1) : 0)
        {
          for (unsigned int d = 0; d < dim; ++d)
            inv_h[d] = 1.0 / lattice.h[d];
        }

        const Lattice<dim>     &lattice;
        std::array<double, dim> inv_h;
        const unsigned int      s1, s2;
      };

      /// d = sym(sum_i v_i (x) grad N_ip) of a point from the velocities of the common field.
      template <int dim, typename Basis>
      DEAL_II_ALWAYS_INLINE inline dealii::SymmetricTensor<2, dim>
      strain_rate(const Support<dim, Basis> &support, const GridGeometry<dim> &g, const double *const node)
      {
        dealii::Tensor<2, dim> L;
        support.for_each(g.s1, g.s2, [&](const unsigned int n, double, const dealii::Tensor<1, dim> &grad) {
          const double *const r = node + std::size_t(n) * (1 + 2 * dim);
          for (unsigned int i = 0; i < dim; ++i)
            for (unsigned int j = 0; j < dim; ++j)
              L[i][j] += r[1 + i] * grad[j];
        });
        return dealii::symmetrize(L);
      }
    } // namespace internal
  } // namespace MPM
} // namespace hysteron

#endif
