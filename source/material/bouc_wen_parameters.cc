#include <hysteron/material/bouc_wen_family.h>
#include <hysteron/material/bouc_wen_parameters.h>

#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace Material
  {
    void
    BoucWenParameters::declare_parameters(dealii::ParameterHandler &prm)
    {
      using dealii::Patterns::Double;
      using dealii::Patterns::Selection;
      prm.enter_subsection("Bouc-Wen");
      {
        prm.declare_entry("Yield stress",
                          "235e6",
                          Double(),
                          "Initial yield stress sigma_y [Pa] (von Mises equivalent stress in "
                          "2D/3D), > 0.");
        prm.declare_entry("Post-yield stiffness ratio",
                          "0",
                          Double(),
                          "a = E_t / E, the ratio of post-yield (tangent) to elastic stiffness, "
                          "in [0, 1). The hardening modulus is H' = a E / (1 - a).");
        prm.declare_entry("Smoothness n",
                          "8",
                          Double(),
                          "Exponent n > 0 of the smooth transition from elastic to plastic: "
                          "large n approaches the bilinear law (n < 1 gives a warning).");
        prm.declare_entry("Beta",
                          "0.5",
                          Double(),
                          "beta of z' = eps' [1 - |z/z_y|^n (beta + gamma sgn(z eps'))]; "
                          "admissible: |gamma| <= beta, beta + gamma > 0 (= 1 for z_y to be the "
                          "saturation value). beta = gamma = 0.5 gives elastic unloading.");
        prm.declare_entry("Gamma",
                          "0.5",
                          Double(),
                          "gamma, the factor of the sign term (see Beta). Note: OpenSees' "
                          "BoucWenMaterial calls this factor beta.");
        prm.declare_entry("Isotropic hardening fraction",
                          "1",
                          Double(),
                          "m in [0, 1]: the share of hardening that expands the yield surface "
                          "(isotropic, m = 1); 1 - m translates it (kinematic, Prager, m = 0).");
        prm.declare_entry("Integrator",
                          "adaptive",
                          Selection("forward euler|adaptive|backward euler"),
                          "Integration of the rate equations over a strain increment: "
                          "'forward euler' (one evaluation, the dissertation's scheme; stable "
                          "only for small increments), 'adaptive' (explicit sub-stepping with an "
                          "embedded error estimate and the Tolerance), 'backward euler' "
                          "(implicit, local Newton, consistent algorithmic tangent for Newton "
                          "solvers).");
        prm.declare_entry("Tolerance",
                          "1e-6",
                          Double(),
                          "Relative tolerance, > 0: local error per increment for 'adaptive', "
                          "residual of the local Newton iteration for 'backward euler'.");
        prm.enter_subsection("Degradation");
        {
          prm.declare_entry("Stiffness degradation c_eta",
                            "0",
                            Double(),
                            "c_eta >= 0 of eta' = c_eta eta^(-m_u) xi', xi the accumulated "
                            "plastic (intrinsic) strain; 0 switches stiffness degradation off.");
          prm.declare_entry("Stiffness degradation exponent m_u",
                            "1",
                            Double(),
                            "m_u >= 0, the exponent of 1/eta in the eta rate.");
          prm.declare_entry("Strength deterioration c_nu",
                            "0",
                            Double(),
                            "c_nu >= 0 of nu_s = 1 + c_nu e_h / (sigma_y eps_y), e_h the "
                            "dissipated energy density; 0 switches strength deterioration off.");
        }
        prm.leave_subsection();
        BoucWenFamilyParameters::declare_parameters(prm);
      }
      prm.leave_subsection();
    }

    std::vector<std::string>
    BoucWenParameters::parse_parameters(const Section &material)
    {
      std::vector<std::string> warnings;
      // (Read before the subsection is entered: a Section enters it in the handler.)
      const double             E = material.get_positive("Young's modulus");
      Section                  s(material, "Bouc-Wen");

      yield_stress     = s.get_positive("Yield stress");
      // The yield strain sigma_y / E of structural materials lies between about 1e-5
      // (soft clays, concrete in tension) and a few per cent. Below 1e-7 it is most likely
      // a unit slip (sigma_y in MPa with E in Pa), and the adaptive integrator would need
      // about 1e7 sub-steps per strain increment of 1; above 5 % (E in MPa or GPa with
      // sigma_y in Pa) the small-strain law is far outside its range. Both: a warning
      // (a scaled, dimensionless model may mean it).
      const double eps_y   = yield_stress / E;
      const auto   numbers = [&]() {
        std::ostringstream m;
        m << "the yield strain sigma_y / E = " << eps_y << " (yield stress " << yield_stress
          << " Pa, Young's modulus " << E << " Pa)";
        return m.str();
      };
      if (eps_y < 1e-7)
        warnings.push_back(s.where("Yield stress") + ": " + numbers() +
                           " is below 1e-7, far below that of any structural material (steel about "
                           "1e-3, concrete in tension 1e-4): a yield stress in MPa with Young's "
                           "modulus in Pa? Both are in Pa (235 MPa is 235e6)");
      if (eps_y > 0.05)
        warnings.push_back(s.where("Yield stress") + ": " + numbers() +
                           " is above 5 %, far outside the range of a small-strain law: check the units");
      post_yield_ratio = s.get_double("Post-yield stiffness ratio");
      require(post_yield_ratio >= 0 && post_yield_ratio < 1,
              s.where("Post-yield stiffness ratio"),
              "must lie in [0, 1) (got " + s.get("Post-yield stiffness ratio") + ")");
      smoothness = s.get_positive("Smoothness n");
      beta       = s.get_double("Beta");
      gamma      = s.get_double("Gamma");
      require(std::abs(gamma) <= beta,
              s.where("Gamma"),
              "must satisfy |gamma| <= beta for a thermodynamically admissible law (got beta = " +
                s.get("Beta") + ", gamma = " + s.get("Gamma") + ")");
      require(beta + gamma > 0,
              s.where("Beta"),
              "beta + gamma must be > 0 (got " + s.get("Beta") + " + " + s.get("Gamma") + ")");
      isotropic_fraction = s.get_double("Isotropic hardening fraction");
      require(isotropic_fraction >= 0 && isotropic_fraction <= 1,
              s.where("Isotropic hardening fraction"),
              "must lie in [0, 1] (got " + s.get("Isotropic hardening fraction") + ")");
      const std::string integrator_name = s.get("Integrator");
      integrator = integrator_name == "forward euler" ? BoucWenIntegrator::forward_euler :
                   integrator_name == "adaptive"      ? BoucWenIntegrator::adaptive :
                                                        BoucWenIntegrator::backward_euler;
      tolerance = s.get_positive("Tolerance");
      require(tolerance < 1, s.where("Tolerance"), "must be < 1 (got " + s.get("Tolerance") + ")");

      {
        Section d(s, "Degradation");
        stiffness_degradation_c_eta = d.get_non_negative("Stiffness degradation c_eta");
        stiffness_degradation_m_u   = d.get_non_negative("Stiffness degradation exponent m_u");
        strength_deterioration_c_nu = d.get_non_negative("Strength deterioration c_nu");
      }

      if (std::abs(beta + gamma - 1) > 1e-12)
        {
          std::ostringstream w;
          w << s.where("Beta") << ": beta + gamma = " << beta + gamma
            << " != 1, so the hysteretic variable saturates at z_y (beta + gamma)^(-1/n), not at "
               "the yield value";
          warnings.push_back(w.str());
        }
      if (smoothness < 1)
        warnings.push_back(s.where("Smoothness n") +
                           ": n < 1 gives a very gradual yield transition and an infinite "
                           "initial slope of |z|^n at z = 0");
      return warnings;
    }
  } // namespace Material
} // namespace hysteron
