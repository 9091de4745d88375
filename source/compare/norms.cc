#include <deal.II/base/numbers.h>

#include <hysteron/base/exceptions.h>

#include "compare/compare.h"
#include "compare/text.h"

#include <algorithm>
#include <cmath>

namespace hysteron
{
  namespace Compare
  {
    using internal::number;

    namespace
    {
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
    } // namespace



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
  } // namespace Compare
} // namespace hysteron
