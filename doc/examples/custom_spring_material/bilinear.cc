// A material whose springs are bilinear with kinematic hardening, as a hysteron plugin: what a
// user writes so that a material of their own drives the springs of a Rigid-Body-Spring
// Network (`set Method = rbsn` with the default `Spring law = uncoupled`). Build it against the
// installed package (CMakeLists.txt beside this file) and load it with
// `set Additional shared libraries = ./build/libcustom_spring_material.so`.
//
// Springs: a spring of stiffness k and yield value F_y (the network scales `Yield stress` by
// the facet's section) is elastic, F = k (delta - delta_p), inside |F - X| <= F_y, and hardens
// kinematically beyond: X' = H delta_p', with H = alpha k / (1 - alpha), so that the tangent
// at yield is k H / (k + H) = alpha k (alpha = `Hardening ratio`). The update is the exact
// return map of an increment (the law is piecewise linear): the trial force F + k d delta
// leaves the elastic range by f = |F_trial - X| - F_y > 0, then d lambda = f / (k + H),
// F = F_trial - k d lambda s, X += H d lambda s, delta_p += d lambda s (s = sgn(F_trial - X)).
// State per spring: delta_p, X and |F - X| / F_y (the H1 output).
//
// As a continuum (mpm, fem, material point) the example is linear elastic: it shows the
// spring interface only.
#include <deal.II/base/parameter_handler.h>

#include <hysteron/material/interface.h>
#include <hysteron/material/uniaxial_spring_law.h>

#include <cmath>
#include <memory>
#include <vector>

namespace custom
{
  using namespace dealii;

  class BilinearSprings : public hysteron::Material::UniaxialSpringLaw
  {
  public:
    BilinearSprings(const double sigma_y, const double alpha)
      : sigma_y(sigma_y)
      , alpha(alpha)
    {}

    double
    yield_stress() const override
    {
      return sigma_y;
    }

    unsigned int
    n_state_variables() const override
    {
      return 3;
    }

    unsigned int
    add_spring(const double k, const double yield_value, double *state) override
    {
      springs.push_back({k, yield_value, alpha * k / (1 - alpha)});
      state[0] = state[1] = state[2] = 0;
      return springs.size() - 1;
    }

    unsigned int
    update(const unsigned int first,
           const unsigned int n,
           const double      *increment,
           double            *force,
           double            *state,
           double            *tangent,
           const unsigned int tangent_stride,
           std::string &) const override
    {
      for (unsigned int i = 0; i < n; ++i)
        {
          const Spring &p     = springs[first + i];
          double       *s     = state + 3 * i;
          const double  trial = force[i] + p.k * increment[i];
          const double  f     = std::abs(trial - s[1]) - p.yield;
          double        dF    = p.k;
          force[i]            = trial;
          if (f > 0)
            {
              const double dlambda = std::copysign(f / (p.k + p.H), trial - s[1]);
              force[i] -= p.k * dlambda;
              s[0] += dlambda;
              s[1] += p.H * dlambda;
              dF = p.k * p.H / (p.k + p.H);
            }
          s[2] = std::abs(force[i] - s[1]) / p.yield;
          if (tangent)
            tangent[i * tangent_stride] = dF;
        }
      return n;
    }

    double
    h1(const unsigned int, const double *state) const override
    {
      return state[2];
    }

    /// 1/2 k (delta - delta_p)^2 (the energy stored by the hardening is not recoverable).
    double
    strain_energy(const unsigned int spring, const double delta, const double *state) const override
    {
      const double elastic = delta - state[0];
      return 0.5 * springs[spring].k * elastic * elastic;
    }

  private:
    struct Spring
    {
      double k, yield, H;
    };
    const double        sigma_y, alpha;
    std::vector<Spring> springs;
  };



  template <int dim>
  class Bilinear : public hysteron::Material::Interface<dim>
  {
  public:
    static void
    declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Bilinear springs");
      prm.declare_entry("Yield stress", "235e6", Patterns::Double(), "sigma_y [Pa], > 0.");
      prm.declare_entry("Hardening ratio", "0.1", Patterns::Double(0, 1),
                        "alpha [-] in [0, 1): the tangent after yield over the elastic one.");
      prm.leave_subsection();
    }

    unsigned int
    n_state_variables() const override
    {
      return 0;
    }

    std::vector<std::string>
    state_variable_names() const override
    {
      return {};
    }

    /// Hooke's law.
    void
    update(const ArrayView<const SymmetricTensor<2, dim>> &strain_increments,
           const ArrayView<SymmetricTensor<2, dim>>       &stresses,
           const ArrayView<double> &,
           const ArrayView<SymmetricTensor<4, dim>> &tangents) const override
    {
      for (std::size_t p = 0; p < strain_increments.size(); ++p)
        {
          stresses[p] += stiffness * strain_increments[p];
          if (tangents.size() > 0)
            tangents[p] = stiffness;
        }
    }

    std::unique_ptr<hysteron::Material::UniaxialSpringLaw>
    uniaxial_spring_law() const override
    {
      return std::make_unique<BilinearSprings>(sigma_y, alpha);
    }

  protected:
    void
    parse_parameters(const hysteron::Section &material) override
    {
      hysteron::Section s(material, "Bilinear springs");
      sigma_y   = s.get_positive("Yield stress");
      alpha     = s.get_non_negative("Hardening ratio");
      stiffness = this->elasticity().template stiffness<dim>();
      hysteron::require(alpha < 1, s.where("Hardening ratio"), "must be below 1");
    }

  private:
    double                  sigma_y = 235e6, alpha = 0.1;
    SymmetricTensor<4, dim> stiffness;
  };
} // namespace custom

HYSTERON_REGISTER_MATERIAL(custom::Bilinear,
                           "bilinear springs",
                           "example plugin: RBSN springs bilinear with kinematic hardening, a "
                           "linear elastic continuum (doc/examples/custom_spring_material)")
