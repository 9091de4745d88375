#include <deal.II/base/numbers.h>

#include <hysteron/base/compare.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

namespace hysteron
{
  namespace Compare
  {
    namespace
    {
      namespace fs = std::filesystem;

      /// 15 significant digits, -0 printed as 0: the format of CsvWriter.
      std::string
      number(const double value, const int digits = 15)
      {
        std::ostringstream s;
        s << std::setprecision(digits) << value + 0.0;
        return s.str();
      }

      std::string
      trim(const std::string &s)
      {
        const auto begin = s.find_first_not_of(" \t\r");
        if (begin == std::string::npos)
          return "";
        const auto end = s.find_last_not_of(" \t\r");
        return s.substr(begin, end - begin + 1);
      }

      std::vector<std::string>
      split(const std::string &line)
      {
        std::vector<std::string> fields;
        std::size_t              begin = 0;
        while (true)
          {
            const auto comma = line.find(',', begin);
            fields.push_back(trim(line.substr(begin, comma - begin)));
            if (comma == std::string::npos)
              return fields;
            begin = comma + 1;
          }
      }

      /// Parse a whole field as a finite number (locale independent).
      bool
      parse_number(const std::string &field, double &value)
      {
        const char *begin = field.data();
        const char *end   = field.data() + field.size();
        if (begin != end && *begin == '+')
          ++begin;
        if (begin != end && (*begin == '+' || *begin == '-') && begin != field.data())
          return false;
        const auto result = std::from_chars(begin, end, value);
        return begin != end && result.ec == std::errc() && result.ptr == end &&
               std::isfinite(value);
      }

