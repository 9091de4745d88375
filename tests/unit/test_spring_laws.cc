// Unit tests of the registered RBSN facet spring laws (hysteron::RBSN::SpringLaw<dim>), created
// by name through SpringLawRegistry<dim> as a scene does, for the 2D facet (3 springs) and the
// 3D facet (6 springs: normal, two shear, two bending, torsion), between cells of two Bouc-Wen
// materials: the yield values of FacetSprings<dim>::yield_values against the section formulas,
// the elastic response F = k delta, the forces reached under monotonic loading of each spring
// alone (F_y,i), and the consistency of variable_order_unsupported() with uniaxial_spring().

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include <hysteron/material/interface.h>
#include <hysteron/rbsn/spring_law.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace hysteron;

namespace
{
  constexpr double E = 210e9, nu = 0.3, G = E / (2 * (1 + nu));

  std::string
  str(const double x)
  {
    std::ostringstream s;
    s << std::setprecision(17) << x;
    return s.str();
  }

  /// A material of `Model = model` (Bouc-Wen: yield stress @p sigma_y, a = 0, n = 20,
  /// beta = gamma = 1/2, the integrator @p integrator).
  template <int dim>
  std::unique_ptr<Material::Interface<dim>>
  make_material(const std::string &model,
                const double       sigma_y    = 240e6,
                const std::string &integrator = "backward euler")
  {
    dealii::ParameterHandler prm;
    prm.enter_subsection("Material");
    Material::declare_parameters(prm);
    prm.leave_subsection();
    prm.enter_subsection("Material");
    prm.set("Model", model);
    prm.set("Young's modulus", str(E));
    prm.set("Poisson's ratio", str(nu));
    prm.enter_subsection("Bouc-Wen");
    prm.set("Yield stress", str(sigma_y));
    prm.set("Post-yield stiffness ratio", "0");
    prm.set("Smoothness n", "20");
    prm.set("Beta", "0.5");
    prm.set("Gamma", "0.5");
    prm.set("Integrator", integrator);
    prm.set("Tolerance", "1e-10");
    prm.leave_subsection();
    prm.leave_subsection();
    return Material::create<dim>(Section(prm, {"Material"}));
  }

  /**
   * The springs of a facet of size @p scale and the yield values expected for @p sigma_y,
   * from the section formulas (not from FacetSprings::yield_values, which is checked
   * against them):
   * - 2D: a facet of length l and thickness t between nuclei h apart, k_n = E t l / h,
   *   k_t = G t l / h, k_phi = k_n l^2 / 12; N_y = sigma_y t l, V_y = N_y / sqrt(3),
   *   M_y = sigma_y t l^2 / 4 (the plastic moment of the section t x l).
   * - 3D: a rectangle b x h (b along s_1, h along s_2) between nuclei L apart, k_n = E A / L,
   *   k_s = G A / L, k_b,i = E I_i / L, k_t = G J / L (I_1 = b h^3 / 12 about s_1,
   *   I_2 = h b^3 / 12 about s_2, J = I_1 + I_2); N_y = sigma_y A, V_y = sigma_y A / sqrt(3),
   *   M_y,1 = sigma_y b h^2 / 4 and M_y,2 = sigma_y h b^2 / 4 (the plastic moments), and the
   *   torque T_y = (1/4) (sigma_y / sqrt(3)) A sqrt(12 J / A) = tau_y b h sqrt(b^2 + h^2) / 4.
   */
  template <int dim>
  struct TestFacet
  {
    RBSN::FacetSprings<dim>                    springs;
    std::array<double, RBSN::n_springs<dim>> yield;

