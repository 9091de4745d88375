// Unit tests of the base and scene infrastructure: registry, parameters, outputs,
// elasticity tensors, and the scene/material-point pipeline in-process.
#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include <hysteron/base/registry.h>
#include <hysteron/material/interface.h>
#include "run/run_scene.h"
#include <hysteron/scene/scene.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace
{
  namespace fs = std::filesystem;
  using namespace hysteron;

  std::string
  read(const std::string &file)
  {
    std::ifstream      in(file);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }

  std::string
  fresh_directory(const std::string &name)
  {
    const std::string d = "unit_output/" + name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }

  struct Shape
  {
    virtual ~Shape() = default;
    virtual int
    corners() const = 0;
  };

  struct Square : Shape
  {
    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Side", "1", dealii::Patterns::Double());
    }
    int
    corners() const override
    {
      return 4;
    }
  };

  struct Triangle : Shape
  {
    static void
    declare_parameters(dealii::ParameterHandler &)
    {}
    int
    corners() const override
    {
      return 3;
    }
  };

  const Plugins::Registration<Shape, Square>   square_registration("square", "four corners");
  const Plugins::Registration<Shape, Triangle> triangle_registration("triangle", "three corners");
} // namespace

TEST(Registry, CreatesRegisteredPluginsByNameInSortedOrder)
{
  using R = Plugins::Registry<Shape>;
  EXPECT_EQ(R::pattern_string(), "square|triangle");
  EXPECT_EQ(R::create("triangle", "Shape")->corners(), 3);
  EXPECT_EQ(R::create("square", "Shape")->corners(), 4);
  dealii::ParameterHandler prm;
  R::declare_parameters(prm);
  EXPECT_EQ(prm.get_double("Side"), 1.0);
}

TEST(Registry, UnknownNameIsAnInputErrorListingTheKnownOnes)
{
  try
    {
      Plugins::Registry<Shape>::create("circle", "Geometry/Shape");
      FAIL() << "no exception";
    }
  catch (const InputError &e)
    {
      EXPECT_EQ(e.where(), "Geometry/Shape");
      EXPECT_NE(e.problem().find("'circle'"), std::string::npos);
      EXPECT_NE(e.problem().find("square|triangle"), std::string::npos);
    }
}

TEST(Registry, DuplicateNameIsRejected)
{
  EXPECT_THROW((Plugins::Registration<Shape, Square>("square", "again")), std::logic_error);
}

TEST(Registry, BuiltInPluginsAreRegisteredForBothDimensions)
{
  EXPECT_TRUE(Material::Registry<2>::has("linear elastic"));
  EXPECT_TRUE(Material::Registry<3>::has("linear elastic"));
  EXPECT_TRUE(Methods::Registry<2>::has("material point"));
  EXPECT_TRUE(Methods::Registry<3>::has("material point"));
}

TEST(Section, ValidationMessagesNameTheFullPath)
{
  dealii::ParameterHandler prm;
  prm.enter_subsection("A");
  prm.enter_subsection("B");
  prm.declare_entry("x", "-2", dealii::Patterns::Double());
  prm.declare_entry("y", "0.5", dealii::Patterns::Double());
  prm.leave_subsection();
  prm.leave_subsection();

  Section a(prm, {"A"});
  Section b(a, "B");
  EXPECT_EQ(b.where("x"), "A/B/x");
  try
    {
      b.get_positive("x");
      FAIL() << "no exception";
    }
  catch (const InputError &e)
    {
      EXPECT_EQ(std::string(e.what()), "A/B/x: must be > 0 (got -2)");
    }
  EXPECT_THROW(b.get_in_open_interval("y", -1, 0.5), InputError);
  EXPECT_EQ(b.get_in_open_interval("y", -1, 0.6), 0.5);
}

TEST(ParseFunction, EvaluatesAndReportsErrorsWithTheParameterPath)
{
  const auto f = parse_function<1>("0.006*sin(2*pi*t)", "t", false, "Material point/Strain xx");
  EXPECT_NEAR(f->value(dealii::Point<1>(0.25)), 0.006, 1e-15);

  const auto g = parse_function<2>("x + 2*y + t", "x,y,t", true, "Body/Velocity");
  g->set_time(3.0);
  EXPECT_DOUBLE_EQ(g->value(dealii::Point<2>(1.0, 2.0)), 8.0);

  for (const std::string bad : {"sin(", "2*q", ""})
    {
      try
        {
          parse_function<1>(bad, "t", false, "Material point/Strain xx");
          FAIL() << "accepted '" << bad << "'";
        }
      catch (const InputError &e)
        {
          EXPECT_EQ(e.where(), "Material point/Strain xx");
        }
    }
}

