// Output columns `s_1`, `s_2`, `s_3`: the principal stresses [Pa], largest first. In 2D
// the in-plane pair (s_xx + s_yy)/2 +- sqrt(((s_xx - s_yy)/2)^2 + s_xy^2) and the
// out-of-plane sigma_zz (0 in plane stress) are sorted together.
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
    class PrincipalStresses : public Column<dim>
    {
    public:
      std::vector<std::string>
      names() const override
      {
        return {"s_1", "s_2", "s_3"};
      }

      void
      evaluate(const PointView<dim> &p, double *out) const override
      {
        std::array<double, 3> s;
        if constexpr (dim == 2)
          {
            const double mean   = 0.5 * (p.stress[0][0] + p.stress[1][1]);
            const double half   = 0.5 * (p.stress[0][0] - p.stress[1][1]);
            const double radius = std::hypot(half, p.stress[0][1]);
            s                   = {{mean + radius, mean - radius, p.sigma_zz}};
          }
        else
          s = dealii::eigenvalues(p.stress);
        std::sort(s.begin(), s.end(), std::greater<double>());
        std::copy(s.begin(), s.end(), out);
      }
    };
  } // namespace PointData
} // namespace hysteron

HYSTERON_REGISTER_OUTPUT_COLUMN(hysteron::PointData::PrincipalStresses,
                                "principal stresses",
                                "the principal stresses s_1 >= s_2 >= s_3 [Pa] (with sigma_zz in "
                                "2D)")