    TestFacet(const double scale, const double sigma_y)
    {
      const double tau_y = sigma_y / std::sqrt(3.0);
      if constexpr (dim == 2)
        {
          const double l = 0.05 * scale, t = 0.02, h = 0.04 * scale;
          springs.k                 = {{E * t * l / h, G * t * l / h, E * t * l / h * l * l / 12}};
          springs.thickness         = t;
          springs.length            = l;
          springs.area              = t * l;
          springs.second_moments[0] = t * l * l * l / 12;
          yield                     = {{sigma_y * t * l, tau_y * t * l, sigma_y * t * l * l / 4}};
        }
      else
        {
          const double b = 0.1 * scale, h = 0.05 * scale, L = 0.08 * scale, A = b * h;
          const double I_1 = b * h * h * h / 12, I_2 = h * b * b * b / 12, J = I_1 + I_2;
          springs.k = {{E * A / L, G * A / L, G * A / L, E * I_1 / L, E * I_2 / L, G * J / L}};
          springs.area           = A;
          springs.second_moments = {{I_1, I_2}};
          springs.length         = std::sqrt(A);
          yield                  = {{sigma_y * A,
                                     tau_y * A,
                                     tau_y * A,
                                     sigma_y * b * h * h / 4,
                                     sigma_y * h * b * b / 4,
                                     tau_y * b * h * std::sqrt(b * b + h * h) / 4}};
        }
    }
  };

  template <int dim>
  class SpringLaws : public ::testing::Test
  {
  public:
    static constexpr unsigned int n = RBSN::n_springs<dim>;
    using Law                       = RBSN::SpringLaw<dim>;
    using Vector                    = typename Law::Vector;
    using Matrix                    = typename Law::Matrix;

    /// Cell a yields at 240 MPa, cell b at 300 MPa: the facet at the smaller one.
    const std::unique_ptr<Material::Interface<dim>> a = make_material<dim>("bouc-wen", 240e6),
                                                    b = make_material<dim>("bouc-wen", 300e6);
    const double                                    sigma_y = 240e6;
    /// Two facets of different size (the laws keep their data per facet).
    const std::vector<TestFacet<dim>> facets{TestFacet<dim>(1, 240e6), TestFacet<dim>(2.5, 240e6)};

    /// Every registered law, created by name as `RBSN/Spring law` does, with its facets set
    /// up and each facet's initial state.
    struct Created
    {
      std::string                      name;
      std::unique_ptr<Law>             law;
      std::vector<std::vector<double>> states;
    };

    std::vector<Created>
    create_all() const
    {
      std::vector<Created> all;
      for (const auto &entry : RBSN::SpringLawRegistry<dim>::entries())
        {
          Created c;
          c.name = entry.name;
          c.law  = RBSN::SpringLawRegistry<dim>::create(entry.name, "RBSN/Spring law");
          EXPECT_EQ(c.law->unsupported(*a), "") << c.name;
          EXPECT_EQ(c.law->unsupported(*b), "") << c.name;
          // The network hands the law its bodies' materials before the facets.
          c.law->initialize({a.get(), b.get()});
          for (unsigned int e = 0; e < facets.size(); ++e)
            {
              c.states.emplace_back(c.law->n_state_variables(), -1.0);
              EXPECT_TRUE(c.law->setup_facet(e, facets[e].springs, *a, *b, c.states[e].data()))
                << c.name << ": the facet between two Bouc-Wen cells is hysteretic";
            }
          all.push_back(std::move(c));
        }
      return all;
    }
  };

  using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;

  class DimensionName
  {
  public:
    template <typename T>
    static std::string
    GetName(int)
    {
      return std::to_string(T::value) + "D";
    }
  };

  template <typename T>
  class SpringLawsIn : public SpringLaws<T::value>
  {};
} // namespace

TYPED_TEST_SUITE(SpringLawsIn, Dimensions, DimensionName);



// The built-in laws are registered for both dimensions; FacetSprings::yield_values gives the
// section's values (2D: N, V, M; 3D: N, V_1, V_2, the plastic moments M_1, M_2 and the torque
// T_y = (1/4) tau_y A sqrt(12 J / A)), relative 1e-14.
TYPED_TEST(SpringLawsIn, RegisteredLawsAndYieldValues)
{
  constexpr int dim = TypeParam::value;
  for (const std::string name : {"coupled", "elastic-perfectly-plastic", "uncoupled"})
    EXPECT_TRUE(RBSN::SpringLawRegistry<dim>::has(name)) << name;
  EXPECT_THROW(RBSN::SpringLawRegistry<dim>::create("no such law", "RBSN/Spring law"), InputError);
  for (const auto &facet : this->facets)
    {
      const auto y = facet.springs.yield_values(this->sigma_y);
      for (unsigned int i = 0; i < this->n; ++i)
        EXPECT_NEAR(y[i], facet.yield[i], 1e-14 * facet.yield[i]) << RBSN::spring_name<dim>(i);
    }
}



