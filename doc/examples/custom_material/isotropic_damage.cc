// An isotropic damage material as a hysteron plugin: the whole of what a user writes to add a
// constitutive model. Build it against the installed package (CMakeLists.txt beside this file)
// and load it with `set Additional shared libraries = ./build/libcustom_material.so`.
//
// Model: sigma = (1 - d) C : eps, with the damage d(kappa) = 1 - (kappa_0 / kappa) exp(-(kappa -
// kappa_0) / kappa_f) for kappa > kappa_0 (exponential softening) and kappa = max over the
// history of the equivalent strain eps_eq = sqrt(eps : eps). State: the total strain (the
// interface passes increments) and kappa.
#include <deal.II/base/parameter_handler.h>

#include <hysteron/material/interface.h>

#include <cmath>

namespace custom
{
  using namespace dealii;

  template <int dim>
  class IsotropicDamage : public hysteron::Material::Interface<dim>
  {
  public:
    static constexpr unsigned int n_strain = SymmetricTensor<2, dim>::n_independent_components;

    static void
    declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Isotropic damage");
      prm.declare_entry("Damage threshold strain", "1e-3", Patterns::Double(),
                        "kappa_0 [-], > 0: equivalent strain at which damage starts.");
      prm.declare_entry("Softening strain", "5e-3", Patterns::Double(),
                        "kappa_f [-], > 0: scale of the exponential softening.");
      prm.leave_subsection();
    }

    unsigned int
    n_state_variables() const override
    {
      return n_strain + 2;
    }

    std::vector<std::string>
    state_variable_names() const override
    {
      std::vector<std::string> names;
      for (unsigned int c = 0; c < n_strain; ++c)
        names.push_back("strain_" + std::to_string(c));
      names.push_back("kappa");
      names.push_back("damage");
      return names;
    }

    void
    update(const ArrayView<const SymmetricTensor<2, dim>> &strain_increments,
           const ArrayView<SymmetricTensor<2, dim>>       &stresses,
           const ArrayView<double>                        &states,
           const ArrayView<SymmetricTensor<4, dim>>       &tangents) const override
    {
      const unsigned int n = n_state_variables();
      for (std::size_t p = 0; p < strain_increments.size(); ++p)
        {
          double                 *state = &states[p * n];
          SymmetricTensor<2, dim> strain;
          for (unsigned int c = 0; c < n_strain; ++c)
            strain.access_raw_entry(c) = state[c];
          strain += strain_increments[p];
          for (unsigned int c = 0; c < n_strain; ++c)
            state[c] = strain.access_raw_entry(c);

          // kappa only grows: damage is irreversible.
          double &kappa = state[n_strain];
          kappa         = std::max(kappa, std::sqrt(strain * strain));
          const double d =
            kappa > kappa_0 ? 1.0 - kappa_0 / kappa * std::exp(-(kappa - kappa_0) / kappa_f) : 0.0;
          state[n_strain + 1] = d;

          stresses[p] = (1.0 - d) * stiffness * strain;
          if (tangents.size() > 0)
            tangents[p] = (1.0 - d) * stiffness; // the secant stiffness (enough for the bench)
        }
    }

  protected:
    void
    parse_parameters(const hysteron::Section &material) override
    {
      hysteron::Section s(material, "Isotropic damage");
      kappa_0   = s.get_positive("Damage threshold strain");
      kappa_f   = s.get_positive("Softening strain");
      stiffness = this->elasticity().template stiffness<dim>();
    }

  private:
    double                  kappa_0 = 1e-3;
    double                  kappa_f = 5e-3;
    SymmetricTensor<4, dim> stiffness;
  };
} // namespace custom

// One line registers the model for dim = 2 and 3 under the name used in `set Model = ...`.
HYSTERON_REGISTER_MATERIAL(custom::IsotropicDamage,
                           "isotropic damage",
                           "example plugin: sigma = (1 - d(kappa)) C : eps with exponential "
                           "softening (doc/examples/custom_material)")
