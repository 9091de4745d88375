// The parameters of the Bouc-Wen family's uniaxial laws (`Bouc-Wen/Uniaxial law`).
#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_family.h>

#include <array>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      using dealii::ParameterHandler;
      using dealii::Patterns::Double;

      /// Entries of type Double in @p subsection: (name, default, documentation) each.
      void
      declare_doubles(ParameterHandler                                  &prm,
                      const char                                        *subsection,
                      const std::vector<std::array<const char *, 3>>    &entries)
      {
        prm.enter_subsection(subsection);
        for (const auto &e : entries)
          prm.declare_entry(e[0], e[1], Double(), e[2]);
        prm.leave_subsection();
      }

      void
      declare_pinching(ParameterHandler &prm)
      {
        declare_doubles(prm,
                        "Pinching",
                        {{{"alpha", "0", "Post-yield stiffness ratio in [0, 1)."}},
                         {{"n", "2", "Exponent n > 0 of |w|^n."}},
                         {{"beta", "0.5", "Factor of sgn(w x') (Foliente's and OpenSees' beta)."}},
                         {{"gamma", "0.5", "The constant term; beta + gamma > 0."}},
                         {{"A0", "1", "Initial A > 0 (the initial tangent is alpha k + (1 - alpha) k A0)."}},
                         {{"delta_A", "0", "A = A0 - delta_A e, >= 0 (e the normalised dissipated energy)."}},
                         {{"delta_nu", "0", "Strength deterioration nu = 1 + delta_nu e, >= 0."}},
                         {{"delta_eta", "0", "Stiffness degradation eta = 1 + delta_eta e, >= 0."}},
                         {{"zeta_s", "0", "Pinching: its measure in [0, 1) (0: no pinching)."}},
                         {{"p", "1", "Pinching: the rate of its onset with e, >= 0."}},
                         {{"q", "0.1", "Pinching: the fraction of the ultimate w_u where it acts, in [0, 1)."}},
                         {{"psi_0", "0.2", "Pinching: the initial spread, > 0."}},
                         {{"delta_psi", "0.005", "Pinching: the growth of the spread with e, >= 0."}},
                         {{"lambda", "0.5", "Pinching: the coupling of spread and severity, > 0."}}});
      }

      void
      declare_opensees(ParameterHandler &prm)
      {
        declare_doubles(prm,
                        "OpenSees BoucWen",
                        {{{"alpha", "0", "alpha of `uniaxialMaterial BoucWen`, [0, 1)."}},
                         {{"n", "1", "n, > 0."}},
                         {{"gamma", "0.5", "gamma (the constant term) [delta^-n]."}},
                         {{"beta", "0.5", "beta (factor of sgn(z delta')) [delta^-n]; beta + gamma > 0."}},
                         {{"Ao", "1", "Ao, > 0."}},
                         {{"deltaA", "0", "deltaA, >= 0."}},
                         {{"deltaNu", "0", "deltaNu, >= 0."}},
                         {{"deltaEta", "0", "deltaEta, >= 0."}}});
        declare_doubles(prm,
                        "OpenSees BoucWenOriginal",
                        {{{"alphaL", "0", "alphaL of `uniaxialMaterial BoucWenOriginal`, [0, 1)."}},
                         {{"alphaNL", "0", "alphaNL, >= 0."}},
                         {{"mu", "2", "mu, the exponent of the nonlinear elastic term, >= 1."}},
                         {{"eta", "1", "eta, the exponent of |u| (n of the other laws), > 0."}},
                         {{"beta", "0.5", "beta (factor of sgn(u delta'))."}},
                         {{"gamma", "0.5", "gamma (the constant term); beta + gamma > 0."}}});
      }

      void
      parse_shape(const Section &s, BoucWenFamilyParameters &p, const char *n_name)
      {
        p.n = s.get_positive(n_name);
        p.beta  = s.get_double("beta");
        p.gamma = s.get_double("gamma");
        require(p.beta + p.gamma > 0,
                s.where("beta"),
                "beta + gamma must be > 0 for the hysteretic variable to saturate (got " +
                  s.get("beta") + " + " + s.get("gamma") + ")");
      }

      double
      get_fraction(const Section &s, const char *entry)
      {
        const double value = s.get_double(entry);
        require(value >= 0 && value < 1, s.where(entry), "must lie in [0, 1) (got " + s.get(entry) + ")");
        return value;
      }

      void
      parse_degradation(const Section &s, BoucWenFamilyParameters &p, const bool opensees)
      {
        p.A0        = s.get_positive(opensees ? "Ao" : "A0");
        p.delta_A   = s.get_non_negative(opensees ? "deltaA" : "delta_A");
        p.delta_nu  = s.get_non_negative(opensees ? "deltaNu" : "delta_nu");
        p.delta_eta = s.get_non_negative(opensees ? "deltaEta" : "delta_eta");
      }
    } // namespace



    void
    BoucWenFamilyParameters::declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry(
        "Uniaxial law",
        "smooth",
        dealii::Patterns::Selection("smooth|pinching|asymmetric|OpenSees BoucWen|OpenSees BoucWenOriginal"),
        "The law of the material's springs and uniaxial points (RBSN springs, oscillator storeys, "
        "the uniaxial bench; the FEM and MPM use the smooth triaxial law and refuse the others): "
        "smooth (this subsection's law); pinching (Baber-Noori with Foliente's parameters, "
        "subsection Pinching); asymmetric (the smooth law with `Asymmetric/Compression yield "
        "ratio`); OpenSees BoucWen and OpenSees BoucWenOriginal (OpenSees' uniaxial materials of "
        "these names, their numbers copied into the subsections of the same names; k and the "
        "yield value come from the host: E and the Yield stress, a storey's stiffness and yield "
        "force, a facet spring's). All but smooth take one implicit step per increment, as "
        "OpenSees does (doc/theory.md, 'The Bouc-Wen family').");
      declare_pinching(prm);
      prm.enter_subsection("Asymmetric");
      prm.declare_entry("Compression yield ratio",
                        "1",
                        Double(),
                        "The yield value in compression (z < 0) over that in tension, > 0; the "
                        "other constants are the smooth law's (Post-yield stiffness ratio, "
                        "Smoothness n, Beta, Gamma), without degradation.");
      prm.leave_subsection();
      declare_opensees(prm);
    }



    void
    BoucWenFamilyParameters::parse_parameters(const Section &bouc_wen, const BoucWenParameters &smooth)
    {
      const std::string law = bouc_wen.get("Uniaxial law");
      variant = law == "pinching"         ? UniaxialVariant::pinching :
                law == "asymmetric"       ? UniaxialVariant::asymmetric :
                law == "OpenSees BoucWen" ? UniaxialVariant::opensees_bouc_wen :
                law == "OpenSees BoucWenOriginal" ? UniaxialVariant::opensees_bouc_wen_original :
                                                    UniaxialVariant::smooth;
      switch (variant)
        {
          case UniaxialVariant::pinching:
            {
              Section s(bouc_wen, "Pinching");
              alpha = get_fraction(s, "alpha");
              parse_shape(s, *this, "n");
              parse_degradation(s, *this, false);
              zeta_s    = get_fraction(s, "zeta_s");
              p         = s.get_non_negative("p");
              q         = get_fraction(s, "q");
              psi0      = s.get_positive("psi_0");
              delta_psi = s.get_non_negative("delta_psi");
              lambda    = s.get_positive("lambda");
              break;
            }
          case UniaxialVariant::asymmetric:
            {
              Section s(bouc_wen, "Asymmetric");
              compression_ratio = s.get_positive("Compression yield ratio");
              require(!smooth.degradation(),
                      bouc_wen.where("Uniaxial law"),
                      "the asymmetric law has no degradation: set the Degradation constants to 0");
              alpha = smooth.post_yield_ratio;
              n     = smooth.smoothness;
              beta  = smooth.beta;
              gamma = smooth.gamma;
              break;
            }
          case UniaxialVariant::opensees_bouc_wen:
            {
              Section s(bouc_wen, "OpenSees BoucWen");
              alpha = get_fraction(s, "alpha");
              parse_shape(s, *this, "n");
              parse_degradation(s, *this, true);
              break;
            }
          case UniaxialVariant::opensees_bouc_wen_original:
            {
              Section s(bouc_wen, "OpenSees BoucWenOriginal");
              alpha_L  = get_fraction(s, "alphaL");
              alpha_NL = s.get_non_negative("alphaNL");
              mu       = s.get_double("mu");
              require(mu >= 1, s.where("mu"), "must be >= 1 (got " + s.get("mu") + ")");
              parse_shape(s, *this, "eta");
              break;
            }
          default:
            break;
        }
    }



    std::string
    BoucWenFamilyParameters::name() const
    {
      switch (variant)
        {
          case UniaxialVariant::pinching:
            return "pinching";
          case UniaxialVariant::asymmetric:
            return "asymmetric";
          case UniaxialVariant::opensees_bouc_wen:
            return "OpenSees BoucWen";
          case UniaxialVariant::opensees_bouc_wen_original:
            return "OpenSees BoucWenOriginal";
          default:
            return "smooth";
        }
    }
  } // namespace Material
} // namespace hysteron
