// The rigid motion of a cell of the network at a point: u + theta x r (probes and VTU).
#ifndef hysteron_rbsn_rigid_motion_h
#define hysteron_rbsn_rigid_motion_h

#include <deal.II/base/tensor.h>

namespace hysteron
{
  namespace RBSN
  {
    /// The rigid motion u + theta x r of a cell with the DoF values @p U at the offset @p r.
    template <int dim, typename Values>
    dealii::Tensor<1, dim>
    rigid_motion(const Values &U, const dealii::Tensor<1, dim> &r)
    {
      dealii::Tensor<1, dim> w;
      if constexpr (dim == 2)
        {
          w[0] = U[0] - U[2] * r[1];
          w[1] = U[1] + U[2] * r[0];
        }
      else
        {
          const dealii::Tensor<1, 3> theta({U[3], U[4], U[5]});
          const dealii::Tensor<1, 3> turn = dealii::cross_product_3d(theta, r);
          for (unsigned int d = 0; d < 3; ++d)
            w[d] = U[d] + turn[d];
        }
      return w;
    }
  } // namespace RBSN
} // namespace hysteron

#endif
