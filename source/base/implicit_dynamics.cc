#include <hysteron/base/exceptions.h>
#include <hysteron/base/implicit_dynamics.h>

namespace hysteron
{
  void
  ImplicitDynamicsParameters::declare_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    prm.declare_entry("HHT alpha",
                      "0",
                      Double(),
                      "Implicit dynamics: the Hilber-Hughes-Taylor parameter alpha in "
                      "[-1/3, 0] (beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha); 0 is the "
                      "Newmark average acceleration rule (no numerical damping).");
    prm.declare_entry("Rayleigh mass coefficient",
                      "0",
                      Double(),
                      "Rayleigh damping C = a0 M + a1 K0 (K0: the initial elastic "
                      "stiffness): a0 [1/s], >= 0. Damping ratio xi(omega) = a0 / (2 omega) "
                      "+ a1 omega / 2.");
    prm.declare_entry("Rayleigh stiffness coefficient", "0", Double(), "Rayleigh damping: a1 [s], >= 0.");
  }



  void
  ImplicitDynamicsParameters::parse_parameters(const Section &s)
  {
    hht_alpha = s.get_double("HHT alpha");
    require(hht_alpha >= -1.0 / 3.0 - 1e-14 && hht_alpha <= 0,
            s.where("HHT alpha"),
            "must be in [-1/3, 0] (got " + s.get("HHT alpha") + ")");
    rayleigh_mass      = s.get_non_negative("Rayleigh mass coefficient");
    rayleigh_stiffness = s.get_non_negative("Rayleigh stiffness coefficient");
  }
} // namespace hysteron
