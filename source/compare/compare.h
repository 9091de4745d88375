#ifndef hysteron_source_compare_compare_h
#define hysteron_source_compare_compare_h

#include "base/plotter.h"
#include <functional>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * Side-by-side comparison of the time tables two runs write (probe_<i>.csv,
   * average_<i>.csv, reactions.csv, energy.csv): the back end of
   * `hysteron --compare`, which runs one scene with two methods (A, e.g. MPM, and
   * B, e.g. FEM). See doc/compare.md for the files and the norms.
   *
   * The module: table.cc reads a CSV table, norms.cc aligns the two time bases
   * and computes the differences, report.cc writes the side-by-side tables and
   * the summaries, plots.cc the gnuplot scripts, plotter.cc runs the plotter,
   * compare_method.cc is the registered method `compare`.
   *
   * None of these functions is collective: call them on one MPI rank. The
   * writers take the record of the run whose files they write (null: the
   * comparison of two directories on its own).
   */
  namespace Compare
  {
    /**
     * A numeric table with a header line, stored by column: values[c][r] is
     * row r of the column named columns[c].
     */
    struct Table
    {
      /// Where the table came from ("<dir>/probe_0.csv"), for messages.
      std::string source;

      std::vector<std::string> columns;

      std::vector<std::vector<double>> values;

      /// The line of each row in @p source (1 = header); empty for tables made in memory.
      std::vector<unsigned int> lines;

      unsigned int
      n_rows() const;

      /// The index of column @p name, or numbers::invalid_unsigned_int.
      unsigned int
      column_index(const std::string &name) const;

      /// Append a row (one value per column). Throws std::logic_error on a wrong length.
      void
      add_row(const std::vector<double> &row);

      /// "<source>:<line>" of row @p row, or "<source>, row <row + 1>" without line numbers.
      std::string
      where(unsigned int row) const;
    };

    /**
     * Read a CSV table: a header line of distinct column names, then rows of
     * finite numbers separated by commas (blank lines are skipped, CRLF line ends
     * accepted). Throws InputError whose where() is "<file>" for a file that
     * cannot be opened or "<file>:<line>" for a missing header, a duplicate or
     * empty column name, a ragged row or a value that is not a finite number.
     */
    Table
    read_csv(const std::string &file);

    /// The differences of one column shared by both tables, over the compared rows.
    struct ColumnDifference
    {
      std::string column;

      /// max |b - a|.
      double max_abs_difference = 0;

      /// S = max |a|; max |b| if a is zero; 0 if both are zero.
      double scale = 0;

      /// max |b - a| / S (0 if S = 0).
      double max_relative_difference = 0;

      /// sqrt(int (b - a)^2 dt / int a^2 dt), trapezoidal rule (int b^2 if a is zero; 0 if both
      /// are).
      double l2_relative_difference = 0;

      /// The column takes a single value in A and a single value in B.
      bool constant = false;
    };

    /**
     * The comparison of a table B against a table A. B (and A) are evaluated
     * by linear interpolation in time at A's times within the common time range
     * [max(a_0, b_0), min(a_end, b_end)]; A's rows outside it are dropped. If
     * the common range is the single instant of a one-row table, that instant
     * is compared; two one-row tables are compared row by row whatever their
     * times. An empty @p time means nothing could be compared (see @p warnings).
     */
    struct TableComparison
    {
      /// The table's name, e.g. "probe_0.csv".
      std::string name;

      /// The compared times.
      std::vector<double> time;

      /// The shared columns (in A's order, without "time").
      std::vector<std::string> columns;

      /// a[c][r], b[c][r]: the values of columns[c] at time[r].
      std::vector<std::vector<double>> a;
      std::vector<std::vector<double>> b;

      /// One entry per shared column, in the order of @p columns.
      std::vector<ColumnDifference> differences;

      /// Columns of only one of the tables.
      std::vector<std::string> only_in_a;
      std::vector<std::string> only_in_b;

      /// Why nothing or not everything was compared (no common time range, ...).
      std::vector<std::string> warnings;
    };

    /**
     * Compare table @p b against table @p a on the columns they share (matched
     * by name). Both tables need a column "time" with strictly increasing
     * values; InputError naming the source and line otherwise.
     */
    TableComparison
    compare_tables(const Table &a, const Table &b, const std::string &name);

    /**
     * The columns to draw for @p comparison. With an empty @p requested list:
     * every shared column that is not constant in both tables (every column of
     * a single compared row), displacements u_* first, then von_mises, stresses
     * s_*, other columns (material state such as H1, eps_ps; reactions;
     * energies) in table order, strains eps_ij, velocities v_*, positions x_*,
     * mass; at most @p max_columns. Otherwise the
     * requested columns the tables share, in the requested order (the automatic
     * choice if there are none).
     */
    std::vector<std::string>
    select_plot_columns(const TableComparison          &comparison,
                        const std::vector<std::string> &requested   = {},
                        unsigned int                    max_columns = 12);

    /**
     * Write the side-by-side table: "time", then for every shared column
     * "<col>_<label_a>", "<col>_<label_b>", "<col>_diff" (= B - A).
     */
    void
    write_side_by_side(const TableComparison &comparison,
                       const std::string     &label_a,
                       const std::string     &label_b,
                       const std::string     &filename,
                       Output::RunRecord     *record = nullptr);

    /**
     * Write a gnuplot script that draws @p columns of the side-by-side table
     * @p data_file (written by write_side_by_side()) in a grid of panels, A and
     * B on the left axis, B - A on the right one, into "<png_file>.tmp"
     * (pngcairo), which run_gnuplot() renames to @p png_file once gnuplot has
     * succeeded: a finished PNG is never replaced by a partial one. File names
     * in the script are taken as they are: pass names relative to the directory
     * the script runs in (run_gnuplot() runs it in its own directory).
     */
    void
    write_gnuplot_script(const TableComparison          &comparison,
                         const std::vector<std::string> &columns,
                         const std::string              &label_a,
                         const std::string              &label_b,
                         const std::string              &data_file,
                         const std::string              &png_file,
                         const std::string              &script_file,
                         Output::RunRecord              *record = nullptr);

    // The plotter (base/plotter.h), which the methods' set histories draw with too.
    using Plot::gnuplot_available;
    using Plot::PlotCommand;
    using Plot::run_gnuplot;
    using Plot::run_plotter;

    /// The outcome of compare_directories().
    struct ComparisonReport
    {
      std::string label_a;
      std::string label_b;
      std::string directory_a;
      std::string directory_b;

      /// The comparison's output directory.
      std::string output_directory;

      /// The tables found in both directories, in the order they were requested.
      std::vector<TableComparison> tables;

      /// Requested tables absent from directory A, and from directory B.
      std::vector<std::string> missing_in_a;
      std::vector<std::string> missing_in_b;

      /// Things the caller should print: missing tables, tables not compared, plots not made.
      std::vector<std::string> warnings;
    };

    /// Options of compare_directories() and write_plots().
    struct Options
    {
      /// Columns to plot (for every table that has them); empty: automatic.
      std::vector<std::string> plot_columns;

      /// At most this many panels per plot in the automatic choice.
      unsigned int max_plot_columns = 12;

      /// compare_directories() draws the plots (write_plots()).
      bool plots = true;

      /// Seconds one plot may take before the plotter is killed.
      double plot_timeout = 60;

      /// Called with a line of progress per plot (none if empty).
      std::function<void(const std::string &)> progress;

      /// The run whose files the comparison writes (null: none).
      Output::RunRecord *record = nullptr;
    };

    /// Write summary.csv: one row per (table, column), sorted by table then column.
    void
    write_summary_csv(const ComparisonReport &report,
                      const std::string      &filename,
                      Output::RunRecord      *record = nullptr);

    /// Write summary.md: the same as a Markdown table, relative differences in %.
    void
    write_summary_markdown(const ComparisonReport &report,
                           const std::string      &filename,
                           Output::RunRecord      *record = nullptr);

    /**
     * Compare the tables @p files (plain file names such as "probe_0.csv";
     * empty: every *.csv file of either directory whose first column is "time")
     * of the run in @p dir_b (label @p label_b) against those of the run in
     * @p dir_a, and write into @p out_dir (created if needed; it must be neither
     * input directory):
     *
     * - <stem>.csv: the side-by-side table of every table present in both,
     * - summary.csv and summary.md over all tables, naming tables present in
     *   only one directory and columns present in only one table,
     * - with Options::plots, then, the plots (write_plots()).
     *
     * All inputs are read and compared before anything is written: an unreadable
     * or malformed table (InputError naming file and line) leaves no output.
     * A table missing in one directory, a table without a common time range and
     * a plot that could not be made are warnings, not errors. Every file is
     * written atomically.
     */
    ComparisonReport
    compare_directories(const std::string              &dir_a,
                        const std::string              &label_a,
                        const std::string              &dir_b,
                        const std::string              &label_b,
                        const std::vector<std::string> &files,
                        const std::string              &out_dir,
                        const Options                  &options = Options());

    /**
     * Draw the plots of @p report (made by compare_directories()) in its output
     * directory: for every compared table with a column to draw,
     * <stem>.gp and, with gnuplot on PATH, <stem>.png (run_gnuplot(), at most
     * Options::plot_timeout seconds each). Adds a warning to @p report for every
     * plot not made; never throws because of gnuplot.
     */
    void
    write_plots(ComparisonReport &report, const Options &options = Options());
  } // namespace Compare
} // namespace hysteron

#endif
