// The nuclei of a network by block (blocks.h): their sampling in colour phases, their
// split over the ranks, the halo a rank fetches for its cells and the numbering of the
// facets. See the top of blocks.cc for the sampling and why it is the same on any
// number of ranks.
#include <hysteron/base/exceptions.h>

#include "rbsn/blocks.h"
#include "rbsn/collective.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace hysteron
{
  namespace RBSN
  {
    namespace Blocks
    {
      template <int dim>
      Nuclei<dim>::Nuclei(const Layout<dim> &layout, const MPI_Comm comm)
        : layout(layout)
        , comm(comm)
        , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
        , rank(dealii::Utilities::MPI::this_mpi_process(comm))
        , points(layout.size())
        , held(layout.size(), false)
        , n_fixed(layout.size(), 0)
        , fixed_in(layout.size())
        , sampler(layout.size(), 0)
      {}



      template <int dim>
      void
      Nuclei<dim>::hold_all(std::vector<Point> all_points)
      {
        AssertThrow(layout.size() == 1, dealii::ExcInternalError());
        first     = {0, all_points.size()};
        points[0] = std::move(all_points);
        held[0]   = true;
        sampler[0] = rank;
      }



      template <int dim>
      std::vector<dealii::Point<dim>>
      Nuclei<dim>::all() const
      {
        std::vector<Point> result;
        result.reserve(size());
        for (unsigned int b = 0; b < layout.size(); ++b)
          {
            AssertThrow(held[b], dealii::ExcInternalError());
            result.insert(result.end(), points[b].begin(), points[b].end());
          }
        return result;
      }



      template <int dim>
      void
      Nuclei<dim>::sample(const Sources &sources)
      {
        const auto        &fixed    = *sources.fixed;
        const unsigned int n_blocks = layout.size();
        for (unsigned int k = 0; k < fixed.size(); ++k)
          {
            const int b = layout.position(fixed[k]);
            AssertThrow(b >= 0, dealii::ExcInternalError()); // in a body, so in a block that meets its box
            fixed_in[b].push_back(k);
          }
        // The samplers: the blocks along the curve in equal shares of the predicted
        // points (each block to the rank of its middle).
        std::vector<double> weight(n_blocks);
        for (unsigned int b = 0; b < n_blocks; ++b)
          {
            n_fixed[b] = fixed_in[b].size();
            weight[b]  = n_fixed[b] + sources.predicted[b];
          }
        double total = std::accumulate(weight.begin(), weight.end(), 0.0);
        if (!(total > 0))
          {
            std::fill(weight.begin(), weight.end(), 1.0);
            total = n_blocks;
          }
        double before = 0;
        for (unsigned int b = 0; b < n_blocks; ++b)
          {
            const double share = (before + 0.5 * weight[b]) / total * n_ranks;
            sampler[b]         = std::min(n_ranks - 1, static_cast<unsigned int>(share));
            before += weight[b];
            if (sampler[b] == rank)
              {
                held[b] = true;
                for (const unsigned int k : fixed_in[b])
                  points[b].push_back(fixed[k]);
              }
          }

        // The phases: this rank's blocks of one colour, each body in turn, then their
        // points to the samplers of their neighbours.
        for (unsigned int colour = 0; colour < (1u << dim); ++colour)
          {
            std::vector<std::pair<unsigned int, unsigned int>> to_send; // block, rank
            // An input error (d at a point) stops every rank before the exchange.
            Collective::collectively(comm, [&]() {
            for (unsigned int b = 0; b < n_blocks; ++b)
              if (sampler[b] == rank && layout.colour(b) == colour)
                {
                  const Sampling::Clip<dim> clip = layout.clip(b, sources.margin);
                  const auto                box  = clip.box();
                  for (unsigned int s = 0; s < sources.bodies.size(); ++s)
                    {
                      bool meets = true;
                      for (unsigned int d = 0; d < dim; ++d)
                        meets = meets && std::max(box.first[d], sources.body_boxes[s].first[d]) <=
                                           std::min(box.second[d], sources.body_boxes[s].second[d]);
                      if (!meets)
                        continue;
                      const std::uint64_t seed =
                        Sampling::mix(Sampling::mix(Sampling::mix(sources.seed) ^ s) ^ layout.linear(b));
                      const auto added = (*sources.bodies[s])(known_points(b, colour, sources), seed, clip);
                      points[b].insert(points[b].end(), added.begin(), added.end());
                    }
                  for (const unsigned int q : layout.neighbours(b, 1))
                    if (sampler[q] != rank)
                      to_send.emplace_back(b, sampler[q]);
                }
            });
            std::sort(to_send.begin(), to_send.end());
            to_send.erase(std::unique(to_send.begin(), to_send.end()), to_send.end());
            send_blocks(to_send);
          }

        // Every block's number of points, and the first cell of each.
        std::vector<std::uint64_t> count(n_blocks, 0);
        for (unsigned int b = 0; b < n_blocks; ++b)
          if (sampler[b] == rank)
            count[b] = points[b].size();
        if (n_ranks > 1)
          dealii::Utilities::MPI::sum(count, comm, count);
        first.assign(n_blocks + 1, 0);
        std::partial_sum(count.begin(), count.end(), first.begin() + 1);
      }



      template <int dim>
      std::vector<dealii::Point<dim>>
      Nuclei<dim>::known_points(const unsigned int b, const unsigned int colour, const Sources &sources) const
      {
        // The fixed points within the margin (in their order), the points of the
        // neighbouring blocks of earlier colours within it (the blocks ascending), and
        // this block's points of the bodies sampled so far.
        const auto   box    = layout.clip(b, 0).box();
        const double margin = sources.margin;
        const auto   within = [&](const Point &p) {
          for (unsigned int d = 0; d < dim; ++d)
            if (p[d] < box.first[d] - margin || p[d] > box.second[d] + margin)
              return false;
          return true;
        };
        const auto                around = layout.neighbours(b, 1);
        std::vector<unsigned int> ids;
        for (const unsigned int q : around)
          for (const unsigned int k : fixed_in[q])
            if (within((*sources.fixed)[k]))
              ids.push_back(k);
        std::sort(ids.begin(), ids.end());
        std::vector<Point> known;
        for (const unsigned int k : ids)
          known.push_back((*sources.fixed)[k]);
        for (const unsigned int q : around)
          if (q != b && layout.colour(q) < colour)
            {
              AssertThrow(held[q], dealii::ExcInternalError());
              for (std::size_t k = n_fixed[q]; k < points[q].size(); ++k)
                if (within(points[q][k]))
                  known.push_back(points[q][k]);
            }
        known.insert(known.end(), points[b].begin() + n_fixed[b], points[b].end());
        return known;
      }



      template <int dim>
      void
      Nuclei<dim>::send_blocks(const std::vector<std::pair<unsigned int, unsigned int>> &block_rank)
      {
        // A message: per block its position, its number of points and their coordinates.
        std::map<unsigned int, std::vector<double>> out;
        for (const auto &[b, r] : block_rank)
          {
            auto &message = out[r];
            message.push_back(b);
            message.push_back(points[b].size());
            for (const auto &p : points[b])
              for (unsigned int d = 0; d < dim; ++d)
                message.push_back(p[d]);
          }
        for (const auto &[from, message] : dealii::Utilities::MPI::some_to_some(comm, out))
          for (std::size_t k = 0; k < message.size();)
            {
              const unsigned int b = static_cast<unsigned int>(message[k]);
              const std::size_t  n = static_cast<std::size_t>(message[k + 1]);
              k += 2;
              points[b].resize(n);
              for (std::size_t i = 0; i < n; ++i, k += dim)
                for (unsigned int d = 0; d < dim; ++d)
                  points[b][i][d] = message[k + d];
              held[b] = true;
            }
      }



      template <int dim>
      void
      Nuclei<dim>::partition(const unsigned int n_parts)
      {
        const auto sizes = part_sizes(size(), n_parts);
        cuts.assign(n_parts + 1, 0);
        std::partial_sum(sizes.begin(), sizes.end(), cuts.begin() + 1);
        splits.clear();
      }



      template <int dim>
      std::pair<unsigned int, unsigned int>
      Nuclei<dim>::sharers(const unsigned int b) const
      {
        // The ranks whose share [cuts[r], cuts[r + 1]) holds the first and the last cell.
        const auto rank_of = [&](const std::uint64_t id) {
          return static_cast<unsigned int>(std::upper_bound(cuts.begin(), cuts.end(), id) - cuts.begin() - 1);
        };
        const unsigned int r0 = rank_of(first[b]);
        return {r0, first[b + 1] > first[b] ? rank_of(first[b + 1] - 1) : r0};
      }



      template <int dim>
      const typename Nuclei<dim>::Split &
      Nuclei<dim>::split(const unsigned int b)
      {
        if (const auto s = splits.find(b); s != splits.end())
          return s->second;
        AssertThrow(held[b], dealii::ExcInternalError());
        // Each rank's share of the block, split by coordinate bisection; the DoFs rank
        // by rank, each rank's cells in the order of their numbers.
        const auto                 r = sharers(b);
        std::vector<std::uint64_t> sizes, base;
        std::uint64_t              next = first[b];
        for (unsigned int q = r.first; q <= r.second; ++q)
          {
            const std::uint64_t n = std::min(cuts[q + 1], first[b + 1]) - std::max(cuts[q], first[b]);
            sizes.push_back(n);
            base.push_back(next);
            next += n;
          }
        Split      &s    = splits[b];
        const auto  part = bisect(points[b], sizes);
        s.rank.resize(part.size());
        s.dof.resize(part.size());
        for (unsigned int i = 0; i < part.size(); ++i)
          {
            s.rank[i] = r.first + part[i];
            s.dof[i]  = base[part[i]]++;
          }
        return s;
      }



      template <int dim>
      std::pair<unsigned int, std::uint64_t>
      Nuclei<dim>::owner(const std::uint64_t id)
      {
        const unsigned int b = std::upper_bound(first.begin(), first.end(), id) - first.begin() - 1;
        const auto         r = sharers(b);
        if (r.first == r.second)
          return {r.first, id};
        const Split &s = split(b);
        return {s.rank[id - first[b]], s.dof[id - first[b]]};
      }



      template <int dim>
      std::vector<unsigned int>
      Nuclei<dim>::own_blocks() const
      {
        std::vector<unsigned int> result;
        for (unsigned int b = 0; b < layout.size(); ++b)
          if (first[b + 1] > first[b] && first[b] < cuts[rank + 1] && first[b + 1] > cuts[rank])
            result.push_back(b);
        return result;
      }



      template <int dim>
      void
      Nuclei<dim>::fetch(const double distance)
      {
        if (layout.single())
          return; // every rank holds the one block
        // The blocks within the distance of this rank's blocks that it does not hold,
        // asked from their samplers, which send them.
        const unsigned int ring = static_cast<unsigned int>(std::ceil(distance / layout.side));
        std::map<unsigned int, std::vector<unsigned long>> requests;
        std::vector<bool>                                  asked(layout.size(), false);
        for (const unsigned int b : own_blocks())
          for (const unsigned int q : layout.neighbours(b, ring))
            if (!held[q] && !asked[q])
              {
                asked[q] = true;
                requests[sampler[q]].push_back(q);
              }
        std::vector<std::pair<unsigned int, unsigned int>> replies;
        for (const auto &[from, blocks] : dealii::Utilities::MPI::some_to_some(comm, requests))
          for (const unsigned long b : blocks)
            replies.emplace_back(b, from);
        send_blocks(replies);
      }



      template <int dim>
      void
      Nuclei<dim>::near_own(const double                 distance,
                            std::vector<std::uint64_t>  &ids,
                            std::vector<Point>          &result,
                            std::vector<bool>           &own)
      {
        // The nuclei within the distance of one of this rank's (a hash grid of cells of
        // that size over the held blocks around them), in the order of the cells.
        const auto mine = [&](const unsigned int b, const std::size_t i) {
          const auto r = sharers(b);
          return r.first == r.second ? r.first == rank : split(b).rank[i] == rank;
        };
        std::vector<unsigned int> blocks;
        {
          const unsigned int ring = layout.single() ? 0 : static_cast<unsigned int>(std::ceil(distance / layout.side));
          std::vector<bool>  near(layout.size(), false);
          for (const unsigned int b : own_blocks())
            for (const unsigned int q : layout.neighbours(b, ring))
              near[q] = true;
          for (unsigned int b = 0; b < layout.size(); ++b)
            if (near[b] && held[b])
              blocks.push_back(b);
        }
        using Key = std::array<long long, dim>;
        const auto key = [&](const Point &p) {
          Key k;
          for (unsigned int d = 0; d < dim; ++d)
            k[d] = static_cast<long long>(std::floor(p[d] / distance));
          return k;
        };
        std::map<Key, std::vector<std::pair<unsigned int, unsigned int>>> grid; // block, index
        for (const unsigned int b : blocks)
          for (unsigned int i = 0; i < points[b].size(); ++i)
            grid[key(points[b][i])].emplace_back(b, i);
        std::map<unsigned int, std::vector<bool>> flagged;
        for (const unsigned int b : blocks)
          flagged[b].assign(points[b].size(), false);
        for (const unsigned int b : blocks)
          for (unsigned int i = 0; i < points[b].size(); ++i)
            if (mine(b, i))
              {
                const Key k = key(points[b][i]);
                for (unsigned int m = 0; m < (dim == 2 ? 9u : 27u); ++m)
                  {
                    Key          q = k;
                    unsigned int r = m;
                    for (unsigned int d = 0; d < dim; ++d, r /= 3)
                      q[d] += static_cast<int>(r % 3) - 1;
                    if (const auto g = grid.find(q); g != grid.end())
                      for (const auto &[c, j] : g->second)
                        if (points[c][j].distance(points[b][i]) <= distance)
                          flagged[c][j] = true;
                  }
              }
        ids.clear();
        result.clear();
        own.clear();
        for (const unsigned int b : blocks)
          for (unsigned int i = 0; i < points[b].size(); ++i)
            if (flagged[b][i] || mine(b, i))
              {
                ids.push_back(first[b] + i);
                result.push_back(points[b][i]);
                own.push_back(mine(b, i));
              }
      }



      template <int dim>
      std::vector<std::uint64_t>
      Nuclei<dim>::first_facets(const std::vector<unsigned int> &n_up)
      {
        // This rank's cells block by block (as near_own() lists them), with their counts.
        const auto                                               blocks = own_blocks();
        std::vector<std::vector<std::pair<unsigned int, unsigned int>>> cells(blocks.size()); // index, count
        std::vector<std::uint64_t> totals(layout.size(), 0);
        std::size_t                k = 0;
        for (unsigned int j = 0; j < blocks.size(); ++j)
          {
            const unsigned int b = blocks[j];
            const auto         r = sharers(b);
            for (unsigned int i = 0; i < first[b + 1] - first[b]; ++i)
              if (r.first == r.second || split(b).rank[i] == rank)
                {
                  AssertThrow(k < n_up.size(), dealii::ExcInternalError());
                  cells[j].emplace_back(i, n_up[k]);
                  totals[b] += n_up[k++];
                }
          }
        AssertThrow(k == n_up.size(), dealii::ExcInternalError());
        // The facets of every block (their lower cells' ranks add them), so the first
        // facet of each block.
        if (n_ranks > 1)
          dealii::Utilities::MPI::sum(totals, comm, totals);
        std::vector<std::uint64_t> block_first(layout.size() + 1, 0);
        std::partial_sum(totals.begin(), totals.end(), block_first.begin() + 1);
        // A shared block: each of its ranks sends its cells' counts to the others.
        std::map<unsigned int, std::vector<unsigned long>> out;
        for (unsigned int j = 0; j < blocks.size(); ++j)
          if (const auto r = sharers(blocks[j]); r.first != r.second)
            for (unsigned int q = r.first; q <= r.second; ++q)
              if (q != rank)
                {
                  auto &message = out[q];
                  message.push_back(blocks[j]);
                  message.push_back(cells[j].size());
                  for (const auto &[i, n] : cells[j])
                    message.insert(message.end(), {i, n});
                }
        std::map<unsigned int, std::vector<std::uint64_t>> counts; // block: count of every cell
        for (unsigned int j = 0; j < blocks.size(); ++j)
          {
            auto &c = counts[blocks[j]];
            c.assign(first[blocks[j] + 1] - first[blocks[j]], 0);
            for (const auto &[i, n] : cells[j])
              c[i] = n;
          }
        for (const auto &[from, message] : dealii::Utilities::MPI::some_to_some(comm, out))
          for (std::size_t m = 0; m < message.size();)
            {
              auto             &c = counts.at(message[m]);
              const std::size_t n = message[m + 1];
              for (std::size_t i = 0; i < n; ++i)
                c[message[m + 2 + 2 * i]] = message[m + 3 + 2 * i];
              m += 2 + 2 * n;
            }
        // The first facet of a cell: its block's, and the facets of the block's lower cells.
        std::vector<std::uint64_t> result;
        for (unsigned int j = 0; j < blocks.size(); ++j)
          {
            const auto   &c    = counts.at(blocks[j]);
            std::uint64_t next = block_first[blocks[j]];
            unsigned int  i    = 0;
            for (const auto &[index, n] : cells[j])
              {
                for (; i < index; ++i)
                  next += c[i];
                result.push_back(next);
              }
          }
        return result;
      }



      template class Nuclei<2>;
      template class Nuclei<3>;
    } // namespace Blocks
  }   // namespace RBSN
} // namespace hysteron
