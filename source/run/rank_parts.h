#ifndef hysteron_source_run_rank_parts_h
#define hysteron_source_run_rank_parts_h

#include <hysteron/base/checkpoint.h>

#include <algorithm>
#include <tuple>
#include <vector>

namespace hysteron
{
  namespace Run
  {
    namespace internal
    {
      inline void
      set_zero(double &x)
      {
        x = 0;
      }

      inline void
      add(double &sum, const double x)
      {
        sum += x;
      }

      template <typename T>
      void
      set_zero(std::vector<T> &x)
      {
        for (auto &v : x)
          v = 0;
      }

      template <typename T>
      void
      add(std::vector<T> &sum, const std::vector<T> &x)
      {
        for (std::size_t i = 0; i < std::min(sum.size(), x.size()); ++i)
          sum[i] += x[i];
      }
    } // namespace internal

    /**
     * The rank parts of a checkpoint written on another number of ranks: every
     * part is loaded in turn with @p load_part (which fills @p sums, each a double
     * or a vector of values summed entry by entry), and rank 0 keeps the sum of all
     * the parts while the other ranks keep zero, so that the global sums (a
     * reduction over the ranks) are those of the checkpoint.
     */
    template <typename LoadPart, typename... Sums>
    void
    sum_rank_parts(std::vector<CheckpointReader> &parts, const bool root, const LoadPart &load_part, Sums &...sums)
    {
      std::tuple<Sums...> total{sums...};
      std::apply([](auto &...t) { (internal::set_zero(t), ...); }, total);
      for (auto &part : parts)
        {
          load_part(part);
          std::apply([&](auto &...t) { (internal::add(t, sums), ...); }, total);
        }
      std::tie(sums...) = total;
      if (!root)
        (internal::set_zero(sums), ...);
    }
  } // namespace Run
} // namespace hysteron

#endif