      /// Natural order: digit runs compare as numbers (probe_2 < probe_10), letters ignore case.
      bool
      natural_less(const std::string &a, const std::string &b)
      {
        std::size_t i = 0, j = 0;
        while (i < a.size() && j < b.size())
          {
            if (std::isdigit(static_cast<unsigned char>(a[i])) &&
                std::isdigit(static_cast<unsigned char>(b[j])))
              {
                std::size_t ie = i, je = j;
                while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie])))
                  ++ie;
                while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je])))
                  ++je;
                const std::string x = a.substr(i, ie - i), y = b.substr(j, je - j);
                const auto        xs = x.find_first_not_of('0'), ys = y.find_first_not_of('0');
                const std::string xn = xs == std::string::npos ? "" : x.substr(xs);
                const std::string yn = ys == std::string::npos ? "" : y.substr(ys);
                if (xn.size() != yn.size())
                  return xn.size() < yn.size();
                if (xn != yn)
                  return xn < yn;
                i = ie;
                j = je;
              }
            else
              {
                const int x = std::tolower(static_cast<unsigned char>(a[i]));
                const int y = std::tolower(static_cast<unsigned char>(b[j]));
                if (x != y)
                  return x < y;
                ++i;
                ++j;
              }
          }
        return a.size() - i < b.size() - j || (a.size() - i == b.size() - j && a < b);
      }

      bool
      starts_with(const std::string &s, const std::string &prefix)
      {
        return s.compare(0, prefix.size(), prefix) == 0;
      }

      /// Labels become column names and plot titles: a short word.
      void
      check_labels(const std::string &label_a, const std::string &label_b)
      {
        for (const std::string &label : {label_a, label_b})
          {
            require(!label.empty() && label != "diff" &&
                      std::all_of(label.begin(),
                                  label.end(),
                                  [](const char c) {
                                    return std::isalnum(static_cast<unsigned char>(c)) ||
                                           c == '_' || c == '-' || c == '.' || c == '+';
                                  }),
                    "comparison label '" + label + "'",
                    "must be a non-empty word of letters, digits and _-.+ (and not 'diff')");
          }
        require(label_a != label_b,
                "comparison labels",
                "the two runs need different labels (both are '" + label_a + "')");
      }

      /// The time column of @p table, checked to increase strictly.
      const std::vector<double> &
      checked_time(const Table &table)
      {
        const unsigned int c = table.column_index("time");
        require(c != dealii::numbers::invalid_unsigned_int, table.source, "has no column 'time'");
        const std::vector<double> &t = table.values[c];
        for (unsigned int r = 1; r < t.size(); ++r)
          require(t[r] > t[r - 1],
                  table.where(r),
                  "time " + number(t[r]) + " does not increase (previous row: " + number(t[r - 1]) +
                    ")");
        return t;
      }

      /// @p v(@p t) linearly interpolated at the increasing times @p at, which lie in [t_0, t_end].
      std::vector<double>
      sample(const std::vector<double> &t,
             const std::vector<double> &v,
             const std::vector<double> &at)
      {
        std::vector<double> result;
        result.reserve(at.size());
        std::size_t j = 0;
        for (const double s : at)
          {
            while (j + 1 < t.size() && t[j + 1] <= s)
              ++j;
            if (t[j] == s || j + 1 == t.size())
              result.push_back(v[j]);
            else
              {
                // (1 - theta) v_j + theta v_j+1 is exact at both ends of the interval.
                const double theta = (s - t[j]) / (t[j + 1] - t[j]);
                result.push_back((1 - theta) * v[j] + theta * v[j + 1]);
              }
          }
        return result;
      }

      ColumnDifference
      difference(const std::string         &column,
                 const std::vector<double> &time,
                 const std::vector<double> &a,
                 const std::vector<double> &b)
      {
        ColumnDifference result;
        result.column       = column;
        const std::size_t n = time.size();

        double max_a = 0, max_b = 0, max_d = 0;
        bool   constant_a = true, constant_b = true;
        for (std::size_t r = 0; r < n; ++r)
          {
            max_a      = std::max(max_a, std::abs(a[r]));
            max_b      = std::max(max_b, std::abs(b[r]));
            max_d      = std::max(max_d, std::abs(b[r] - a[r]));
            constant_a = constant_a && a[r] == a[0];
            constant_b = constant_b && b[r] == b[0];
          }
        result.constant           = constant_a && constant_b;
        result.max_abs_difference = max_d;

        // The reference is A, or B where A is identically zero.
        const bool                 a_is_zero = (max_a == 0);
        const std::vector<double> &reference = a_is_zero ? b : a;
        result.scale                         = a_is_zero ? max_b : max_a;
        if (result.scale == 0 || max_d == 0)
          return result;
        result.max_relative_difference = max_d / result.scale;

        // Trapezoidal weights; the sums are scaled by the maxima to avoid under- and overflow:
        // L2 = (max_d / S) sqrt(sum w (d / max_d)^2 / sum w (ref / S)^2).
        double sum_d = 0, sum_ref = 0;
        for (std::size_t r = 0; r < n; ++r)
          {
            const double w =
              n == 1 ? 1.0 : 0.5 * (time[std::min(r + 1, n - 1)] - time[r == 0 ? 0 : r - 1]);
            const double d   = (b[r] - a[r]) / max_d;
            const double ref = reference[r] / result.scale;
            sum_d += w * d * d;
            sum_ref += w * ref * ref;
          }
        result.l2_relative_difference = result.max_relative_difference * std::sqrt(sum_d / sum_ref);
        return result;
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

      /// A POSIX shell word.
      std::string
      shell_word(const std::string &s)
      {
        std::string result = "'";
        for (const char c : s)
          result += (c == '\'' ? std::string("'\\''") : std::string(1, c));
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

      /// A CSV text field (quoted if needed).
      std::string
      csv_text(const std::string &s)
      {
        if (s.find_first_of(",\"\n") == std::string::npos)
          return s;
        std::string result = "\"";
        for (const char c : s)
          result += (c == '"' ? std::string("\"\"") : std::string(1, c));
        return result + "\"";
      }

      std::string
      markdown_text(const std::string &s)
      {
        std::string result;
        for (const char c : s)
          result += (c == '|' ? std::string("\\|") : std::string(1, c));
        return result;
      }

      std::string
      format(const char *spec, const double value)
      {
        char buffer[64];
        std::snprintf(buffer, sizeof(buffer), spec, value + 0.0);
        return buffer;
      }

      /// One line of the summaries: a compared column, or a table or column of one run only.
      struct SummaryEntry
      {
        std::string             table;
        std::string             column;
        std::string             status;
        const TableComparison  *comparison = nullptr;
        const ColumnDifference *difference = nullptr;
      };

      std::vector<SummaryEntry>
      summary_entries(const ComparisonReport &report)
      {
        std::vector<SummaryEntry> entries;
        for (const auto &t : report.tables)
          {
            if (t.time.empty())
              entries.push_back({t.name, "", "not compared", &t, nullptr});
            else
              for (const auto &d : t.differences)
                entries.push_back({t.name, d.column, "compared", &t, &d});
            for (const auto &c : t.only_in_a)
              entries.push_back({t.name, c, "only in " + report.label_a, &t, nullptr});
            for (const auto &c : t.only_in_b)
              entries.push_back({t.name, c, "only in " + report.label_b, &t, nullptr});
          }
        for (const auto &name : report.missing_in_a)
          entries.push_back({name, "", "missing in " + report.label_a, nullptr, nullptr});
        for (const auto &name : report.missing_in_b)
          entries.push_back({name, "", "missing in " + report.label_b, nullptr, nullptr});
        std::stable_sort(entries.begin(),
                         entries.end(),
                         [](const SummaryEntry &x, const SummaryEntry &y) {
                           if (x.table != y.table)
                             return natural_less(x.table, y.table);
                           return natural_less(x.column, y.column);
                         });
        return entries;
      }

      fs::path
      canonical(const std::string &directory)
      {
        std::error_code ec;
        fs::path        p = fs::weakly_canonical(directory, ec);
        if (ec)
          p = fs::absolute(directory).lexically_normal();
        return p.has_filename() ? p : p.parent_path(); // "a/b/" is "a/b"
      }

      /// Whether the first field of the first line of @p file is "time".
      bool
      is_time_table(const fs::path &file)
      {
        std::ifstream in(file);
        std::string   line;
        return std::getline(in, line) && split(line).front() == "time";
      }
    } // namespace



    unsigned int
    Table::n_rows() const
    {
      return values.empty() ? 0 : values.front().size();
    }



    unsigned int
    Table::column_index(const std::string &name) const
    {
      const auto it = std::find(columns.begin(), columns.end(), name);
      return it == columns.end() ? dealii::numbers::invalid_unsigned_int
                                 : static_cast<unsigned int>(it - columns.begin());
    }



    void
    Table::add_row(const std::vector<double> &row)
    {
      if (row.size() != columns.size())
        throw std::logic_error("Table::add_row: " + std::to_string(row.size()) + " values for " +
                               std::to_string(columns.size()) + " columns");
      values.resize(columns.size());
      for (std::size_t c = 0; c < row.size(); ++c)
        values[c].push_back(row[c]);
    }



    std::string
    Table::where(const unsigned int row) const
    {
      if (row < lines.size())
        return source + ":" + std::to_string(lines[row]);
      return source + ", row " + std::to_string(row + 1);
    }



    Table
    read_csv(const std::string &file)
    {
      std::ifstream in(file);
      if (!in)
        throw InputError(file, std::string("cannot open the file: ") + std::strerror(errno));

      Table table;
      table.source = file;
      std::string line;
      if (!std::getline(in, line) || trim(line).empty())
        throw InputError(file + ":1", "no header line");
      table.columns = split(line);
      for (std::size_t c = 0; c < table.columns.size(); ++c)
        {
          require(!table.columns[c].empty(),
                  file + ":1",
                  "column " + std::to_string(c + 1) + " has no name");
          require(std::find(table.columns.begin(), table.columns.begin() + c, table.columns[c]) ==
                    table.columns.begin() + c,
                  file + ":1",
                  "the column name '" + table.columns[c] + "' appears twice");
        }
      table.values.resize(table.columns.size());

      for (unsigned int number_of_line = 2; std::getline(in, line); ++number_of_line)
        {
          if (trim(line).empty())
            continue;
          const std::vector<std::string> fields = split(line);
          const std::string              where  = file + ":" + std::to_string(number_of_line);
          require(fields.size() == table.columns.size(),
                  where,
                  "the row has " + std::to_string(fields.size()) + " values, the header has " +
                    std::to_string(table.columns.size()) + " columns");
          for (std::size_t c = 0; c < fields.size(); ++c)
            {
              double value = 0;
              require(parse_number(fields[c], value),
                      where,
                      "'" + fields[c] + "' in column '" + table.columns[c] +
                        "' is not a finite number");
              table.values[c].push_back(value);
            }
          table.lines.push_back(number_of_line);
        }
      if (in.bad())
        throw InputError(file, std::string("cannot read the file: ") + std::strerror(errno));
      return table;
    }



    TableComparison
    compare_tables(const Table &a, const Table &b, const std::string &name)
    {
      const std::vector<double> &ta = checked_time(a);
      const std::vector<double> &tb = checked_time(b);

      TableComparison result;
      result.name = name;
      for (const auto &c : a.columns)
        if (c != "time")
          (b.column_index(c) == dealii::numbers::invalid_unsigned_int ? result.only_in_a
                                                                      : result.columns)
            .push_back(c);
      for (const auto &c : b.columns)
        if (c != "time" && a.column_index(c) == dealii::numbers::invalid_unsigned_int)
          result.only_in_b.push_back(c);

      if (ta.empty() || tb.empty())
        {
          result.warnings.push_back("not compared: " + (ta.empty() ? a.source : b.source) +
                                    " has no rows");
          return result;
        }

      const double begin = std::max(ta.front(), tb.front());
      const double end   = std::min(ta.back(), tb.back());
      if (ta.size() == 1 && tb.size() == 1)
        {
          // Two single rows (a static result, say): compare them whatever their times.
          result.time = ta;
          if (ta[0] != tb[0])
            result.warnings.push_back("the single rows are at different times (" + number(ta[0]) +
                                      " in " + a.source + ", " + number(tb[0]) + " in " + b.source +
                                      "); compared at " + number(ta[0]));
        }
      else if (begin > end)
        {
          result.warnings.push_back("not compared: no common time range ([" + number(ta.front()) +
                                    ", " + number(ta.back()) + "] in " + a.source + ", [" +
                                    number(tb.front()) + ", " + number(tb.back()) + "] in " +
                                    b.source + ")");
          return result;
        }
      else
        {
          for (const double t : ta)
            if (t >= begin && t <= end)
              result.time.push_back(t);
          // The common range is the instant of a single row of B between rows of A.
          if (result.time.empty())
            result.time.push_back(begin);
        }

      for (const auto &c : result.columns)
        {
          const auto &va = a.values[a.column_index(c)];
          const auto &vb = b.values[b.column_index(c)];
          result.a.push_back(sample(ta, va, result.time));
          result.b.push_back(sample(tb, vb, result.time));
          result.differences.push_back(
            difference(c, result.time, result.a.back(), result.b.back()));
        }
      return result;
    }



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
    write_side_by_side(const TableComparison &comparison,
                       const std::string     &label_a,
                       const std::string     &label_b,
                       const std::string     &filename)
    {
      check_labels(label_a, label_b);
      std::vector<std::string> header{"time"};
      for (const auto &c : comparison.columns)
        for (const auto &suffix : {label_a, label_b, std::string("diff")})
          header.push_back(c + "_" + suffix);

      Output::CsvWriter   csv(filename, header);
      std::vector<double> row(header.size());
      for (std::size_t r = 0; r < comparison.time.size(); ++r)
        {
          row[0] = comparison.time[r];
          for (std::size_t c = 0; c < comparison.columns.size(); ++c)
            {
              row[1 + 3 * c] = comparison.a[c][r];
              row[2 + 3 * c] = comparison.b[c][r];
              row[3 + 3 * c] = comparison.b[c][r] - comparison.a[c][r];
            }
          csv.add_row(row);
        }
      csv.commit();
    }



    void
    write_gnuplot_script(const TableComparison          &comparison,
                         const std::vector<std::string> &columns,
                         const std::string              &label_a,
                         const std::string              &label_b,
                         const std::string              &data_file,
                         const std::string              &png_file,
                         const std::string              &script_file)
    {
      check_labels(label_a, label_b);
      const std::size_t  n_panels = std::max<std::size_t>(columns.size(), 1);
      const unsigned int n_cols = static_cast<unsigned int>(std::ceil(std::sqrt(n_panels) - 1e-9));
      const unsigned int n_rows = static_cast<unsigned int>((n_panels + n_cols - 1) / n_cols);
      const std::string  style  = comparison.time.size() > 1 ? "lines" : "points pt 7";
      const std::string  temporary = png_file + ".tmp";

      Output::AtomicFile file(script_file);
      auto              &out = file.stream();
      out << "# " << comparison.name << ": " << label_b << " against " << label_a
          << ", written by hysteron (doc/compare.md).\n"
          << "# Data: " << data_file << " (time, then <col>_" << label_a << ", <col>_" << label_b
          << ", <col>_diff per column). Run: gnuplot " << fs::path(script_file).filename().string()
          << "\n"
          << "set terminal pngcairo noenhanced size " << 460 * n_cols << "," << 340 * n_rows
          << " font ',9'\n"
          << "# Plot into a temporary file, renamed below: a finished PNG is never replaced by a "
             "partial one.\n"
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
          << "set output\n"
          << "system "
          << gnuplot_string("mv -f -- " + shell_word(temporary) + " " + shell_word(png_file))
          << "\n";
      file.commit();
    }



    bool
    gnuplot_available()
    {
      const char *path = std::getenv("PATH");
      if (path == nullptr)
        return false;
      std::istringstream directories(path);
      std::string        directory;
      while (std::getline(directories, directory, ':'))
        {
          const std::string candidate = (directory.empty() ? "." : directory) + "/gnuplot";
          if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate))
            return true;
        }
      return false;
    }



    std::string
    run_gnuplot(const std::string &script_file, const std::string &png_file)
    {
      const fs::path  directory = fs::path(script_file).parent_path();
      const fs::path  png       = directory / png_file;
      const fs::path  temporary = directory / (png_file + ".tmp");
      std::error_code ec;
      const auto      remove_outputs = [&]() {
        // A PNG of an earlier run would not show these data.
        fs::remove(temporary, ec);
        fs::remove(png, ec);
      };

      if (!gnuplot_available())
        {
          remove_outputs();
          return "gnuplot is not on PATH: wrote " + script_file + " but not its PNG";
        }

      const std::string command = "cd " + shell_word(directory.empty() ? "." : directory.string()) +
                                  " && gnuplot " +
                                  shell_word(fs::path(script_file).filename().string()) + " 2>&1";
      std::FILE *pipe = ::popen(command.c_str(), "r");
      if (pipe == nullptr)
        {
          remove_outputs();
          return "cannot run gnuplot on " + script_file + ": " + std::strerror(errno);
        }
      std::string messages;
      char        buffer[4096];
      while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr)
        messages += buffer;
      const int status = ::pclose(pipe);
      messages         = trim(messages);
      std::replace(messages.begin(), messages.end(), '\n', ' ');

      // Done means: gnuplot succeeded and the script renamed the complete plot.
      if (status != 0 || fs::exists(temporary, ec) || !fs::exists(png, ec))
        {
          remove_outputs();
          return "gnuplot failed on " + script_file +
                 (status == -1        ? std::string()
                  : WIFEXITED(status) ? " (exit status " + std::to_string(WEXITSTATUS(status)) + ")"
                                      : std::string(" (killed)")) +
                 (messages.empty() ? std::string() : ": " + messages) + "; no PNG written";
        }
      if (!messages.empty())
        return "gnuplot on " + script_file + ": " + messages;
      return "";
    }



    void
    write_summary_csv(const ComparisonReport &report, const std::string &filename)
    {
      Output::AtomicFile file(filename);
      auto              &out = file.stream();
      out << "table,column,status,rows,time_begin,time_end,scale,max_abs_difference,"
             "max_relative_difference,l2_relative_difference\n";
      for (const auto &e : summary_entries(report))
        {
          out << csv_text(e.table) << ',' << csv_text(e.column) << ',' << csv_text(e.status);
          if (e.difference != nullptr)
            {
              const auto &t = *e.comparison;
              const auto &d = *e.difference;
              out << ',' << t.time.size() << ',' << number(t.time.front()) << ','
                  << number(t.time.back()) << ',' << number(d.scale) << ','
                  << number(d.max_abs_difference) << ',' << number(d.max_relative_difference) << ','
                  << number(d.l2_relative_difference) << '\n';
            }
          else
            out << ",,,,,,,\n";
        }
      file.commit();
    }



    void
    write_summary_markdown(const ComparisonReport &report, const std::string &filename)
    {
      const std::string A = report.label_a, B = report.label_b;

      Output::AtomicFile file(filename);
      auto              &out = file.stream();
      out << "# " << B << " against " << A << "\n\n"
          << "A = " << A << " (`" << report.directory_a << "`), B = " << B << " (`"
          << report.directory_b << "`).\n\n"
          << "Norms over the rows of A in the common time range of the two tables, B linearly "
             "interpolated in time to A's times t_i: max |B - A|; the scale S = max |A| (max |B| "
             "if A is zero); max rel. = max |B - A| / S; L2 rel. = sqrt(int (B - A)^2 dt / int "
             "A^2 dt) (int B^2 dt if A is zero), integrals by the trapezoidal rule over t_i. A "
             "column that is zero in both runs has differences 0.\n\n";

      out << "| table | column | max \\|" << B << " - " << A
          << "\\| | S | max rel. [%] | L2 rel. [%] |\n"
          << "|---|---|---:|---:|---:|---:|\n";
      for (const auto &e : summary_entries(report))
        if (e.difference != nullptr)
          out << "| " << markdown_text(e.table) << " | " << markdown_text(e.column) << " | "
              << format("%.4g", e.difference->max_abs_difference) << " | "
              << format("%.4g", e.difference->scale) << " | "
              << format("%.3g", 100 * e.difference->max_relative_difference) << " | "
              << format("%.3g", 100 * e.difference->l2_relative_difference) << " |\n";

      out << "\n";
      std::vector<const TableComparison *> tables;
      for (const auto &t : report.tables)
        tables.push_back(&t);
      std::sort(tables.begin(), tables.end(), [](const auto *x, const auto *y) {
        return natural_less(x->name, y->name);
      });
      for (const auto *t : tables)
        {
          out << "- " << markdown_text(t->name) << ": ";
          if (t->time.empty())
            out << "not compared";
          else
            out << t->time.size() << (t->time.size() == 1 ? " row" : " rows") << ", time "
                << number(t->time.front(), 6) << " to " << number(t->time.back(), 6);
          for (const auto &[label, columns] :
               {std::make_pair(A, t->only_in_a), std::make_pair(B, t->only_in_b)})
            if (!columns.empty())
              {
                auto sorted = columns;
                std::sort(sorted.begin(), sorted.end(), natural_less);
                out << "; columns only in " << label << ":";
                for (std::size_t i = 0; i < sorted.size(); ++i)
                  out << (i == 0 ? " " : ", ") << markdown_text(sorted[i]);
              }
          for (const auto &w : t->warnings)
            out << "; " << markdown_text(w);
          out << "\n";
        }
      std::set<std::string> missing(report.missing_in_a.begin(), report.missing_in_a.end());
      missing.insert(report.missing_in_b.begin(), report.missing_in_b.end());
      std::vector<std::string> names(missing.begin(), missing.end());
      std::sort(names.begin(), names.end(), natural_less);
      for (const auto &name : names)
        {
          const auto in = [&name](const std::vector<std::string> &list) {
            return std::find(list.begin(), list.end(), name) != list.end();
          };
          out << "- " << markdown_text(name) << ": "
              << (in(report.missing_in_a) && in(report.missing_in_b) ? "in neither run"
                  : in(report.missing_in_a)                          ? "only in " + B
                                                                     : "only in " + A)
              << "\n";
        }
      file.commit();
    }



    ComparisonReport
    compare_directories(const std::string              &dir_a,
                        const std::string              &label_a,
                        const std::string              &dir_b,
                        const std::string              &label_b,
                        const std::vector<std::string> &files,
                        const std::string              &out_dir,
                        const Options                  &options)
    {
      check_labels(label_a, label_b);
      std::error_code ec;
      for (const auto &d : {dir_a, dir_b})
        require(fs::is_directory(d, ec), d, "is not a directory");
      require(!out_dir.empty(), "comparison output directory", "the name is empty");
      for (const auto &d : {dir_a, dir_b})
        require(canonical(out_dir) != canonical(d),
                out_dir,
                "the comparison output directory must not be an input directory");

      // The tables to compare.
      std::vector<std::string> names;
      if (files.empty())
        {
          std::set<std::string> found;
          for (const auto &d : {dir_a, dir_b})
            for (const auto &entry : fs::directory_iterator(d))
              if (entry.is_regular_file() && entry.path().extension() == ".csv" &&
                  is_time_table(entry.path()))
                found.insert(entry.path().filename().string());
          names.assign(found.begin(), found.end());
          std::sort(names.begin(), names.end(), natural_less);
        }
      else
        for (const auto &name : files)
          if (std::find(names.begin(), names.end(), name) == names.end())
            names.push_back(name);
      for (const auto &name : names)
        {
          const fs::path p(name);
          require(!name.empty() && p == p.filename() && name != "." && name != "..",
                  "compared table '" + name + "'",
                  "must be a file name without a directory");
          require(p.stem() != "summary",
                  "compared table '" + name + "'",
                  "would collide with the comparison's summary files");
        }

      // Read and compare everything before writing anything.
      ComparisonReport report;
      report.label_a     = label_a;
      report.label_b     = label_b;
      report.directory_a = dir_a;
      report.directory_b = dir_b;
      for (const auto &name : names)
        {
          const std::string file_a = (fs::path(dir_a) / name).string();
          const std::string file_b = (fs::path(dir_b) / name).string();
          const bool        in_a = fs::exists(file_a, ec), in_b = fs::exists(file_b, ec);
          if (in_a && in_b)
            {
              report.tables.push_back(compare_tables(read_csv(file_a), read_csv(file_b), name));
              for (const auto &w : report.tables.back().warnings)
                report.warnings.push_back(name + ": " + w);
            }
          else
            {
              if (!in_a)
                report.missing_in_a.push_back(name);
              if (!in_b)
                report.missing_in_b.push_back(name);
              report.warnings.push_back(name + ": " +
                                        (in_a || in_b ? "only in " + (in_a ? dir_a : dir_b)
                                                      : "in neither " + dir_a + " nor " + dir_b) +
                                        "; not compared");
            }
        }

      Output::prepare_directory(out_dir, "comparison output directory");
      for (const auto &t : report.tables)
        {
          if (t.time.empty())
            continue;
          const std::string stem = fs::path(t.name).stem().string();
          const std::string data = stem + ".csv";
          write_side_by_side(t, label_a, label_b, (fs::path(out_dir) / data).string());
          if (!options.plots)
            continue;
          const auto columns =
            select_plot_columns(t, options.plot_columns, options.max_plot_columns);
          if (columns.empty())
            {
              report.warnings.push_back(
                t.name + (t.columns.empty() ? ": no shared column; no plot"
                                            : ": every shared column is constant; no plot"));
              continue;
            }
          const std::string script = (fs::path(out_dir) / (stem + ".gp")).string();
          write_gnuplot_script(t, columns, label_a, label_b, data, stem + ".png", script);
          const std::string warning = run_gnuplot(script, stem + ".png");
          if (!warning.empty())
            report.warnings.push_back(warning);
        }
      write_summary_csv(report, (fs::path(out_dir) / "summary.csv").string());
      write_summary_markdown(report, (fs::path(out_dir) / "summary.md").string());
      return report;
    }
  } // namespace Compare
} // namespace hysteron
