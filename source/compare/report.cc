#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>

#include "compare/compare.h"
#include "compare/text.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

namespace hysteron
{
  namespace Compare
  {
    using internal::check_labels;
    using internal::format;
    using internal::number;
    using internal::split;

    namespace
    {
      namespace fs = std::filesystem;

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



    void
    write_side_by_side(const TableComparison &comparison,
                       const std::string     &label_a,
                       const std::string     &label_b,
                       const std::string     &filename,
                       Output::RunRecord     *record)
    {
      check_labels(label_a, label_b);
      std::vector<std::string> header{"time"};
      for (const auto &c : comparison.columns)
        for (const auto &suffix : {label_a, label_b, std::string("diff")})
          header.push_back(c + "_" + suffix);

      Output::CsvWriter   csv(filename, header, record);
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
    write_summary_csv(const ComparisonReport &report, const std::string &filename, Output::RunRecord *record)
    {
      Output::AtomicFile file(filename, record);
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
    write_summary_markdown(const ComparisonReport &report, const std::string &filename, Output::RunRecord *record)
    {
      const std::string A = report.label_a, B = report.label_b;

      Output::AtomicFile file(filename, record);
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
      report.output_directory = out_dir;
      for (const auto &t : report.tables)
        if (!t.time.empty())
          {
            const std::string data = fs::path(t.name).stem().string() + ".csv";
            write_side_by_side(t, label_a, label_b, (fs::path(out_dir) / data).string(), options.record);
          }
      write_summary_csv(report, (fs::path(out_dir) / "summary.csv").string(), options.record);
      write_summary_markdown(report, (fs::path(out_dir) / "summary.md").string(), options.record);
      if (options.plots)
        write_plots(report, options);
      return report;
    }
  } // namespace Compare
} // namespace hysteron