// Small deformations (1e-3 z_y,i) are elastic for every law: F = k delta on each spring alone
// and on all n together (relative 1e-10), the tangent is K, H1 at most 1e-3 and the strain
// energy is 1/2 k delta^2; facets of two sizes.
TYPED_TEST(SpringLawsIn, SmallDeformationsAreElastic)
{
  constexpr int          dim = TypeParam::value;
  constexpr unsigned int n   = RBSN::n_springs<dim>;
  using Vector               = typename SpringLaws<dim>::Vector;
  using Matrix               = typename SpringLaws<dim>::Matrix;
  for (auto &c : this->create_all())
    for (unsigned int e = 0; e < this->facets.size(); ++e)
      {
        const auto &facet = this->facets[e];
        // Spring i alone (m = i), then all together (m = n).
        for (unsigned int m = 0; m <= n; ++m)
          {
            std::vector<double> state = c.states[e];
            Vector              delta{}, F{};
            for (unsigned int i = 0; i < n; ++i)
              if (m == n || i == m)
                delta[i] = (i % 2 ? -1e-3 : 1e-3) * facet.yield[i] / facet.springs.k[i];
            Matrix T;
            c.law->update(e, delta, F, state.data(), &T);
            for (unsigned int i = 0; i < n; ++i)
              {
                const double expected = facet.springs.k[i] * delta[i];
                EXPECT_NEAR(F[i], expected, 1e-10 * 1e-3 * facet.yield[i])
                  << c.name << ", " << dim << "D, facet " << e << ", " << RBSN::spring_name<dim>(i)
                  << " spring, loaded: " << (m == n ? "all" : RBSN::spring_name<dim>(m));
                for (unsigned int j = 0; j < n; ++j)
                  EXPECT_NEAR(T[i][j], i == j ? facet.springs.k[i] : 0.0,
                              1e-10 * std::sqrt(facet.springs.k[i] * facet.springs.k[j]))
                    << c.name << ", " << dim << "D, D(" << i << ", " << j << ")";
                // Bouc-Wen: Phi^n, ~0; elastic-perfectly-plastic: |F_i| / F_y,i <= 1e-3.
                EXPECT_LE(c.law->h1(e, i, state.data()), 1e-3 * (1 + 1e-9)) << c.name;
                EXPECT_NEAR(c.law->strain_energy(e, i, delta[i], state.data()),
                            0.5 * facet.springs.k[i] * delta[i] * delta[i],
                            1e-9 * 0.5 * facet.springs.k[i] * delta[i] * delta[i] + 1e-300)
                  << c.name << ", " << RBSN::spring_name<dim>(i);
              }
          }
      }
}



