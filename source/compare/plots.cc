#include <hysteron/base/output.h>

#include "compare/compare.h"
#include "compare/text.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace hysteron
{
  namespace Compare
  {
    using internal::check_labels;
    using internal::number;

    namespace
    {
      namespace fs = std::filesystem;

      bool
      starts_with(const std::string &s, const std::string &prefix)
      {
        return s.compare(0, prefix.size(), prefix) == 0;
      }

      /// The order of the automatic plot selection (lower first).
      int
      plot_rank(const std::string &c)
      {
        const bool strain = c.size() == 6 && starts_with(c, "eps_") &&
                            std::string("xyz").find(c[4]) != std::string::npos &&
                            std::string("xyz").find(c[5]) != std::string::npos;
        if (starts_with(c, "u_"))
          return 0;
        if (c == "von_mises")
          return 1;
        if (starts_with(c, "s_"))
          return 2;
        if (strain)
          return 4;
        if (starts_with(c, "v_"))
          return 5;
        if (starts_with(c, "x_"))
          return 6;
        if (c == "mass")
          return 7;
        return 3; // state variables, reactions, energies
      }

      /// A gnuplot string literal: single quotes, a quote doubled.
      std::string
      gnuplot_string(const std::string &s)
      {
        std::string result = "'";
        for (const char c : s)
          result += (c == '\'' ? std::string("''") : std::string(1, c));
        return result + "'";
      }

      /// "set yrange [lo:hi]" for a flat series (gnuplot would warn), else autoscale.
      std::string
      range_command(const std::string &axis, const std::vector<double> &values)
      {
        const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
        if (*lo != *hi)
          return "set " + axis + "range [*:*]\n";
        const double pad = (*lo == 0 ? 1.0 : 0.1 * std::abs(*lo));
        return "set " + axis + "range [" + number(*lo - pad, 17) + ":" + number(*hi + pad, 17) +
               "]\n";
      }
    } // namespace



    std::vector<std::string>
    select_plot_columns(const TableComparison          &comparison,
                        const std::vector<std::string> &requested,
                        const unsigned int              max_columns)
    {
      std::vector<std::string> selected;
      for (const auto &c : requested)
        if (std::find(comparison.columns.begin(), comparison.columns.end(), c) !=
              comparison.columns.end() &&
            std::find(selected.begin(), selected.end(), c) == selected.end())
          selected.push_back(c);
      if (!selected.empty())
        return selected;

      // In a single row every column is constant: draw them all.
      for (const auto &d : comparison.differences)
        if (!d.constant || comparison.time.size() == 1)
          selected.push_back(d.column);
      std::stable_sort(selected.begin(),
                       selected.end(),
                       [](const std::string &x, const std::string &y) {
                         return plot_rank(x) < plot_rank(y);
                       });
      if (selected.size() > max_columns)
        selected.resize(max_columns);
      return selected;
    }



    void
    write_gnuplot_script(const TableComparison          &comparison,
                         const std::vector<std::string> &columns,
                         const std::string              &label_a,
                         const std::string              &label_b,
                         const std::string              &data_file,
                         const std::string              &png_file,
                         const std::string              &script_file,
                         Output::RunRecord              *record)
    {
      check_labels(label_a, label_b);
      const std::size_t  n_panels = std::max<std::size_t>(columns.size(), 1);
      const unsigned int n_cols = static_cast<unsigned int>(std::ceil(std::sqrt(n_panels) - 1e-9));
      const unsigned int n_rows = static_cast<unsigned int>((n_panels + n_cols - 1) / n_cols);
      const std::string  style  = comparison.time.size() > 1 ? "lines" : "points pt 7";
      const std::string  temporary = png_file + ".tmp";

      Output::AtomicFile file(script_file, record);
      auto              &out = file.stream();
      out << "# " << comparison.name << ": " << label_b << " against " << label_a
          << ", written by hysteron (doc/compare.md).\n"
          << "# Data: " << data_file << " (time, then <col>_" << label_a << ", <col>_" << label_b
          << ", <col>_diff per column). Run: gnuplot " << fs::path(script_file).filename().string()
          << " && mv " << temporary << " " << png_file << "\n"
          << "set terminal pngcairo noenhanced size " << 460 * n_cols << "," << 340 * n_rows
          << " font ',9'\n"
          << "# Draw into a temporary file, renamed by hysteron once gnuplot has succeeded: a "
             "finished PNG is never replaced by a partial one.\n"
          << "set output " << gnuplot_string(temporary) << "\n"
          << "set datafile separator ','\n"
          << "set multiplot layout " << n_rows << "," << n_cols << " title "
          << gnuplot_string(comparison.name + ": " + label_b + " against " + label_a) << "\n"
          << "set grid\n"
          << "set key top left font ',8' samplen 2\n"
          << "set xlabel 'time'\n"
          << "set ytics nomirror\n"
          << "set y2tics textcolor rgb '#7f7f7f'\n"
          << "set y2label " << gnuplot_string(label_b + " - " + label_a)
          << " textcolor rgb '#7f7f7f'\n";
      if (comparison.time.size() > 1)
        out << "set autoscale xfix\n";
      else
        out << "set xrange [" << number(comparison.time[0] - 1, 17) << ":"
            << number(comparison.time[0] + 1, 17) << "]\n";

      for (const auto &column : columns)
        {
          const auto it = std::find(comparison.columns.begin(), comparison.columns.end(), column);
          if (it == comparison.columns.end())
            throw std::logic_error("write_gnuplot_script: '" + column + "' is not a shared column");
          const std::size_t   c = it - comparison.columns.begin();
          std::vector<double> both(comparison.a[c]), diff(comparison.time.size());
          both.insert(both.end(), comparison.b[c].begin(), comparison.b[c].end());
          for (std::size_t r = 0; r < diff.size(); ++r)
            diff[r] = comparison.b[c][r] - comparison.a[c][r];

          const std::string data = gnuplot_string(data_file) + " skip 1 using 1:";
          out << "\n# " << column << "\n"
              << "set title " << gnuplot_string(column) << " offset 0,-0.6\n"
              << range_command("y", both) << range_command("y2", diff) << "plot " << data
              << 2 + 3 * c << " with " << style << " lw 2 lc rgb '#1f77b4' title "
              << gnuplot_string(label_a) << ", \\\n     " << data << 3 + 3 * c << " with " << style
              << " lw 2 dt 2 lc rgb '#d62728' title " << gnuplot_string(label_b) << ", \\\n     "
              << data << 4 + 3 * c << " axes x1y2 with " << style << " lw 1 lc rgb '#7f7f7f' title "
              << gnuplot_string(label_b + " - " + label_a) << "\n";
        }
      out << "\nunset multiplot\n"
          << "set output\n";
      file.commit();
    }



    void
    write_plots(ComparisonReport &report, const Options &options)
    {
      // Every compared table with a column to draw, and its columns.
      std::vector<std::pair<const TableComparison *, std::vector<std::string>>> plots;
      for (const auto &t : report.tables)
        {
          if (t.time.empty())
            continue;
          auto columns = select_plot_columns(t, options.plot_columns, options.max_plot_columns);
          if (columns.empty())
            report.warnings.push_back(t.name + (t.columns.empty()
                                                  ? ": no shared column; no plot"
                                                  : ": every shared column is constant; no plot"));
          else
            plots.emplace_back(&t, std::move(columns));
        }

      const fs::path directory(report.output_directory);
      for (std::size_t i = 0; i < plots.size(); ++i)
        {
          const auto        start  = std::chrono::steady_clock::now();
          const auto       &table  = *plots[i].first;
          const std::string stem   = fs::path(table.name).stem().string();
          const std::string png    = stem + ".png";
          const std::string script = (directory / (stem + ".gp")).string();
          write_gnuplot_script(table,
                               plots[i].second,
                               report.label_a,
                               report.label_b,
                               stem + ".csv",
                               png,
                               script,
                               options.record);
          const std::string warning = run_gnuplot(script, png, options.plot_timeout, options.record);
          if (!warning.empty())
            report.warnings.push_back(warning);
          if (options.progress)
            {
              const std::chrono::duration<double> seconds =
                std::chrono::steady_clock::now() - start;
              std::error_code ec;
              options.progress("compare: plot " + std::to_string(i + 1) + "/" +
                               std::to_string(plots.size()) + " " + png +
                               (fs::exists(directory / png, ec) ? "" : " not drawn") + " (" +
                               internal::format("%.2f", seconds.count()) + " s)");
            }
        }
    }
  } // namespace Compare
} // namespace hysteron
