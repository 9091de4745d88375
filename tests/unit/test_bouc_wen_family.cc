// Unit tests of the Bouc-Wen family's uniaxial laws (Bouc-Wen/Uniaxial law), through the
// material's uniaxial_spring_law() as the RBSN and the oscillator use them:
// - the asymmetric law with equal yield values is the smooth law with the backward Euler
//   integrator (the same implicit step), spring by spring, to round-off;
// - every law's tangent is the derivative of its update (central differences);
// - the FEM-facing query continuum_unsupported() refuses every law but the smooth one;
// - OpenSees BoucWen does not scale with the yield value, the others do.

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>
#include <hysteron/material/interface.h>

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace hysteron;

namespace
{
  /// A Bouc-Wen material (E = 200 GPa, sigma_y = 200 MPa, a = 0.05, n = 3, backward Euler)
  /// whose springs follow @p law, with @p entries (subsection, entry, value) set.
  std::unique_ptr<Material::Interface<2>>
  make_material(const std::string &law, const std::vector<std::vector<std::string>> &entries = {})
  {
    dealii::ParameterHandler prm;
    prm.enter_subsection("Material");
    Material::declare_parameters(prm);
    prm.set("Model", "bouc-wen");
    prm.set("Young's modulus", "200e9");
    prm.enter_subsection("Bouc-Wen");
    prm.set("Yield stress", "200e6");
    prm.set("Post-yield stiffness ratio", "0.05");
    prm.set("Smoothness n", "3");
    prm.set("Integrator", "backward euler");
    prm.set("Tolerance", "1e-13");
    prm.set("Uniaxial law", law);
    for (const auto &e : entries)
      {
        prm.enter_subsection(e[0]);
        prm.set(e[1], e[2]);
        prm.leave_subsection();
      }
    prm.leave_subsection();
    prm.leave_subsection();
    return Material::create<2>(Section(prm, {"Material"}));
  }

  /// A path of increments over growing cycles (about 8 yield deformations of 1e-3 at the end).
  std::vector<double>
  increments(const unsigned int n)
  {
    std::vector<double> d;
    double              last = 0;
    for (unsigned int i = 1; i <= n; ++i)
      {
        const double t    = 4.0 * i / n;
        const double next = 2e-3 * t * std::sin(2 * M_PI * t);
        d.push_back(next - last);
        last = next;
      }
    return d;
  }
} // namespace



TEST(BoucWenFamily, AsymmetricWithEqualYieldIsTheSmoothBackwardEuler)
{
  const auto smooth = make_material("smooth")->uniaxial_spring_law();
  const auto asym   = make_material("asymmetric")->uniaxial_spring_law();
  std::vector<double> s_state(smooth->n_state_variables()), a_state(asym->n_state_variables());
  smooth->add_spring(200e9, 200e6, s_state.data());
  asym->add_spring(200e9, 200e6, a_state.data());
  double      fs = 0, fa = 0, ts = 0, ta = 0, worst = 0;
  std::string failure;
  for (double d : increments(400))
    {
      ASSERT_EQ(smooth->update(0, 1, &d, &fs, s_state.data(), &ts, 1, failure), 1u) << failure;
      ASSERT_EQ(asym->update(0, 1, &d, &fa, a_state.data(), &ta, 1, failure), 1u) << failure;
      worst = std::max(worst, std::abs(fs - fa));
      EXPECT_NEAR(ts, ta, 1e-6 * 200e9);
    }
  EXPECT_LT(worst, 1e-9 * 200e6) << "largest force difference " << worst << " N";
}



TEST(BoucWenFamily, TangentIsTheDerivativeOfTheUpdate)
{
  const std::vector<std::pair<std::string, std::vector<std::vector<std::string>>>> laws{
    {"pinching",
     {{"Pinching", "zeta_s", "0.8"}, {"Pinching", "delta_nu", "0.01"}, {"Pinching", "delta_eta", "0.02"}, {"Pinching", "delta_A", "0.001"}}},
    {"asymmetric", {{"Asymmetric", "Compression yield ratio", "1.7"}}},
    {"OpenSees BoucWen",
     {{"OpenSees BoucWen", "beta", "6e5"}, {"OpenSees BoucWen", "gamma", "4e5"}, {"OpenSees BoucWen", "n", "2"},
      {"OpenSees BoucWen", "deltaNu", "1e-6"}, {"OpenSees BoucWen", "deltaEta", "1e-6"}}},
    {"OpenSees BoucWenOriginal", {{"OpenSees BoucWenOriginal", "alphaNL", "1e-3"}, {"OpenSees BoucWenOriginal", "eta", "2"}}}};
  for (const auto &[name, entries] : laws)
    {
      const auto law = make_material(name, entries)->uniaxial_spring_law();
      std::vector<double> state(law->n_state_variables());
      law->add_spring(200e9, 200e6, state.data());
      double      force = 0, tangent = 0;
      std::string failure;
      unsigned int checked = 0;
      for (double d : increments(200))
        {
          // Central difference of the update from the same start, h = 1e-7 of the increment
          // scale (the update is smooth away from the sign switch of the increment).
          const double h = 1e-10;
          double       fp = force, fm = force, dp = d + h, dm = d - h, t = 0;
          std::vector<double> sp = state, sm = state, s0 = state;
          ASSERT_EQ(law->update(0, 1, &dp, &fp, sp.data(), nullptr, 1, failure), 1u) << failure;
          ASSERT_EQ(law->update(0, 1, &dm, &fm, sm.data(), nullptr, 1, failure), 1u) << failure;
          ASSERT_EQ(law->update(0, 1, &d, &force, state.data(), &t, 1, failure), 1u) << failure;
          const double fd = (fp - fm) / (2 * h);
          if (std::abs(d) > 1e-6 && s0[0] * state[0] > 0) // no sign switch of z inside
            {
              EXPECT_NEAR(t, fd, 1e-5 * 200e9) << name << " at z = " << state[0];
              ++checked;
            }
          tangent = t;
        }
      EXPECT_GT(checked, 100u) << name;
      EXPECT_TRUE(std::isfinite(tangent)) << name;
    }
}



TEST(BoucWenFamily, ContinuumAndYieldValueQueries)
{
  EXPECT_EQ(make_material("smooth")->continuum_unsupported(), "");
  for (const std::string name : {"pinching", "asymmetric", "OpenSees BoucWen", "OpenSees BoucWenOriginal"})
    {
      const auto material = make_material(name);
      EXPECT_NE(material->continuum_unsupported().find("Uniaxial law = " + name), std::string::npos);
      EXPECT_EQ(material->uniaxial_spring_law()->scales_with_yield_value(), name != "OpenSees BoucWen");
    }
}
