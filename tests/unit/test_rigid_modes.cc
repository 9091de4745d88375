// The rigid-body-mode check of static analyses: which supports leave which motions free.
#include <hysteron/base/parameters.h>
#include <hysteron/base/rigid_modes.h>

#include <gtest/gtest.h>

using namespace hysteron;

namespace
{
  RigidModeCheck<2>
  square()
  {
    return RigidModeCheck<2>({dealii::Point<2>(0.5, 0.5)}, {1.0});
  }

  using Modes = std::vector<std::string>;
} // namespace

TEST(RigidModes, NoSupportLeavesAllThreeFree)
{
  EXPECT_EQ(square().free_modes(0), (Modes{"translation in x", "translation in y", "rotation"}));
}

TEST(RigidModes, ClampedEdgeLeavesNothingFree)
{
  auto check = square();
  for (const double y : {0.0, 0.5, 1.0})
    for (const unsigned int d : {0u, 1u})
      check.add_displacement(0, dealii::Point<2>(0, y), d);
  EXPECT_TRUE(check.free_modes(0).empty());
}

TEST(RigidModes, PinLeavesTheRotationFree)
{
  // u = v = 0 at one point: the rotation about that point is free, a combination of
  // the rotation about the centre and a translation.
  auto check = square();
  check.add_displacement(0, dealii::Point<2>(0, 0), 0);
  check.add_displacement(0, dealii::Point<2>(0, 0), 1);
  EXPECT_EQ(check.free_modes(0), (Modes{"a combination of translation and rotation"}));
}

TEST(RigidModes, PinAtTheCentreNamesTheRotation)
{
  auto check = square();
  check.add_displacement(0, dealii::Point<2>(0.5, 0.5), 0);
  check.add_displacement(0, dealii::Point<2>(0.5, 0.5), 1);
  EXPECT_EQ(check.free_modes(0), (Modes{"rotation"}));
}

TEST(RigidModes, RollerEdgeLeavesTheSlidingFree)
{
  // u_x = 0 along x = 0: the translation in y is free; the rotation is not.
  auto check = square();
  for (const double y : {0.0, 0.25, 1.0})
    check.add_displacement(0, dealii::Point<2>(0, y), 0);
  EXPECT_EQ(check.free_modes(0), (Modes{"translation in y"}));
}

TEST(RigidModes, PinAndRollerSupportASimpleBeam)
{
  auto check = square();
  check.add_displacement(0, dealii::Point<2>(0, 0), 0);
  check.add_displacement(0, dealii::Point<2>(0, 0), 1);
  check.add_displacement(0, dealii::Point<2>(1, 0), 1);
  EXPECT_TRUE(check.free_modes(0).empty());
}

TEST(RigidModes, RotationDofOfACellPreventsTheRotation)
{
  auto check = square();
  check.add_displacement(0, dealii::Point<2>(0.3, 0.2), 0);
  check.add_displacement(0, dealii::Point<2>(0.3, 0.2), 1);
  check.add_rotation(0);
  EXPECT_TRUE(check.free_modes(0).empty());
}

TEST(RigidModes, PartsAreIndependent)
{
  RigidModeCheck<2> check({dealii::Point<2>(0, 0), dealii::Point<2>(5, 0)}, {1.0, 1.0});
  for (const double y : {-0.5, 0.5})
    for (const unsigned int d : {0u, 1u})
      check.add_displacement(0, dealii::Point<2>(-0.5, y), d);
  EXPECT_TRUE(check.free_modes(0).empty());
  EXPECT_EQ(check.free_modes(1).size(), 3u);
}

TEST(RigidModes, ThreeDimensionalRollerFaceLeavesFourMotions)
{
  // u_z = 0 on the face z = 0 of a unit cube: translations in x, y and the rotation
  // about z stay free.
  RigidModeCheck<3> check({dealii::Point<3>(0.5, 0.5, 0.5)}, {1.0});
  for (const double x : {0.0, 1.0})
    for (const double y : {0.0, 1.0})
      check.add_displacement(0, dealii::Point<3>(x, y, 0), 2);
  EXPECT_EQ(check.free_modes(0), (Modes{"translation in x", "translation in y", "rotation about z"}));
}

TEST(RigidModes, ConnectedPartsNumberByFirstNode)
{
  ConnectedParts parts(5);
  parts.join(3, 4);
  parts.join(0, 2);
  EXPECT_EQ(parts.parts(), (std::vector<unsigned int>{0, 1, 0, 2, 2}));
}

TEST(Parameters, RandIsRefusedRandSeedIsNot)
{
  EXPECT_THROW(parse_function<1>("1 + rand()", "t", false, "Load/Value"), InputError);
  EXPECT_THROW(parse_function<1>("rand ( )", "t", false, "Load/Value"), InputError);
  EXPECT_NO_THROW(parse_function<1>("rand_seed(3)", "t", false, "Load/Value"));
  EXPECT_NO_THROW(parse_function<2>("xrand * (yrand)", "xrand,yrand", false, "Load/Value"));
}

TEST(Parameters, NonFiniteValuesNameTheEntryPointAndTime)
{
  const auto f = parse_function<2>("1/x", "x,y,t", true, "Boundary left/Displacement");
  f->set_time(0.25);
  EXPECT_DOUBLE_EQ(f->value(dealii::Point<2>(2, 0)), 0.5);
  try
    {
      f->value(dealii::Point<2>(0, 3));
      FAIL() << "no exception";
    }
  catch (const NonFiniteExpression &e)
    {
      EXPECT_EQ(e.where(), "Boundary left/Displacement");
      EXPECT_EQ(e.problem(), "the expression '1/x' evaluates to inf at x = 0, y = 3, t = 0.25");
    }
}

TEST(Parameters, ExpressionsOfTimeAreSampledUpFront)
{
  const auto ok = parse_function<1>("sqrt(1 - t)", "t", false, "Load/Value");
  EXPECT_NO_THROW(check_finite_in_time(*ok, 1.0));
  EXPECT_THROW(check_finite_in_time(*ok, 2.0), InputError);
}

TEST(Parameters, PointsMustBeFinite)
{
  EXPECT_EQ(parse_points<2>("0.5, 1; 2, 3", "Output/Probe points").size(), 2u);
  EXPECT_THROW(parse_points<2>("nan, 1", "Output/Probe points"), InputError);
  EXPECT_THROW(parse_points<2>("1, inf", "Output/Probe points"), InputError);
  EXPECT_THROW(parse_points<2>("1, 2, 3", "Output/Probe points"), InputError);
}
