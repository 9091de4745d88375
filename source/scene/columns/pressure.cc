// Output column `pressure`: p = -(sigma_xx + sigma_yy + sigma_zz) / 3 [Pa], positive in
// compression, with the out-of-plane stress of plane strain in 2D.
#include <hysteron/scene/output_column.h>

namespace hysteron
{
  namespace PointData
  {
    template <int dim>
    class Pressure : public Column<dim>
    {
    public:
      std::vector<std::string>
      names() const override
      {
        return {"pressure"};
      }

      void
      evaluate(const PointView<dim> &p, double *out) const override
      {
        out[0] = -(dealii::trace(p.stress) + p.sigma_zz) / 3.0;
      }
    };
  } // namespace PointData
} // namespace hysteron

HYSTERON_REGISTER_OUTPUT_COLUMN(hysteron::PointData::Pressure,
                                "pressure",
                                "the pressure p = -tr(sigma)/3 [Pa], positive in compression "
                                "(with sigma_zz in 2D)")
