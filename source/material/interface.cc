#include <hysteron/base/exceptions.h>
#include <hysteron/material/interface.h>

#include <algorithm>
#include <cmath>

namespace hysteron
{
  namespace Material
  {
    std::string
    to_string(const StressState state)
    {
      switch (state)
        {
          case StressState::plane_stress:
            return "plane stress";
          case StressState::plane_strain:
            return "plane strain";
          case StressState::axisymmetric:
            return "axisymmetric";
          default:
            return "3D";
        }
    }

    double
    Elasticity::p_wave_speed() const
    {
      return std::sqrt(p_wave_modulus() / density);
    }

    template <int dim>
    void
    Interface<dim>::initialize(const Elasticity &elasticity, const Section &section)
    {
      elastic = elasticity;
      parse_parameters(section);
    }

    template <int dim>
    void
    Interface<dim>::parse_parameters(const Section &)
    {}

    template <int dim>
    void
    Interface<dim>::initialize_state(const dealii::ArrayView<double> &state) const
    {
      std::fill(state.begin(), state.end(), 0.0);
    }

    template <int dim>
    void
    Interface<dim>::update_point(const dealii::SymmetricTensor<2, dim> &strain_increment,
                                 dealii::SymmetricTensor<2, dim>       &stress,
                                 const dealii::ArrayView<double>       &state,
                                 dealii::SymmetricTensor<4, dim>       *tangent) const
    {
      update(dealii::ArrayView<const dealii::SymmetricTensor<2, dim>>(&strain_increment, 1),
             dealii::ArrayView<dealii::SymmetricTensor<2, dim>>(&stress, 1),
             state,
             tangent ? dealii::ArrayView<dealii::SymmetricTensor<4, dim>>(tangent, 1) :
                       dealii::ArrayView<dealii::SymmetricTensor<4, dim>>());
    }

    template <int dim>
    void
    Interface<dim>::update_axisymmetric(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &,
      const dealii::ArrayView<const double> &,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>> &,
      const dealii::ArrayView<double> &,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &,
      const dealii::ArrayView<HoopTangent<dim>> &) const
    {
      // create() refuses axisymmetric scenes for models without supports_axisymmetry().
      AssertThrow(false, dealii::ExcNotImplemented());
    }

    template <int dim>
    void
    Interface<dim>::out_of_plane(const dealii::SymmetricTensor<2, dim> &,
                                 const dealii::SymmetricTensor<2, dim> &stress,
                                 const dealii::ArrayView<const double> &,
                                 double &eps_zz,
                                 double &sigma_zz) const
    {
      eps_zz   = 0;
      sigma_zz = 0;
      if (dim != 2)
        return;
      const double in_plane_sum = stress[0][0] + stress[1][1];
      if (elastic.stress_state == StressState::plane_stress)
        eps_zz = -elastic.poissons_ratio / elastic.youngs_modulus * in_plane_sum;
      else
        sigma_zz = elastic.poissons_ratio * in_plane_sum;
    }

    void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      using dealii::Patterns::Double;
      using dealii::Patterns::Selection;
      prm.declare_entry("Model",
                        "linear elastic",
                        Selection(Registry<3>::pattern_string()),
                        "The constitutive model. Registered models:" +
                          Registry<3>::documentation());
      prm.declare_entry("Stress state",
                        "plane stress",
                        Selection("plane stress|plane strain|axisymmetric"),
                        "How a 2D model treats the third direction: 'plane stress' "
                        "(sigma_zz = 0, thin bodies with an out-of-plane thickness), "
                        "'plane strain' (eps_zz = 0) or 'axisymmetric' (a solid of "
                        "revolution: x is the radius r >= 0, y the axis, the third "
                        "direction the hoop direction with eps_tt = u_r / r; masses, "
                        "volumes, loads and reactions are those of the whole ring, 2 pi r "
                        "per unit of section area; MPM and FEM). Ignored in 3D.");
      prm.declare_entry("Young's modulus", "210e9", Double(), "Young's modulus E [Pa], > 0.");
      prm.declare_entry("Poisson's ratio",
                        "0.3",
                        Double(),
                        "Poisson's ratio nu [-], in the open interval (-1, 0.5).");
      prm.declare_entry("Density", "7850", Double(), "Mass density rho [kg/m^3], > 0.");
      Registry<3>::declare_parameters(prm);
    }

    template <int dim>
    std::unique_ptr<Interface<dim>>
    create(const Section &section)
    {
      Elasticity elasticity;
      elasticity.youngs_modulus = section.get_positive("Young's modulus");
      elasticity.poissons_ratio = section.get_in_open_interval("Poisson's ratio", -1.0, 0.5);
      elasticity.density        = section.get_positive("Density");
      if (dim == 3)
        elasticity.stress_state = StressState::three_dimensional;
      else
        {
          const std::string state = section.get("Stress state");
          elasticity.stress_state = state == "plane stress" ? StressState::plane_stress :
                                    state == "axisymmetric" ? StressState::axisymmetric :
                                                              StressState::plane_strain;
        }

      auto model = Registry<dim>::create(section.get("Model"), section.where("Model"));
      model->initialize(elasticity, section);
      if (elasticity.stress_state == StressState::axisymmetric && !model->supports_axisymmetry())
        throw InputError(section.where("Stress state"),
                         "the model '" + section.get("Model") +
                           "' has no axisymmetric form (it does not take the hoop strain)");
      return model;
    }

    template class Interface<2>;
    template class Interface<3>;
    template std::unique_ptr<Interface<2>>
    create<2>(const Section &);
    template std::unique_ptr<Interface<3>>
    create<3>(const Section &);
  } // namespace Material
} // namespace hysteron
