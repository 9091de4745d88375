// Unit tests of the amplitudes (hysteron::Amplitude, `subsection Amplitude <name>`) and of the
// time integration of an amplified velocity.
#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/scene/amplitude.h>
#include <hysteron/scene/description.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

namespace
{
  using namespace hysteron;

  /// Parse the amplitudes of `entries` (name -> {entry -> value}).
  AmplitudeMap
  parse(const std::map<std::string, std::map<std::string, std::string>> &entries)
  {
    dealii::ParameterHandler prm;
    std::vector<std::string> names;
    for (const auto &e : entries)
      names.push_back(e.first);
    Amplitude::declare_parameters(prm, names);
    for (const auto &[name, values] : entries)
      {
        prm.enter_subsection("Amplitude " + name);
        for (const auto &[key, value] : values)
          prm.set(key, value);
        prm.leave_subsection();
      }
    return Amplitude::parse_all(prm, names, [](const std::string &f) { return f; });
  }
} // namespace

TEST(Amplitude, LinearStepAndConstantBeyondTheEnds)
{
  const auto a = parse({{"cycle", {{"Values", "0, 0; 1, 2; 3, -2; 4, 0"}}},
                        {"stairs", {{"Values", "1, 1; 2, 3"}, {"Interpolation", "step"}}}});
  const Amplitude &c = *a.at("cycle");
  EXPECT_EQ(c.value(-1), 0.0);
  EXPECT_EQ(c.value(0.25), 0.5);
  EXPECT_EQ(c.value(1), 2.0);
  EXPECT_DOUBLE_EQ(c.value(1.5), 1.0); // 2 + (-4) * 0.25
  EXPECT_DOUBLE_EQ(c.value(3.75), -0.5);
  EXPECT_EQ(c.value(10), 0.0);
  const Amplitude &s = *a.at("stairs");
  EXPECT_EQ(s.value(0.5), 1.0); // held before the first point
  EXPECT_EQ(s.value(1.999), 1.0);
  EXPECT_EQ(s.value(2), 3.0);
  EXPECT_EQ(s.value(5), 3.0);
  EXPECT_EQ(c.breakpoints(0.5, 3), std::vector<double>{1.0});
  EXPECT_EQ(c.breakpoints(0, 4), (std::vector<double>{1.0, 3.0}));
}

TEST(Amplitude, ReadsACsvFileWithHeaderAndComments)
{
  const std::string file = "amplitude_unit_test.csv";
  {
    std::ofstream out(file);
    out << "time,factor\n# a comment\n0, 0\n\n0.5 1\n1,\t-1\n";
  }
  const auto a = parse({{"f", {{"File", file}}}});
  EXPECT_EQ(a.at("f")->value(0.25), 0.5);
  EXPECT_EQ(a.at("f")->value(0.75), 0.0);
  std::remove(file.c_str());
}

TEST(Amplitude, InputErrorsNameTheEntryAndTheProblem)
{
  const auto message = [](const std::map<std::string, std::string> &values) {
    try
      {
        parse({{"a", values}});
      }
    catch (const InputError &e)
      {
        return std::string(e.what());
      }
    return std::string("no error");
  };
  EXPECT_NE(message({{"Values", "0, 0; 1, 1; 1, 2"}}).find("Amplitude a/Values: the times must increase strictly: point 3"),
            std::string::npos);
  EXPECT_NE(message({{"Values", "0, 0; 1"}}).find("'1' is not a pair"), std::string::npos);
  EXPECT_NE(message({}).find("needs its points"), std::string::npos);
  EXPECT_NE(message({{"Values", "0, 1"}, {"File", "x.csv"}}).find("not both"), std::string::npos);
  EXPECT_NE(message({{"File", "/nonexistent/amplitude.csv"}}).find("cannot open '/nonexistent/amplitude.csv'"),
            std::string::npos);
  // A NaN or an overflow does not read as a number at all.
  EXPECT_NE(message({{"Values", "0, nan"}}).find("is not a pair"), std::string::npos);
}

TEST(Amplitude, IntegralOfAnAmplifiedVelocityIsExactPieceByPiece)
{
  // v(t) = (1 + t^2, 3) times a(t) = 0, 0; 1, 2; 3, -2; 4, 0 over [0.5, 3.5], where
  // a = 2t on [0.5, 1], 4 - 2t on [1, 3] and 2t - 8 on [3, 3.5]. By hand:
  //   int_0.5^1 2t (1 + t^2) = [t^2 + t^4/2] = 1.5 - 0.28125,
  //   int_1^3 (4 - 2t)(1 + t^2) = [4t - t^2 + 4t^3/3 - t^4/2]_1^3,
  //   int_3^3.5 (2t - 8)(1 + t^2) = [t^2 - 8t + t^4/2 - 8t^3/3]_3^3.5,
  // and int 3 a = 3 (0.75 + 0 - 0.75) = 0.
  const auto a = parse({{"cycle", {{"Values", "0, 0; 1, 2; 3, -2; 4, 0"}}}});
  dealii::FunctionParser<1> v(2);
  v.initialize("t", "1 + t^2; 3", {});
  const auto G = [](const double t) { return 4 * t - t * t + 4 * t * t * t / 3 - t * t * t * t / 2; };
  const auto F = [](const double t) { return t * t - 8 * t + t * t * t * t / 2 - 8 * t * t * t / 3; };
  const double x = (1.5 - 0.28125) + (G(3) - G(1)) + (F(3.5) - F(3));
  const auto u = integrate_in_time<2>(v, 0.5, 3.5, a.at("cycle").get());
  EXPECT_NEAR(u[0], x, 1e-12);
  EXPECT_NEAR(u[1], 0.0, 1e-12);
  // Without the pieces (one Gauss rule over the kinks) the integral would be off.
  const auto whole = [&](const double t0, const double t1) {
    const double m = 0.5 * (t0 + t1), r = 0.5 * (t1 - t0), g = std::sqrt(0.6);
    double       s = 0;
    for (const auto &[t, w] : {std::make_pair(m - g * r, 5.0 / 9), std::make_pair(m, 8.0 / 9),
                               std::make_pair(m + g * r, 5.0 / 9)})
      s += w * a.at("cycle")->value(t) * (1 + t * t);
    return r * s;
  };
  EXPECT_GT(std::abs(whole(0.5, 3.5) - x), 1e-2);
}
