// The nuclei of a large network, sampled block by block.
//
// The bodies' box is tiled by blocks of side B (from the spacing and the predicted
// number of points, or `Sampling block size`; never from the number of ranks). A block
// of a body is sampled as the whole body was (Bridson's front and the darts of
// poisson_disk_points()), restricted to the block: its trials are refused outside it,
// its darts go into it, and it starts from the points known around it, within a margin
// M = 2 d_max: the fixed points (user and boundary points, on every rank) and the
// random points of the neighbouring blocks sampled before it. Its seed is a hash of the
// Random seed, the body and the block. The blocks are sampled in 2^dim phases, one per
// colour (the parities of the block's indices), so that two blocks sampled in the same
// phase are never neighbours: with B >= M their points are at least B >= 2 d_max apart,
// farther than any d, and the points of a block depend only on the fixed points and on
// the blocks of earlier phases. A block is therefore the same whichever rank samples it.
// A later block knows the earlier ones, so the distance rule holds across the seams, and
// every block is saturated given what it knows (later points only cover more): the
// union is a saturated Poisson-disk set. A trial whose d exceeds M is refused (the
// sampled d_max was too low: no point beyond M is known), which costs density there,
// never the distance rule.
//
// Each block is sampled by one rank: the blocks along the Hilbert curve of the tiling,
// cut into equal shares of the predicted points. After each phase a rank sends the new
// points of its blocks to the samplers of their neighbours. The cells are numbered block
// by block along the curve, each block's in the order of its points. The ranks' cells
// are consecutive shares of that order (part_sizes()); the last block of one rank and
// the first of the next are split between them by coordinate bisection, as the former
// bisection of all nuclei split a network of one block. Every rank holds the number of
// points of every block (a few numbers per block), the nuclei of the blocks it sampled
// and of the blocks within the halo of its cells, which it asks their samplers for.
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
      std::uint64_t
      hilbert_index(std::array<std::uint32_t, dim> x, const unsigned int bits)
      {
        // Undo the rotations and reflections of the curve's sub-cubes from the top bit
        // down, then Gray-encode: x then holds the index transposed, bit b of x[i] being
        // its bit dim b + dim - 1 - i.
        const std::uint32_t top = std::uint32_t(1) << (bits - 1);
        for (std::uint32_t q = top; q > 1; q >>= 1)
          {
            const std::uint32_t p = q - 1;
            for (unsigned int i = 0; i < dim; ++i)
              if (x[i] & q)
                x[0] ^= p; // invert
              else
                {
                  const std::uint32_t t = (x[0] ^ x[i]) & p; // exchange
                  x[0] ^= t;
                  x[i] ^= t;
                }
          }
        for (unsigned int i = 1; i < dim; ++i)
          x[i] ^= x[i - 1];
        std::uint32_t t = 0;
        for (std::uint32_t q = top; q > 1; q >>= 1)
          if (x[dim - 1] & q)
            t ^= q - 1;
        for (unsigned int i = 0; i < dim; ++i)
          x[i] ^= t;
        std::uint64_t key = 0;
        for (int b = bits - 1; b >= 0; --b)
          for (unsigned int i = 0; i < dim; ++i)
            key = (key << 1) | ((x[i] >> b) & 1);
        return key;
      }



      std::vector<std::uint64_t>
      part_sizes(const std::uint64_t n, const unsigned int n_parts)
      {
        std::vector<std::uint64_t> sizes(n_parts, 0);
        struct Range
        {
          std::uint64_t n;
          unsigned int  first, count;
        };
        std::vector<Range> todo{{n, 0, n_parts}};
        while (!todo.empty())
          {
            const Range r = todo.back();
            todo.pop_back();
            if (r.count == 1)
              {
                sizes[r.first] = r.n;
                continue;
              }
            const unsigned int  left = r.count / 2;
            const std::uint64_t m    = static_cast<std::uint64_t>(std::llround(double(r.n) * left / r.count));
            todo.push_back({m, r.first, left});
            todo.push_back({r.n - m, r.first + left, r.count - left});
          }
        return sizes;
      }



      template <int dim>
      std::vector<unsigned int>
      bisect(const std::vector<dealii::Point<dim>> &points, const std::vector<std::uint64_t> &sizes)
      {
        std::vector<unsigned int> result(points.size(), 0);
        std::vector<unsigned int> ids(points.size());
        std::iota(ids.begin(), ids.end(), 0u);
        struct Range
        {
          std::size_t  begin, end;
          unsigned int first, count;
        };
        std::vector<Range> todo{{0, ids.size(), 0, static_cast<unsigned int>(sizes.size())}};
        while (!todo.empty())
          {
            const Range r = todo.back();
            todo.pop_back();
            if (r.count == 1 || r.begin == r.end)
              {
                for (std::size_t k = r.begin; k < r.end; ++k)
                  result[ids[k]] = r.first;
                continue;
              }
            dealii::Point<dim> lo = points[ids[r.begin]], hi = lo;
            for (std::size_t k = r.begin; k < r.end; ++k)
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lo[d] = std::min(lo[d], points[ids[k]][d]);
                  hi[d] = std::max(hi[d], points[ids[k]][d]);
                }
            unsigned int axis = 0;
            for (unsigned int d = 1; d < dim; ++d)
              if (hi[d] - lo[d] > hi[axis] - lo[axis])
                axis = d;
            const unsigned int left   = r.count / 2;
            const std::size_t  middle = r.begin + std::accumulate(sizes.begin() + r.first,
                                                                 sizes.begin() + r.first + left,
                                                                 std::uint64_t(0));
            std::nth_element(ids.begin() + r.begin, ids.begin() + middle, ids.begin() + r.end,
                             [&](const unsigned int a, const unsigned int b) {
                               return points[a][axis] < points[b][axis] ||
                                      (points[a][axis] == points[b][axis] && a < b);
                             });
            todo.push_back({r.begin, middle, r.first, left});
            todo.push_back({middle, r.end, r.first + left, r.count - left});
          }
        return result;
      }



      template <int dim>
      Layout<dim>::Layout(const Point                                &lo,
                          const Point                                &hi,
                          const double                                size,
                          const std::vector<std::pair<Point, Point>> &body_boxes)
        : origin(lo)
        , side(size)
      {
        for (unsigned int d = 0; d < dim; ++d)
          {
            n[d] = size > 0 ? std::max(1, static_cast<int>(std::ceil((hi[d] - lo[d]) / size))) : 1;
            tiles *= n[d];
          }
        if (tiles == 1)
          {
            index.push_back(Index{});
            by_linear[0] = 0;
            return;
          }
        // The blocks that meet a body's box (closed boxes: a point on the box's face
        // belongs to a block that meets it).
        std::vector<std::pair<std::uint64_t, Index>> found;
        unsigned int bits = 1;
        while ((1 << bits) < *std::max_element(n.begin(), n.end()))
          ++bits;
        Sampling::Clip<dim> c;
        c.origin = origin;
        c.size   = side;
        c.n      = n;
        for (const auto &box : body_boxes)
          {
            Index a, b;
            for (unsigned int d = 0; d < dim; ++d)
              {
                a[d] = c.coordinate(box.first[d], d);
                b[d] = c.coordinate(box.second[d], d);
              }
            Index i = a;
            while (true)
              {
                std::array<std::uint32_t, dim> x;
                for (unsigned int d = 0; d < dim; ++d)
                  x[d] = i[d];
                found.emplace_back(hilbert_index<dim>(x, bits), i);
                unsigned int d = 0;
                for (; d < dim && ++i[d] > b[d]; ++d)
                  i[d] = a[d];
                if (d == dim)
                  break;
              }
          }
        std::sort(found.begin(), found.end());
        found.erase(std::unique(found.begin(), found.end()), found.end());
        for (const auto &f : found)
          {
            by_linear[linear_of(f.second)] = index.size();
            index.push_back(f.second);
          }
      }



      template <int dim>
      std::uint64_t
      Layout<dim>::linear_of(const Index &i) const
      {
        std::uint64_t k = 0;
        for (int d = dim - 1; d >= 0; --d)
          k = k * n[d] + i[d];
        return k;
      }



      template <int dim>
      int
      Layout<dim>::position(const Index &i) const
      {
        for (unsigned int d = 0; d < dim; ++d)
          if (i[d] < 0 || i[d] >= n[d])
            return -1;
        const auto found = by_linear.find(linear_of(i));
        return found == by_linear.end() ? -1 : static_cast<int>(found->second);
      }



      template <int dim>
      int
      Layout<dim>::position(const Point &p) const
      {
        if (tiles == 1)
          return 0;
        const Sampling::Clip<dim> c = clip(0, 0);
        Index                     i;
        for (unsigned int d = 0; d < dim; ++d)
          i[d] = c.coordinate(p[d], d);
        return position(i);
      }



      template <int dim>
      unsigned int
      Layout<dim>::colour(const unsigned int b) const
      {
        unsigned int c = 0;
        for (unsigned int d = 0; d < dim; ++d)
          c |= (index[b][d] & 1) << d;
        return c;
      }



      template <int dim>
      std::uint64_t
      Layout<dim>::linear(const unsigned int b) const
      {
        return linear_of(index[b]);
      }



      template <int dim>
      Sampling::Clip<dim>
      Layout<dim>::clip(const unsigned int b, const double margin) const
      {
        Sampling::Clip<dim> c;
        c.origin = origin;
        c.size   = side;
        c.n      = n;
        c.index  = index[b];
        c.margin = margin;
        return c;
      }



      template <int dim>
      std::vector<unsigned int>
      Layout<dim>::neighbours(const unsigned int b, const unsigned int ring) const
      {
        std::vector<unsigned int> result;
        const int                 r = static_cast<int>(ring);
        Index                     i;
        for (unsigned int d = 0; d < dim; ++d)
          i[d] = index[b][d] - r;
        while (true)
          {
            if (const int p = position(i); p >= 0)
              result.push_back(p);
            unsigned int d = 0;
            for (; d < dim && ++i[d] > index[b][d] + r; ++d)
              i[d] = index[b][d] - r;
            if (d == dim)
              break;
          }
        std::sort(result.begin(), result.end());
        return result;
      }



      template class Layout<2>;
      template class Layout<3>;
      template std::uint64_t hilbert_index<2>(std::array<std::uint32_t, 2>, unsigned int);
      template std::uint64_t hilbert_index<3>(std::array<std::uint32_t, 3>, unsigned int);
      template std::vector<unsigned int> bisect<2>(const std::vector<dealii::Point<2>> &, const std::vector<std::uint64_t> &);
      template std::vector<unsigned int> bisect<3>(const std::vector<dealii::Point<3>> &, const std::vector<std::uint64_t> &);
    } // namespace Blocks
  }   // namespace RBSN
} // namespace hysteron
