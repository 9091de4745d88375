// Unit tests of the comparison of two runs' tables (compare/compare.h): reading CSV files,
// interpolation in time, the norms, the side-by-side, summary and plot outputs.
#include <deal.II/base/numbers.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>

#include "compare/compare.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

namespace
{
  namespace fs = std::filesystem;
  using namespace hysteron;
  using Compare::Table;

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
    const std::string d = "unit_output/compare/" + name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }

  /// A table "time" + @p columns sampled from @p f(column, t) at @p times.
  Table
  make_table(const std::string                                 &source,
             const std::vector<std::string>                    &columns,
             const std::vector<double>                         &times,
             const std::function<double(unsigned int, double)> &f)
  {
    Table t;
    t.source  = source;
    t.columns = {"time"};
    t.columns.insert(t.columns.end(), columns.begin(), columns.end());
    for (const double time : times)
      {
        std::vector<double> row{time};
        for (unsigned int c = 0; c < columns.size(); ++c)
          row.push_back(f(c, time));
        t.add_row(row);
      }
    return t;
  }

  std::vector<double>
  uniform(const double begin, const double end, const unsigned int n_intervals)
  {
    std::vector<double> t;
    for (unsigned int i = 0; i <= n_intervals; ++i)
      t.push_back(i == n_intervals ? end : begin + (end - begin) * i / n_intervals);
    return t;
  }

  /// Write @p table with the writer the methods use.
  void
  write_table(const Table &table, const std::string &file)
  {
    Output::CsvWriter csv(file, table.columns);
    for (unsigned int r = 0; r < table.n_rows(); ++r)
      {
        std::vector<double> row;
        for (const auto &column : table.values)
          row.push_back(column[r]);
        csv.add_row(row);
      }
    csv.commit();
  }

  /// The InputError thrown by @p f (fails the test if there is none).
  InputError
  input_error(const std::function<void()> &f)
  {
    try
      {
        f();
      }
    catch (const InputError &e)
      {
        return e;
      }
    ADD_FAILURE() << "no InputError";
    return InputError("", "");
  }

  bool
  has_temporary_files(const std::string &directory)
  {
    for (const auto &entry : fs::recursive_directory_iterator(directory))
      if (entry.path().extension() == ".tmp")
        return true;
    return false;
  }
} // namespace

