// Output columns `eps_1`, `eps_2` (and `eps_3` in 3D): the principal values of the
// point's strain tensor, largest first (tensor shear components; in 2D the in-plane
// pair (eps_xx + eps_yy)/2 +- sqrt(((eps_xx - eps_yy)/2)^2 + eps_xy^2)). An RBSN cell's
// strain is the one fitted to the jumps of its facets (doc/rbsn.md).
#include <deal.II/base/symmetric_tensor.h>

#include <hysteron/scene/output_column.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

namespace hysteron
{
  namespace PointData
  {
    template <int dim>
    class PrincipalStrains : public Column<dim>
    {
    public:
      std::vector<std::string>
      names() const override
      {
        if constexpr (dim == 2)
          return {"eps_1", "eps_2"};
        else
          return {"eps_1", "eps_2", "eps_3"};
      }

      void
      evaluate(const PointView<dim> &p, double *out) const override
      {
        if constexpr (dim == 2)
          {
            const double mean   = 0.5 * (p.strain[0][0] + p.strain[1][1]);
            const double radius = std::hypot(0.5 * (p.strain[0][0] - p.strain[1][1]), p.strain[0][1]);
            out[0]              = mean + radius;
            out[1]              = mean - radius;
          }
        else
          {
            std::array<double, 3> e = dealii::eigenvalues(p.strain);
            std::sort(e.begin(), e.end(), std::greater<double>());
            std::copy(e.begin(), e.end(), out);
          }
      }
    };
  } // namespace PointData
} // namespace hysteron

HYSTERON_REGISTER_OUTPUT_COLUMN(hysteron::PointData::PrincipalStrains,
                                "principal strains",
                                "the principal strains eps_1 >= eps_2 (>= eps_3 in 3D; in 2D the "
                                "in-plane pair) of the strain tensor")