TEST(ParseNames, RejectsDuplicatesAndEmptyNames)
{
  EXPECT_EQ(parse_names("steel, rubber", "Material names"),
            (std::vector<std::string>{"steel", "rubber"}));
  EXPECT_TRUE(parse_names("", "Material names").empty());
  EXPECT_THROW(parse_names("a, a", "Material names"), InputError);
  EXPECT_THROW(parse_names("a,,b", "Material names"), InputError);
}

TEST(AtomicFile, AppearsOnlyWhenCommitted)
{
  const std::string d = fresh_directory("atomic");
  {
    Output::AtomicFile f(d + "/a.txt");
    f.stream() << "partial";
    EXPECT_TRUE(fs::exists(d + "/a.txt.tmp"));
    EXPECT_FALSE(fs::exists(d + "/a.txt"));
  } // destroyed without commit: as after an exception
  EXPECT_FALSE(fs::exists(d + "/a.txt"));
  EXPECT_FALSE(fs::exists(d + "/a.txt.tmp"));

  Output::write_file(d + "/b.txt", "complete\n");
  EXPECT_EQ(read(d + "/b.txt"), "complete\n");
  EXPECT_FALSE(fs::exists(d + "/b.txt.tmp"));
}

TEST(AtomicFile, UnwritableLocationIsARuntimeError)
{
  EXPECT_THROW(Output::AtomicFile("/dev/null/x.csv"), RuntimeError);
}

TEST(CsvWriter, WritesHeaderAndFullPrecisionRows)
{
  const std::string d = fresh_directory("csv");
  {
    Output::CsvWriter csv(d + "/t.csv", {"t", "x"});
    csv.add_row({0.0, -0.0});
    csv.add_row({1.0, 1.0 / 3.0});
    EXPECT_THROW(csv.add_row({1.0}), std::logic_error);
    csv.commit();
  }
  EXPECT_EQ(read(d + "/t.csv"), "t,x\n0,0\n1,0.333333333333333\n");
}

TEST(PrepareDirectory, CreatesNestedDirectoriesAndRejectsFiles)
{
  const std::string d = fresh_directory("prepare");
  Output::prepare_directory(d + "/a/b", "Output/Directory");
  EXPECT_TRUE(fs::is_directory(d + "/a/b"));
  Output::write_file(d + "/file", "x");
  EXPECT_THROW(Output::prepare_directory(d + "/file", "Output/Directory"), InputError);
  EXPECT_THROW(Output::prepare_directory(d + "/file/sub", "Output/Directory"), InputError);
}

TEST(FieldWriter, WritesVtuFilesAndAGrowingPvdRecord)
{
  const std::string          d = fresh_directory("fields");
  dealii::Triangulation<2>   tria;
  dealii::GridGenerator::hyper_cube(tria);
  tria.refine_global(2);
  dealii::FE_Q<2>       fe(1);
  dealii::DoFHandler<2> dof_handler(tria);
  dof_handler.distribute_dofs(fe);
  dealii::Vector<double> u(dof_handler.n_dofs());
  for (unsigned int i = 0; i < u.size(); ++i)
    u[i] = i;

  Output::FieldWriter writer(d, "solution", MPI_COMM_WORLD);
  for (const double time : {0.0, 0.5})
    {
      dealii::DataOut<2> data_out;
      data_out.attach_dof_handler(dof_handler);
      data_out.add_data_vector(u, "u");
      data_out.build_patches();
      writer.write(data_out, time);
    }
  EXPECT_TRUE(fs::exists(d + "/solution-00000.vtu"));
  EXPECT_TRUE(fs::exists(d + "/solution-00001.vtu"));
  const std::string pvd = read(d + "/solution.pvd");
  EXPECT_NE(pvd.find("timestep=\"0.5\""), std::string::npos);
  EXPECT_NE(pvd.find("solution-00001.vtu"), std::string::npos);
  EXPECT_EQ(writer.records().size(), 2u);
  for (const auto &entry : fs::directory_iterator(d))
    EXPECT_NE(entry.path().extension(), ".tmp");
}

