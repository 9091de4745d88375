#ifndef hysteron_material_point_uniaxial_h
#define hysteron_material_point_uniaxial_h

#include <deal.II/base/function_parser.h>

#include <hysteron/material/bouc_wen_family.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>

#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace MaterialPoint
  {
    /**
     * The one-dimensional test bench of the uniaxial Bouc-Wen law
     * (Material::BoucWenUniaxial): `set Method = uniaxial`.
     *
     * A strain path eps(t) (muParser, `subsection Uniaxial / Strain`) is cut into
     * `Steps` equal time steps up to `End time`; every step is one update of the
     * law with the increment eps(t_{i+1}) - eps(t_i). The law reads
     * `Material / Young's modulus` as its stiffness k and the
     * `Material / Bouc-Wen` subsection (yield stress, a, n, beta, gamma,
     * integrator, tolerance, degradation); the material `Model` entry is not
     * used, so the bench works whatever model the scene's material is.
     * The Dimension of the scene does not matter either.
     *
     * Writes `history.csv` (rank 0): t, eps, sig, z, with degradation eta, e_h,
     * nu_s, then H1 = |z/z_y|^n and H2 = beta + gamma sgn(z deps) of the step
     * that ended at t (H2 = beta on the first row).
     */
    template <int dim>
    class Uniaxial : public Methods::Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      run() override;

      std::string
      summary() const override;

      /// The CSV column names.
      std::vector<std::string>
      column_names() const;

      /// One row per step (and t = 0): the values written to history.csv.
      const std::vector<std::vector<double>> &
      history() const
      {
        return rows;
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

    private:
      /// The strain at step @p step (t = End time step / Steps), checked to be finite.
      double
      strain_at(unsigned int step) const;

      /// run() with a law of the wider family (`Bouc-Wen/Uniaxial law`, one spring k = E,
      /// F_y = sigma_y): columns t, eps, sig, z, H1.
      void
      run_variant();

      Material::BoucWenUniaxial                   law;
      std::unique_ptr<Material::UniaxialSpringLaw> variant;
      std::unique_ptr<dealii::FunctionParser<1>> strain;
      double                                     end_time = 1;
      unsigned int                               n_steps  = 1;
      std::vector<std::vector<double>>           rows;
      unsigned long                              total_work = 0;
    };
  } // namespace MaterialPoint
} // namespace hysteron

#endif