TEST(CompareReadCsv, ReadsHeaderAndRows)
{
  const std::string d = fresh_directory("read");
  Output::write_file(d + "/t.csv", "time, u_x ,s_xx\r\n0,1e-3,-2\r\n\r\n0.5,+2.5E+2,-0\n");
  const Table t = Compare::read_csv(d + "/t.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"time", "u_x", "s_xx"}));
  ASSERT_EQ(t.n_rows(), 2u);
  EXPECT_EQ(t.values[1], (std::vector<double>{1e-3, 250.0}));
  EXPECT_EQ(t.values[2][0], -2.0);
  EXPECT_EQ(t.lines, (std::vector<unsigned int>{2, 4}));
  EXPECT_EQ(t.column_index("s_xx"), 2u);
  EXPECT_EQ(t.where(1), d + "/t.csv:4");
}

TEST(CompareReadCsv, MalformedFilesAreInputErrorsNamingFileAndLine)
{
  const std::string d        = fresh_directory("malformed");
  const auto        error_of = [&](const std::string &content) {
    Output::write_file(d + "/bad.csv", content);
    return input_error([&]() { Compare::read_csv(d + "/bad.csv"); });
  };

  const InputError ragged = error_of("time,u_x\n0,1\n1,2,3\n");
  EXPECT_EQ(ragged.where(), d + "/bad.csv:3");
  EXPECT_EQ(ragged.problem(), "the row has 3 values, the header has 2 columns");

  const InputError text = error_of("time,u_x\n0,1\n\n1,abc\n");
  EXPECT_EQ(text.where(), d + "/bad.csv:4");
  EXPECT_EQ(text.problem(), "'abc' in column 'u_x' is not a finite number");

  EXPECT_EQ(error_of("time,u_x\n0,1.5x\n").where(), d + "/bad.csv:2");
  EXPECT_EQ(error_of("time,u_x\n0,nan\n").where(), d + "/bad.csv:2");
  EXPECT_EQ(error_of("time,u_x\n0,+-1\n").where(), d + "/bad.csv:2");
  EXPECT_EQ(error_of("time,u_x\n0,\n").where(), d + "/bad.csv:2");
  EXPECT_EQ(error_of("").where(), d + "/bad.csv:1");
  EXPECT_EQ(error_of("time,,u_x\n").where(), d + "/bad.csv:1");
  EXPECT_NE(error_of("time,u_x,u_x\n").problem().find("appears twice"), std::string::npos);

  const InputError missing = input_error([&]() { Compare::read_csv(d + "/none.csv"); });
  EXPECT_EQ(missing.where(), d + "/none.csv");
  EXPECT_NE(missing.problem().find("cannot open"), std::string::npos);
}

TEST(CompareTables, DecreasingOrRepeatedTimeIsAnErrorNamingFileAndLine)
{
  const std::string d = fresh_directory("decreasing");
  Output::write_file(d + "/a.csv", "time,u_x\n0,0\n1,1\n2,2\n");
  Output::write_file(d + "/b.csv", "time,u_x\n0,0\n0.5,1\n\n0.4,2\n");
  const Table      a = Compare::read_csv(d + "/a.csv");
  const InputError e =
    input_error([&]() { Compare::compare_tables(a, Compare::read_csv(d + "/b.csv"), "b.csv"); });
  EXPECT_EQ(e.where(), d + "/b.csv:5");
  EXPECT_EQ(e.problem(), "time 0.4 does not increase (previous row: 0.5)");

  Output::write_file(d + "/c.csv", "time,u_x\n0,0\n0,1\n");
  EXPECT_EQ(input_error([&]() {
              Compare::compare_tables(Compare::read_csv(d + "/c.csv"), a, "c.csv");
            }).where(),
            d + "/c.csv:3");

  Output::write_file(d + "/d.csv", "t,u_x\n0,0\n");
  EXPECT_EQ(input_error([&]() {
              Compare::compare_tables(a, Compare::read_csv(d + "/d.csv"), "d.csv");
            }).problem(),
            "has no column 'time'");
}

TEST(CompareTables, LinearDataIsInterpolatedExactly)
{
  const auto f = [](const unsigned int c, const double t) {
    return c == 0 ? 2.0 + 3.0 * t : -1.5e3 * t;
  };
  const Table a = make_table("a", {"u_x", "s_xx"}, uniform(0, 1, 10), f);
  // B at irregular times that bracket A's: 0, 0.037, 0.111, 0.185, ..., 1.036.
  std::vector<double> tb;
  for (unsigned int k = 0; k < 29; ++k)
    tb.push_back(0.037 * k * (1 + 0.01 * (k % 3)));
  const Table b = make_table("b", {"s_xx", "u_x"}, tb, [&](const unsigned int c, const double t) {
    return f(1 - c, t);
  });

  const auto result = Compare::compare_tables(a, b, "t.csv");
  EXPECT_EQ(result.time, a.values[0]);
  ASSERT_EQ(result.differences.size(), 2u);
  for (const auto &d : result.differences)
    {
      EXPECT_LT(d.max_abs_difference, 1e-14 * d.scale) << d.column;
      EXPECT_LT(d.l2_relative_difference, 1e-14) << d.column;
      EXPECT_FALSE(d.constant);
    }
  EXPECT_EQ(result.differences[0].column, "u_x");
  EXPECT_DOUBLE_EQ(result.differences[0].scale, 5.0);
  EXPECT_DOUBLE_EQ(result.differences[1].scale, 1.5e3);
  EXPECT_TRUE(result.warnings.empty());
}

TEST(CompareTables, KnownDifferencesOfASine)
{
  const double pi = dealii::numbers::PI;
  // A = sin t on [0, pi]; B on another grid: B = A + 0.01 sin t and B = A + 0.01 t.
  const Table a = make_table("a", {"p", "q"}, uniform(0, pi, 20000), [](unsigned int, double t) {
    return std::sin(t);
  });
  const Table b = make_table("b", {"p", "q"}, uniform(0, pi, 15001), [](unsigned int c, double t) {
    return std::sin(t) + 0.01 * (c == 0 ? std::sin(t) : t);
  });
  const auto  r = Compare::compare_tables(a, b, "sine.csv");
  ASSERT_EQ(r.differences.size(), 2u);
  ASSERT_EQ(r.time.size(), 20001u);

  // max |0.01 sin t| / max |sin t| = 0.01; the L2 ratio of proportional signals is 0.01.
  EXPECT_NEAR(r.differences[0].scale, 1.0, 1e-12);
  EXPECT_NEAR(r.differences[0].max_relative_difference, 0.01, 1e-8);
  EXPECT_NEAR(r.differences[0].l2_relative_difference, 0.01, 1e-8);
  // max |0.01 t| = 0.01 pi; sqrt(int_0^pi (0.01 t)^2 / int_0^pi sin^2) = 0.01 pi sqrt(2/3).
  EXPECT_NEAR(r.differences[1].max_abs_difference, 0.01 * pi, 1e-8);
  EXPECT_NEAR(r.differences[1].max_relative_difference, 0.01 * pi, 1e-8);
  EXPECT_NEAR(r.differences[1].l2_relative_difference, 0.01 * pi * std::sqrt(2.0 / 3.0), 1e-7);
}

TEST(CompareTables, PartialOverlapComparesTheCommonTimeRangeOnly)
{
  const auto  f = [](unsigned int, double t) { return t * t; };
  const Table a = make_table("a", {"u_x"}, uniform(0, 10, 10), f);

  const auto later =
    Compare::compare_tables(a, make_table("b", {"u_x"}, uniform(2.5, 20, 7), f), "");
  EXPECT_EQ(later.time, (std::vector<double>{3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(later.a[0], (std::vector<double>{9, 16, 25, 36, 49, 64, 81, 100}));
  // B = t^2 sampled every 2.5 from 2.5: at t = 3 the chord gives 6.25 + 0.2 (25 - 6.25) = 10.
  EXPECT_DOUBLE_EQ(later.b[0][0], 10.0);
  EXPECT_DOUBLE_EQ(later.b[0][7], 100.0);
  EXPECT_DOUBLE_EQ(later.differences[0].max_abs_difference, 1.5);

  const auto earlier = Compare::compare_tables(a, make_table("b", {"u_x"}, {-5, 2.5, 7.5}, f), "");
  EXPECT_EQ(earlier.time, (std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_DOUBLE_EQ(earlier.differences[0].scale, 49.0);

  const auto disjoint = Compare::compare_tables(a, make_table("b", {"u_x"}, {11, 12}, f), "");
  EXPECT_TRUE(disjoint.time.empty());
  EXPECT_TRUE(disjoint.differences.empty());
  ASSERT_EQ(disjoint.warnings.size(), 1u);
  EXPECT_NE(disjoint.warnings[0].find("no common time range"), std::string::npos);
}

TEST(CompareTables, SharedAndUnsharedColumns)
{
  const auto  f = [](unsigned int c, double t) { return c + t; };
  const Table a = make_table("a", {"u_x", "mass", "H1"}, {0, 1}, f);
  const Table b = make_table("b", {"H1", "u_x", "extra"}, {0, 1}, f);
  const auto  r = Compare::compare_tables(a, b, "");
  EXPECT_EQ(r.columns, (std::vector<std::string>{"u_x", "H1"}));
  EXPECT_EQ(r.only_in_a, (std::vector<std::string>{"mass"}));
  EXPECT_EQ(r.only_in_b, (std::vector<std::string>{"extra"}));
  ASSERT_EQ(r.differences.size(), 2u);
  // u_x: a = t, b = 1 + t; H1: a = 2 + t, b = t.
  EXPECT_DOUBLE_EQ(r.differences[0].max_abs_difference, 1.0);
  EXPECT_DOUBLE_EQ(r.differences[1].max_abs_difference, 2.0);
  EXPECT_DOUBLE_EQ(r.differences[1].max_relative_difference, 2.0 / 3.0);
}

TEST(CompareTables, ZeroColumns)
{
  const Table a =
    make_table("a", {"zero", "a_zero"}, uniform(0, 2, 4), [](unsigned, double) { return 0.0; });
  const Table b = make_table("b", {"zero", "a_zero"}, uniform(0, 2, 4), [](unsigned c, double t) {
    return c == 0 ? -0.0 : 0.5 * t;
  });
  const auto  r = Compare::compare_tables(a, b, "");
  const auto &zero = r.differences[0], &a_zero = r.differences[1];
  EXPECT_EQ(zero.max_abs_difference, 0.0);
  EXPECT_EQ(zero.scale, 0.0);
  EXPECT_EQ(zero.max_relative_difference, 0.0);
  EXPECT_EQ(zero.l2_relative_difference, 0.0);
  EXPECT_TRUE(zero.constant);
  // A is zero: the scale is max |b| = 1, and both relative differences are 1.
  EXPECT_EQ(a_zero.scale, 1.0);
  EXPECT_DOUBLE_EQ(a_zero.max_relative_difference, 1.0);
  EXPECT_DOUBLE_EQ(a_zero.l2_relative_difference, 1.0);
  EXPECT_FALSE(a_zero.constant);
}

TEST(CompareTables, SingleRowTables)
{
  const Table a1   = make_table("a", {"u_x"}, {1.0}, [](unsigned, double) { return 2.0; });
  const Table b1   = make_table("b", {"u_x"}, {2.0}, [](unsigned, double) { return 2.5; });
  const auto  rows = Compare::compare_tables(a1, b1, "");
  EXPECT_EQ(rows.time, (std::vector<double>{1.0}));
  EXPECT_DOUBLE_EQ(rows.differences[0].max_relative_difference, 0.25);
  EXPECT_DOUBLE_EQ(rows.differences[0].l2_relative_difference, 0.25);
  EXPECT_TRUE(rows.differences[0].constant);
  ASSERT_EQ(rows.warnings.size(), 1u);
  EXPECT_NE(rows.warnings[0].find("different times"), std::string::npos);
  EXPECT_EQ(Compare::select_plot_columns(rows), (std::vector<std::string>{"u_x"}));

  // A single row of B between rows of A: A is interpolated to its time.
  const Table a       = make_table("a", {"u_x"}, {0, 1}, [](unsigned, double t) { return 4 * t; });
  const Table b       = make_table("b", {"u_x"}, {0.25}, [](unsigned, double) { return 1.1; });
  const auto  between = Compare::compare_tables(a, b, "");
  EXPECT_EQ(between.time, (std::vector<double>{0.25}));
  EXPECT_DOUBLE_EQ(between.a[0][0], 1.0);
  EXPECT_NEAR(between.differences[0].max_relative_difference, 0.1, 1e-15);
  EXPECT_TRUE(between.warnings.empty());
}

TEST(CompareSelectPlotColumns, PrefersDisplacementsAndStressesAndHonoursAList)
{
  const std::vector<std::string> names{"x_x",
                                       "x_y",
                                       "u_x",
                                       "u_y",
                                       "v_x",
                                       "v_y",
                                       "s_xx",
                                       "s_yy",
                                       "s_xy",
                                       "von_mises",
                                       "eps_xx",
                                       "eps_yy",
                                       "eps_xy",
                                       "H1",
                                       "eps_ps",
                                       "frozen"};
  const Table                    a =
    make_table("a", names, {0, 1}, [](unsigned c, double t) { return c == 15 ? 1.0 : c + t; });
  const auto r = Compare::compare_tables(a, a, "");
  EXPECT_EQ(Compare::select_plot_columns(r),
            (std::vector<std::string>{"u_x",
                                      "u_y",
                                      "von_mises",
                                      "s_xx",
                                      "s_yy",
                                      "s_xy",
                                      "H1",
                                      "eps_ps",
                                      "eps_xx",
                                      "eps_yy",
                                      "eps_xy",
                                      "v_x"}));
  EXPECT_EQ(Compare::select_plot_columns(r, {}, 3),
            (std::vector<std::string>{"u_x", "u_y", "von_mises"}));
  EXPECT_EQ(Compare::select_plot_columns(r, {"frozen", "none", "u_y", "frozen"}),
            (std::vector<std::string>{"frozen", "u_y"}));
  EXPECT_EQ(Compare::select_plot_columns(r, {"none"}).size(), 12u);
}

namespace
{
  /// Two run directories: probe_0.csv, probe_10.csv and energy.csv in both, reactions.csv in
  /// MPM's only, particles.csv (not a time table) in both.
  void
  make_runs(const std::string &d)
  {
    fs::create_directories(d + "/mpm");
    fs::create_directories(d + "/fem");
    const auto probe = [](const double amplitude) {
      return [amplitude](unsigned c, double t) {
        return c == 0 ? amplitude * std::sin(t) : c == 1 ? 100 * std::sin(t) : 7.0;
      };
    };
    write_table(make_table("", {"u_x", "von_mises", "mass"}, uniform(0, 2, 20), probe(1.0)),
                d + "/mpm/probe_0.csv");
    write_table(make_table("", {"u_x", "von_mises", "mass"}, uniform(0, 2.5, 250), probe(1.02)),
                d + "/fem/probe_0.csv");
    for (const auto &run : {"mpm", "fem"})
      {
        write_table(make_table("", {"u_x", "H1"}, uniform(0, 1, 4), probe(1.0)),
                    d + "/" + run + "/probe_10.csv");
        write_table(
          make_table("", {"kinetic"}, uniform(0, 2, 4), [](unsigned, double t) { return t; }),
          d + "/" + run + "/energy.csv");
        Output::write_file(d + "/" + run + "/particles.csv", "id,x\n0,1\n");
      }
    write_table(make_table("", {"left_x"}, uniform(0, 2, 4), probe(1.0)), d + "/mpm/reactions.csv");
  }
} // namespace

TEST(CompareDirectories, WritesSideBySideTablesSummariesAndPlots)
{
  const std::string d = fresh_directory("directories");
  make_runs(d);
  const auto report =
    Compare::compare_directories(d + "/mpm", "MPM", d + "/fem", "FEM", {}, d + "/out");

  ASSERT_EQ(report.tables.size(), 3u);
  EXPECT_EQ(report.tables[0].name, "energy.csv");
  EXPECT_EQ(report.tables[1].name, "probe_0.csv");
  EXPECT_EQ(report.tables[2].name, "probe_10.csv");
  EXPECT_EQ(report.missing_in_b, (std::vector<std::string>{"reactions.csv"}));
  EXPECT_TRUE(report.missing_in_a.empty());
  EXPECT_EQ(report.tables[1].differences[0].column, "u_x");
  EXPECT_NEAR(report.tables[1].differences[0].max_relative_difference, 0.02, 0.002);

  // The side-by-side table: A's rows with B interpolated, B - A.
  const Table side = Compare::read_csv(d + "/out/probe_0.csv");
  EXPECT_EQ(side.columns,
            (std::vector<std::string>{"time",
                                      "u_x_MPM",
                                      "u_x_FEM",
                                      "u_x_diff",
                                      "von_mises_MPM",
                                      "von_mises_FEM",
                                      "von_mises_diff",
                                      "mass_MPM",
                                      "mass_FEM",
                                      "mass_diff"}));
  ASSERT_EQ(side.n_rows(), 21u);
  EXPECT_NEAR(side.values[1][20], std::sin(2.0), 1e-14);
  EXPECT_NEAR(side.values[3][20], side.values[2][20] - side.values[1][20], 1e-14);
  EXPECT_EQ(side.values[9], std::vector<double>(21, 0.0));

  // summary.csv: sorted by table (naturally) then column, table-level rows first.
  std::istringstream       summary(read(d + "/out/summary.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(summary, line);)
    lines.push_back(line.substr(0, line.find(',', line.find(',', line.find(',') + 1) + 1)));
  EXPECT_EQ(lines,
            (std::vector<std::string>{"table,column,status",
                                      "energy.csv,kinetic,compared",
                                      "probe_0.csv,mass,compared",
                                      "probe_0.csv,u_x,compared",
                                      "probe_0.csv,von_mises,compared",
                                      "probe_10.csv,H1,compared",
                                      "probe_10.csv,u_x,compared",
                                      "reactions.csv,,missing in FEM"}));
  EXPECT_NE(read(d + "/out/summary.csv").find("energy.csv,kinetic,compared,5,0,2,2,0,0,0\n"),
            std::string::npos);

  const std::string md = read(d + "/out/summary.md");
  EXPECT_NE(md.find("| table | column | max \\|FEM - MPM\\| | S | max rel. [%] | L2 rel. [%] |"),
            std::string::npos);
  EXPECT_NE(md.find("| energy.csv | kinetic | 0 | 2 | 0 | 0 |"), std::string::npos);
  EXPECT_NE(md.find("| probe_0.csv | mass | 0 | 7 | 0 | 0 |"), std::string::npos);
  EXPECT_NE(md.find("trapezoidal"), std::string::npos);
  EXPECT_NE(md.find("reactions.csv: only in MPM"), std::string::npos);
  EXPECT_LT(md.find("energy.csv"), md.find("probe_0.csv"));
  EXPECT_LT(md.find("| probe_0.csv"), md.find("| probe_10.csv"));

  // The plots: mass is constant in both runs, so probe_0 draws u_x and von_mises.
  const std::string gp = read(d + "/out/probe_0.gp");
  EXPECT_NE(gp.find("set multiplot layout 1,2"), std::string::npos);
  EXPECT_NE(gp.find("set output 'probe_0.png.tmp'"), std::string::npos);
  EXPECT_EQ(gp.find("'mass'"), std::string::npos);
  EXPECT_TRUE(fs::exists(d + "/out/energy.gp"));
  if (Compare::gnuplot_available())
    {
      for (const auto &stem : {"energy", "probe_0", "probe_10"})
        {
          const std::string png = read(d + "/out/" + stem + ".png");
          ASSERT_GT(png.size(), 8u) << stem;
          EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << stem;
        }
      EXPECT_TRUE(report.warnings.size() == 1) << report.warnings.back();
    }
  EXPECT_EQ(report.warnings.front(), "reactions.csv: only in " + d + "/mpm; not compared");
  EXPECT_FALSE(fs::exists(d + "/out/reactions.csv"));
  EXPECT_FALSE(has_temporary_files(d + "/out"));

  // An explicit list of files; one in neither directory.
  const auto listed = Compare::compare_directories(
    d + "/mpm", "MPM", d + "/fem", "FEM", {"probe_10.csv", "probe_7.csv"}, d + "/out2");
  ASSERT_EQ(listed.tables.size(), 1u);
  EXPECT_EQ(listed.missing_in_a, (std::vector<std::string>{"probe_7.csv"}));
  EXPECT_EQ(listed.missing_in_b, (std::vector<std::string>{"probe_7.csv"}));
  EXPECT_FALSE(fs::exists(d + "/out2/probe_0.csv"));
  EXPECT_NE(read(d + "/out2/summary.md").find("- probe_7.csv: in neither run\n"),
            std::string::npos);
}

TEST(CompareDirectories, WithoutGnuplotTheScriptIsKeptAndAWarningReturned)
{
  const std::string d = fresh_directory("no_gnuplot");
  make_runs(d);
  fs::create_directories(d + "/out");
  Output::write_file(d + "/out/probe_0.png", "an earlier plot");
  const char       *path  = std::getenv("PATH");
  const std::string saved = path == nullptr ? "" : path;
  ::setenv("PATH", "/nonexistent", 1);
  Compare::ComparisonReport report;
  try
    {
      report = Compare::compare_directories(
        d + "/mpm", "MPM", d + "/fem", "FEM", {"probe_0.csv"}, d + "/out");
    }
  catch (...)
    {
      ::setenv("PATH", saved.c_str(), 1);
      throw;
    }
  ::setenv("PATH", saved.c_str(), 1);

  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("gnuplot is not on PATH"), std::string::npos);
  EXPECT_TRUE(fs::exists(d + "/out/probe_0.gp"));
  EXPECT_TRUE(fs::exists(d + "/out/probe_0.csv"));
  EXPECT_FALSE(fs::exists(d + "/out/probe_0.png")); // the earlier plot would not match
  EXPECT_FALSE(has_temporary_files(d + "/out"));
}

TEST(CompareDirectories, AMalformedTableIsAnErrorAndLeavesNoOutput)
{
  const std::string d = fresh_directory("malformed_run");
  make_runs(d);
  Output::write_file(d + "/fem/probe_10.csv", "time,u_x,H1\n0,0,0\n0.5,1\n");
  const InputError e = input_error(
    [&]() { Compare::compare_directories(d + "/mpm", "MPM", d + "/fem", "FEM", {}, d + "/out"); });
  EXPECT_EQ(e.where(), d + "/fem/probe_10.csv:3");
  EXPECT_FALSE(fs::exists(d + "/out"));

  Output::write_file(d + "/fem/probe_10.csv", "time,u_x,H1\n0,0,0\n0.5,1,1\n0.5,1,1\n");
  EXPECT_EQ(input_error([&]() {
              Compare::compare_directories(d + "/mpm", "MPM", d + "/fem", "FEM", {}, d + "/out");
            }).where(),
            d + "/fem/probe_10.csv:4");
  EXPECT_FALSE(fs::exists(d + "/out"));
}

TEST(CompareDirectories, RejectsBadLabelsNamesAndAnInputDirectoryAsOutput)
{
  const std::string d = fresh_directory("rejects");
  make_runs(d);
  const auto run =
    [&](const std::string &label_b, const std::vector<std::string> &files, const std::string &out) {
      return input_error([&]() {
        Compare::compare_directories(d + "/mpm", "MPM", d + "/fem", label_b, files, out);
      });
    };
  EXPECT_EQ(run("MPM", {}, d + "/out").where(), "comparison labels");
  EXPECT_EQ(run("F,EM", {}, d + "/out").where(), "comparison label 'F,EM'");
  EXPECT_EQ(run("", {}, d + "/out").where(), "comparison label ''");
  EXPECT_EQ(run("FEM", {}, d + "/fem/").problem(),
            "the comparison output directory must not be an input directory");
  EXPECT_EQ(run("FEM", {"../probe_0.csv"}, d + "/out").where(), "compared table '../probe_0.csv'");
  EXPECT_EQ(run("FEM", {"summary.csv"}, d + "/out").where(), "compared table 'summary.csv'");
  EXPECT_EQ(input_error([&]() {
              Compare::compare_directories(d + "/none", "MPM", d + "/fem", "FEM", {}, d + "/out");
            }).where(),
            d + "/none");
  EXPECT_FALSE(fs::exists(d + "/out"));
}

TEST(CompareGnuplot, AFailedPlotLeavesNeitherAPartialNorAStalePng)
{
  if (!Compare::gnuplot_available())
    GTEST_SKIP() << "gnuplot is not on PATH";
  const std::string d = fresh_directory("gnuplot_failure");
  Output::write_file(d + "/p.png", "an earlier plot");
  Output::write_file(
    d + "/p.gp", "set terminal pngcairo\nset output 'p.png.tmp'\nplot sin(x)\nno_such_command\n");
  const std::string warning = Compare::run_gnuplot(d + "/p.gp", "p.png");
  EXPECT_EQ(warning.find("gnuplot failed on " + d + "/p.gp (exit status 1): "), 0u) << warning;
  EXPECT_NE(warning.find("no_such_command"), std::string::npos) << warning;
  EXPECT_FALSE(fs::exists(d + "/p.png"));
  EXPECT_FALSE(fs::exists(d + "/p.png.tmp"));
}

// The plot runner (compare/plotter.cc): a plotter runs without a shell, within its timeout, and
// leaves either a complete PNG or none.
namespace
{
  /// An executable shell script @p name in @p directory: a fake plotter.
  std::string
  write_script(const std::string &directory, const std::string &name, const std::string &body)
  {
    const std::string file = directory + "/" + name;
    Output::write_file(file, "#!/bin/sh\n" + body);
    fs::permissions(file, fs::perms::owner_exec, fs::perm_options::add);
    return fs::absolute(file).string();
  }

  /// The fake plotter @p script run in @p directory, drawing p.png, for at most @p timeout s.
  Compare::PlotCommand
  plot_command(const std::string &script, const std::string &directory, const double timeout = 10)
  {
    Compare::PlotCommand command;
    command.arguments = {script, "p.gp"};
    command.directory = directory;
    command.png_file  = "p.png";
    command.subject   = directory + "/p.gp";
    command.timeout   = timeout;
    return command;
  }

  double
  seconds_since(const std::chrono::steady_clock::time_point start)
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  /// PATH set to @p path for the lifetime of the object.
  class ScopedPath
  {
  public:
    explicit ScopedPath(const std::string &path)
      : saved(std::getenv("PATH") == nullptr ? "" : std::getenv("PATH"))
    {
      ::setenv("PATH", path.c_str(), 1);
    }

    ~ScopedPath()
    {
      ::setenv("PATH", saved.c_str(), 1);
    }

  private:
    const std::string saved;
  };

  /// Whether process @p pid is gone (or a zombie) within @p seconds.
  bool
  process_ends(const std::string &pid, const double seconds)
  {
    const auto start = std::chrono::steady_clock::now();
    while (seconds_since(start) < seconds)
      {
        std::ifstream stat("/proc/" + pid + "/stat");
        std::string   line;
        if (!std::getline(stat, line) || line.substr(line.rfind(')') + 2, 1) == "Z")
          return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    return false;
  }
} // namespace

TEST(CompareRunPlotter, APlotterThatSucceedsLeavesItsPngOnly)
{
  const std::string d = fresh_directory("plotter_success");
  const std::string script =
    write_script(d, "plotter", "[ \"$1\" = p.gp ] && echo png > p.png.tmp\n");
  Output::write_file(d + "/p.png", "an earlier plot");
  EXPECT_EQ(Compare::run_plotter(plot_command(script, d)), "");
  EXPECT_EQ(read(d + "/p.png"), "png\n");
  EXPECT_FALSE(has_temporary_files(d));

  // What the plotter prints is a warning; the PNG stays.
  const std::string talking =
    write_script(d, "talking plotter", "echo png > p.png.tmp\necho 'warning: a b' >&2\n");
  EXPECT_EQ(Compare::run_plotter(plot_command(talking, d)),
            "talking plotter on " + d + "/p.gp: warning: a b");
  EXPECT_TRUE(fs::exists(d + "/p.png"));
}

TEST(CompareRunPlotter, APlotterThatFailsLeavesNoPngAndAWarning)
{
  const std::string d = fresh_directory("plotter_failure");
  const std::string script =
    write_script(d, "plotter", "echo partial > p.png.tmp\necho 'cannot draw' >&2\nexit 3\n");
  Output::write_file(d + "/p.png", "an earlier plot");
  EXPECT_EQ(Compare::run_plotter(plot_command(script, d)),
            "plotter failed on " + d + "/p.gp (exit status 3): cannot draw; no PNG written");
  EXPECT_FALSE(fs::exists(d + "/p.png"));
  EXPECT_FALSE(has_temporary_files(d));

  const std::string idle = write_script(d, "idle", "exit 0\n");
  EXPECT_EQ(Compare::run_plotter(plot_command(idle, d)),
            "idle failed on " + d + "/p.gp (it drew no p.png.tmp); no PNG written");

  EXPECT_EQ(Compare::run_plotter(plot_command(d + "/none", d)),
            "cannot run none on " + d + "/p.gp: No such file or directory; no PNG written");
  EXPECT_FALSE(fs::exists(d + "/p.png"));
}

TEST(CompareRunPlotter, APlotThatExceedsItsTimeoutIsKilledAndLeavesNoPng)
{
  const std::string d = fresh_directory("plotter_timeout");
  // The plotter starts a child that holds the output pipe: both must go.
  const std::string script =
    write_script(d, "plotter", "echo partial > p.png.tmp\nsleep 30 &\necho $! > sleep.pid\nwait\n");
  Output::write_file(d + "/p.png", "an earlier plot");
  const auto        start   = std::chrono::steady_clock::now();
  const std::string warning = Compare::run_plotter(plot_command(script, d, 0.5));
  const double      elapsed = seconds_since(start);
  EXPECT_EQ(warning,
            "plotter failed on " + d + "/p.gp (still running after 0.5 s: killed); no PNG written");
  EXPECT_GE(elapsed, 0.5);
  EXPECT_LT(elapsed, 5.0);
  EXPECT_FALSE(fs::exists(d + "/p.png"));
  EXPECT_FALSE(has_temporary_files(d));
  std::ifstream pid_file(d + "/sleep.pid");
  std::string   pid;
  ASSERT_TRUE(std::getline(pid_file, pid));
  EXPECT_TRUE(process_ends(pid, 5.0)) << "the plotter's child " << pid << " still runs";
}

TEST(CompareRunPlotter, ASlowGnuplotLeavesTheTablesAndSummaryAndAWarning)
{
  const std::string d = fresh_directory("plotter_slow_gnuplot");
  fs::create_directories(d + "/a");
  fs::create_directories(d + "/b");
  for (const auto &run : {"a", "b"})
    Output::write_file(d + "/" + run + "/probe_0.csv", "time,u_x\n0,0\n1,1\n");
  const std::string bin = d + "/bin";
  fs::create_directories(bin);
  write_script(bin, "gnuplot", "echo partial > probe_0.png.tmp\nexec /bin/sleep 30\n");

  Compare::Options options;
  options.plot_timeout = 0.3;
  std::vector<std::string> progress;
  options.progress = [&progress](const std::string &line) { progress.push_back(line); };
  Compare::ComparisonReport report;
  {
    const ScopedPath fake_gnuplot(fs::absolute(bin).string());
    report = Compare::compare_directories(d + "/a", "A", d + "/b", "B", {}, d + "/out", options);
  }

  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0],
            "gnuplot failed on " + d +
              "/out/probe_0.gp (still running after 0.3 s: killed); no PNG written");
  ASSERT_EQ(progress.size(), 1u);
  EXPECT_EQ(progress[0].find("compare: plot 1/1 probe_0.png not drawn ("), 0u) << progress[0];
  for (const auto &file : {"probe_0.csv", "probe_0.gp", "summary.csv", "summary.md"})
    EXPECT_TRUE(fs::exists(d + "/out/" + file)) << file;
  EXPECT_FALSE(fs::exists(d + "/out/probe_0.png"));
  EXPECT_FALSE(has_temporary_files(d + "/out"));
}