TEST(Elasticity, StiffnessTensorsOfTheThreeStressStates)
{
  Material::Elasticity e;
  e.youngs_modulus = 200e9;
  e.poissons_ratio = 0.25;
  e.density        = 8000;

  // 3D: uniaxial stress state eps = diag(1, -nu, -nu) gives sigma = diag(E, 0, 0).
  e.stress_state = Material::StressState::three_dimensional;
  dealii::SymmetricTensor<2, 3> eps3;
  eps3[0][0] = 1;
  eps3[1][1] = eps3[2][2] = -0.25;
  const auto s3 = e.stiffness<3>() * eps3;
  EXPECT_NEAR(s3[0][0], 200e9, 1e-3);
  EXPECT_NEAR(s3[1][1], 0, 1e-3);
  EXPECT_NEAR(e.p_wave_modulus(), 200e9 * 0.75 / (1.25 * 0.5), 1e-3);
  EXPECT_NEAR(e.p_wave_speed(), std::sqrt(240e9 / 8000), 1e-9);

  // Plane stress: eps = diag(1, -nu) gives sigma = diag(E, 0); shear 2 mu.
  e.stress_state = Material::StressState::plane_stress;
  dealii::SymmetricTensor<2, 2> eps2;
  eps2[0][0] = 1;
  eps2[1][1] = -0.25;
  eps2[0][1] = 0.5;
  const auto s2 = e.stiffness<2>() * eps2;
  EXPECT_NEAR(s2[0][0], 200e9, 1e-3);
  EXPECT_NEAR(s2[1][1], 0, 1e-3);
  EXPECT_NEAR(s2[0][1], 2 * e.shear_modulus() * 0.5, 1e-3);
  EXPECT_NEAR(e.p_wave_modulus(), 200e9 / (1 - 0.0625), 1e-3);

  // Plane strain: eps = diag(1, 0) gives sigma_xx = lambda + 2 mu = E (1-nu)/((1+nu)(1-2nu)).
  e.stress_state = Material::StressState::plane_strain;
  dealii::SymmetricTensor<2, 2> uniaxial_strain;
  uniaxial_strain[0][0] = 1;
  EXPECT_NEAR((e.stiffness<2>() * uniaxial_strain)[0][0], 240e9, 1e-3);
}

TEST(Scene, RunsAMaterialPointSceneInProcess)
{
  const std::string        d = fresh_directory("scene");
  dealii::ParameterHandler prm;
  Scene<3>::declare_parameters(prm, SceneNames{{"soft"}, {}, {}, {}, {}, {}});
  prm.set("Dimension", "3");
  prm.set("Material names", "soft");
  prm.enter_subsection("Material soft");
  prm.set("Young's modulus", "1e6");
  prm.leave_subsection();
  prm.enter_subsection("Material point");
  prm.set("Material", "soft");
  prm.set("Strain xx", "0.01*t");
  prm.set("Stress-free components", "yy, zz");
  prm.set("Steps", "4");
  prm.leave_subsection();
  prm.enter_subsection("Output");
  prm.set("Directory", d);
  prm.leave_subsection();

  RunOptions options;
  options.quiet = true;
  Output::RunRecord record;
  Scene<3>          scene(prm, options);
  EXPECT_EQ(scene.material_names(), (std::vector<std::string>{"", "soft"}));
  EXPECT_THROW(scene.material("hard", "Body/Material"), InputError);
  Run::run_scene(scene, record);

  const std::string csv = read(d + "/history.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "t,eps_xx,eps_yy,eps_zz,eps_xy,eps_yz,eps_xz,sig_xx,sig_yy,sig_zz,sig_xy,sig_yz,sig_xz");
  // Last row: t = 1, eps_xx = 0.01, sigma_xx = E eps_xx = 1e4 Pa.
  const std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  EXPECT_EQ(last.substr(0, last.find(',')), "1");
  EXPECT_NE(last.find(",10000,"), std::string::npos) << last;
  EXPECT_TRUE(fs::exists(d + "/parameters.prm"));
}