// Monotonic loading of each spring alone to 30 z_y,i (300 increments): the force reaches the
// spring's yield value F_y,i (relative 1e-3; a = 0, n = 20, so the Bouc-Wen laws saturate at
// F_y), H1 is 1 (to 1e-3), the other springs carry nothing; reversed loading reaches -F_y,i.
// For the coupled law this is the single-component case of its yield criterion.
TYPED_TEST(SpringLawsIn, EachSpringAloneYieldsAtItsYieldValue)
{
  constexpr int          dim = TypeParam::value;
  constexpr unsigned int n   = RBSN::n_springs<dim>;
  using Vector               = typename SpringLaws<dim>::Vector;
  using Matrix               = typename SpringLaws<dim>::Matrix;
  for (auto &c : this->create_all())
    {
      double worst = 0;
      for (unsigned int e = 0; e < this->facets.size(); ++e)
        for (unsigned int i = 0; i < n; ++i)
          for (const double sign : {1.0, -1.0})
            {
              const auto         &facet = this->facets[e];
              std::vector<double> state = c.states[e];
              Vector              F{};
              const double        z_y = facet.yield[i] / facet.springs.k[i];
              Matrix              T;
              for (unsigned int j = 0; j < 300; ++j)
                {
                  Vector dd{};
                  dd[i] = sign * 0.1 * z_y;
                  c.law->update(e, dd, F, state.data(), &T);
                }
              const double error = std::abs(F[i] - sign * facet.yield[i]) / facet.yield[i];
              worst              = std::max(worst, error);
              EXPECT_LT(error, 1e-3) << c.name << ", " << dim << "D, facet " << e << ", "
                                     << RBSN::spring_name<dim>(i) << " spring, sign " << sign
                                     << ": F = " << F[i] << ", F_y = " << facet.yield[i];
              EXPECT_NEAR(c.law->h1(e, i, state.data()), 1.0, 1e-3) << c.name;
              // At yield the tangent of the loaded spring is (nearly) zero.
              EXPECT_LT(std::abs(T[i][i]), 1e-3 * facet.springs.k[i]) << c.name;
              for (unsigned int m = 0; m < n; ++m)
                if (m != i)
                  {
                    EXPECT_EQ(F[m], 0.0) << c.name << ", " << RBSN::spring_name<dim>(m);
                  }
            }
      std::cout << "  " << dim << "D, " << c.name << ": max |F / F_y,i - 1| = " << worst << std::endl;
    }
}



// `Analysis = variable order` takes a law's uniaxial springs: a law that supports it
// (variable_order_unsupported() == "") gives every spring of a hysteretic facet a uniaxial
// law with the facet's k_i and F_y,i and a distinct state offset inside the facet's state;
// a law that does not gives none and says why.
TYPED_TEST(SpringLawsIn, VariableOrderAndUniaxialSpringsAgree)
{
  constexpr int          dim = TypeParam::value;
  constexpr unsigned int n   = RBSN::n_springs<dim>;
  for (auto &c : this->create_all())
    for (unsigned int e = 0; e < this->facets.size(); ++e)
      {
        const bool supported = c.law->variable_order_unsupported().empty();
        if (c.name == "uncoupled")
          {
            EXPECT_TRUE(supported);
          }
        std::set<unsigned int> offsets;
        for (unsigned int i = 0; i < n; ++i)
          {
            const auto spring = c.law->uniaxial_spring(e, i);
            if (!supported)
              {
                EXPECT_EQ(spring.law, nullptr) << c.name;
                continue;
              }
            ASSERT_NE(spring.law, nullptr) << c.name << ", " << RBSN::spring_name<dim>(i);
            EXPECT_EQ(spring.law->stiffness(), this->facets[e].springs.k[i]) << c.name;
            const double yield = this->facets[e].yield[i];
            EXPECT_NEAR(spring.law->yield_value(), yield, 1e-14 * yield)
              << c.name << ", " << RBSN::spring_name<dim>(i);
            EXPECT_LE(spring.offset + spring.law->n_state_variables(), c.law->n_state_variables())
              << c.name;
            offsets.insert(spring.offset);
          }
        if (supported)
          {
            EXPECT_EQ(offsets.size(), n) << c.name;
          }
      }
}



// Facets between a Bouc-Wen cell and a linear elastic one are linear (setup_facet() returns
// false: the network handles F = k delta itself).
TYPED_TEST(SpringLawsIn, LinearElasticNeighboursGiveLinearSprings)
{
  constexpr int dim     = TypeParam::value;
  const auto    elastic = make_material<dim>("linear elastic");
  for (const auto &entry : RBSN::SpringLawRegistry<dim>::entries())
    {
      const auto          law = RBSN::SpringLawRegistry<dim>::create(entry.name, "RBSN/Spring law");
      std::vector<double> state(law->n_state_variables());
      EXPECT_FALSE(law->setup_facet(0, this->facets[0].springs, *this->a, *elastic, state.data()))
        << entry.name;
      EXPECT_FALSE(law->setup_facet(1, this->facets[1].springs, *elastic, *this->a, state.data()))
        << entry.name;
    }
}
