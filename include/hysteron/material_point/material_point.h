#ifndef hysteron_material_point_material_point_h
#define hysteron_material_point_material_point_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/symmetric_tensor.h>

#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace MaterialPoint
  {
    /// The six tensor components in CSV order: xx, yy, zz, xy, yz, xz.
    extern const std::array<const char *, 6> component_names;

    /**
     * One material point driven along a strain path: the constitutive test bench.
     *
     * Each strain component is a function of t (muParser). Components listed in
     * `Stress-free components` are unknowns instead: at every step they are found
     * by Newton's method so that the corresponding stress components vanish
     * (mixed control; e.g. "yy, zz" in 3D gives uniaxial stress). The Jacobian is
     * the model's tangent restricted to the free components; with tensor shear
     * components, d sigma_a / d eps_b = C_ab for b on the diagonal and 2 C_ab
     * for b off the diagonal (eps_b and eps_ba are the same unknown).
     *
     * Writes `history.csv`: t, the six strains, the six stresses (out-of-plane
     * ones included), then the model's state variables.
     */
    template <int dim>
    class Method : public Methods::Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      run() override;

      std::string
      summary() const override;

      bool
      takes_continuum_materials() const override
      {
        return true;
      }

      /// One row per step (and t = 0): the values written to history.csv.
      const std::vector<std::vector<double>> &
      history() const
      {
        return rows;
      }

      /// The CSV column names.
      std::vector<std::string>
      column_names() const;

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

    private:
      /// (i, j) index of a component, and whether it is prescribed.
      struct Component
      {
        unsigned int                                  i, j;
        std::string                                   name;
        bool                                          free;
        std::unique_ptr<dealii::FunctionParser<1>>    strain;
      };

      std::vector<Component>            components;
      const Material::Interface<dim>   *material = nullptr;
      double                            end_time = 1;
      unsigned int                      n_steps  = 1;
      double                            tolerance = 1e-12;
      unsigned int                      max_iterations = 50;
      std::vector<std::vector<double>>  rows;
      unsigned int                      total_iterations = 0;
    };
  } // namespace MaterialPoint
} // namespace hysteron

#endif
