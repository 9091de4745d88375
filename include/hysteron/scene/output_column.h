#ifndef hysteron_scene_output_column_h
#define hysteron_scene_output_column_h

#include <deal.II/base/array_view.h>
#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <hysteron/base/registry.h>
#include <hysteron/material/interface.h>

#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace PointData
  {
    /**
     * What a point offers an output column (an MPM material point, an FEM
     * quadrature point, an RBSN cell with its Love-Weber stress and the strain
     * fitted to its facets, doc/rbsn.md): its position, displacement, velocity,
     * stress and strain (tensor shear components), its material (null for a rigid
     * point) and the material's state variables (none for an RBSN cell), and in 2D
     * the out-of-plane stress sigma_zz (0 in plane stress).
     */
    template <int dim>
    struct PointView
    {
      const dealii::Point<dim>              &x;
      const dealii::Tensor<1, dim>          &u;
      const dealii::Tensor<1, dim>          &v;
      const dealii::SymmetricTensor<2, dim> &stress;
      const dealii::SymmetricTensor<2, dim> &strain;
      const Material::Interface<dim>        *material;
      dealii::ArrayView<const double>        state;
      double                                 sigma_zz;
    };

    /**
     * An output column plugin: one or more columns computed from a point, appended
     * to every point table of the MPM, the FEM and the RBSN (probe_<i>.csv,
     * average_<i>.csv, particles.csv, quadrature_points.csv, cells.csv) when named in
     * `Output/Additional columns`. Adding one takes one class and one registration line:
     *
     *   template <int dim>
     *   class Pressure : public PointData::Column<dim>
     *   {
     *     std::vector<std::string> names() const override { return {"pressure"}; }
     *     void evaluate(const PointData::PointView<dim> &p, double *out) const override
     *     { out[0] = -(trace(p.stress) + p.sigma_zz) / 3; }
     *   };
     *   HYSTERON_REGISTER_OUTPUT_COLUMN(Pressure, "pressure", "p = -tr(sigma)/3 [Pa]")
     *
     * evaluate() runs once per point and row: no allocation there.
     */
    template <int dim>
    class Column
    {
    public:
      virtual ~Column() = default;

      /// Parameters in `subsection Output` (optional; names must not clash).
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /// The names of the columns (e.g. {"pressure"}).
      virtual std::vector<std::string>
      names() const = 0;

      /// Write names().size() values of point @p p into @p out.
      virtual void
      evaluate(const PointView<dim> &p, double *out) const = 0;
    };

    template <int dim>
    using ColumnRegistry = Plugins::Registry<Column<dim>>;

    /**
     * The columns a scene asked for (`Output/Additional columns`), in the order
     * given. Each scene holds its own (OutputControl::additional_columns): two
     * scenes of one process never share a selection.
     */
    template <int dim>
    class ColumnSelection
    {
    public:
      /// Select the columns by name (the Scene does this when it reads the parameters;
      /// @p where is the parameter path for errors).
      void
      select(const std::vector<std::string> &names, const std::string &where);

      bool
      empty() const
      {
        return columns.empty();
      }

      /// The names of the values of every selected column, in order.
      std::vector<std::string>
      names() const;

      /// Write the values of every selected column of @p point into @p out.
      void
      evaluate(const PointView<dim> &point, double *out) const;

    private:
      std::vector<std::shared_ptr<const Column<dim>>> columns;
      /// The number of values of each column (names() allocates).
      std::vector<unsigned int> widths;
    };
  } // namespace PointData
} // namespace hysteron

/// Register the output column class template @p classname (dim = 2, 3) under @p name.
#define HYSTERON_REGISTER_OUTPUT_COLUMN(classname, name, description) \
  HYSTERON_REGISTER_DIM_PLUGIN(::hysteron::PointData::Column, classname, name, description)

#endif
