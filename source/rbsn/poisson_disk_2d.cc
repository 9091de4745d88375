// The 2D Poisson-disk sampling: its background grid, Bridson's front and the darts into its gaps.
#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include "rbsn/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      using Point = dealii::Point<2>;
      using Sampling::uniform;

      /**
       * The background grid of the Poisson-disk sampling in 2D: square cells of side
       * d_min / sqrt(2) (each holds at most one random point; larger cells if that grid
       * would exceed 4e7 cells: still exact, only slower) over the box [lo, hi] of the
       * sampling and a margin around it, the points of each cell listed from head[cell]
       * through next[]. A trial p is refused by q if |p - q| < min(d(p), d(q)). With
       * |grad d| <= L, d(p) >= d(q) - L |p - q|, so every p with |p - q| < d(q) / (1 + L)
       * is refused: the cells inside that disk of q are covered.
       */
      class Grid2
      {
      public:
        Grid2(const Point &box_lo, const Point &box_hi, const double margin, const Spacing<2> &d)
          : d(d)
          , margin(margin)
          , shrink(1 / (1 + d.gradient))
        {
          const dealii::Tensor<1, 2> m({margin, margin});
          lo              = box_lo - m;
          hi              = box_hi + m;
          const double wx = hi[0] - lo[0], wy = hi[1] - lo[1];
          cell            = std::max(d.min / std::sqrt(2.0), std::sqrt(wx * wy / 4e7));
          nx              = std::max(1, static_cast<int>(std::ceil(wx / cell)));
          ny              = std::max(1, static_cast<int>(std::ceil(wy / cell)));
          head.assign(static_cast<std::size_t>(nx) * ny, -1);
          covered.assign(head.size(), false);
        }

        int
        column(const double x) const
        {
          return std::clamp(static_cast<int>(std::floor((x - lo[0]) / cell)), 0, nx - 1);
        }

        int
        row(const double y) const
        {
          return std::clamp(static_cast<int>(std::floor((y - lo[1]) / cell)), 0, ny - 1);
        }

        bool
        in_grid(const Point &p) const
        {
          return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
        }

        /// Add p with d(p) = @p dp and cover the cells of its disk of radius dp / (1 + L).
        void
        add(const Point &p, const double dp)
        {
          const int         i = column(p[0]), j = row(p[1]);
          const std::size_t c = static_cast<std::size_t>(j) * nx + i;
          next.push_back(head[c]);
          head[c] = static_cast<int>(points.size());
          points.push_back(p);
          radius.push_back(dp);
          const double R     = dp * shrink;
          const int    reach = static_cast<int>(std::ceil(R / cell));
          for (int b = std::max(0, j - reach); b <= std::min(ny - 1, j + reach); ++b)
            for (int a = std::max(0, i - reach); a <= std::min(nx - 1, i + reach); ++a)
              {
                // The corner of the cell farthest from p.
                const double x0 = lo[0] + a * cell, y0 = lo[1] + b * cell;
                const double fx = std::max(std::abs(x0 - p[0]), std::abs(x0 + cell - p[0]));
                const double fy = std::max(std::abs(y0 - p[1]), std::abs(y0 + cell - p[1]));
                if (fx * fx + fy * fy < R * R)
                  covered[static_cast<std::size_t>(b) * nx + a] = true;
              }
        }

        /**
         * Whether p (in the domain, @p inside) keeps its distance from every point, and
         * d(p) in @p dp. Fixed points beyond the grid (far) are checked one by one where
         * d(p) exceeds the margin, or with @p refuse_wide such a trial is refused (the
         * points beyond the margin are not known).
         */
        template <typename Inside>
        bool
        free(const Point &p, double &dp, const Inside &inside, const bool refuse_wide) const
        {
          if (!in_grid(p) || covered[static_cast<std::size_t>(row(p[1])) * nx + column(p[0])] || !inside(p))
            return false;
          dp              = d(p);
          const int i     = column(p[0]), j = row(p[1]);
          const int reach = static_cast<int>(std::ceil(dp / cell));
          for (int b = std::max(0, j - reach); b <= std::min(ny - 1, j + reach); ++b)
            for (int a = std::max(0, i - reach); a <= std::min(nx - 1, i + reach); ++a)
              for (int k = head[static_cast<std::size_t>(b) * nx + a]; k >= 0; k = next[k])
                if (points[k].distance(p) < std::min(dp, radius[k]))
                  return false;
          if (dp > margin)
            {
              if (refuse_wide)
                return false;
              for (const auto &q : far)
                if (q.distance(p) < dp) // d(q) is not needed: the stricter test
                  return false;
            }
          return true;
        }

        /// Whether every trial in the square [x0, x0 + size] x [y0, y0 + size] is refused
        /// because one point's disk of radius d(q) / (1 + L) holds its four corners.
        bool
        square_covered(const double x0, const double y0, const double size) const
        {
          const int square_reach = static_cast<int>(std::ceil(d.max * shrink / cell));
          const int i = column(x0 + 0.5 * size), j = row(y0 + 0.5 * size);
          for (int b = std::max(0, j - square_reach - 1); b <= std::min(ny - 1, j + square_reach + 1); ++b)
            for (int a = std::max(0, i - square_reach - 1); a <= std::min(nx - 1, i + square_reach + 1); ++a)
              for (int k = head[static_cast<std::size_t>(b) * nx + a]; k >= 0; k = next[k])
                {
                  const double fx = std::max(std::abs(x0 - points[k][0]), std::abs(x0 + size - points[k][0]));
                  const double fy = std::max(std::abs(y0 - points[k][1]), std::abs(y0 + size - points[k][1]));
                  const double R  = radius[k] * shrink;
                  if (fx * fx + fy * fy < R * R)
                    return true;
                }
          return false;
        }

        const Spacing<2>   &d;
        const double        margin, shrink;
        Point               lo, hi;
        double              cell = 0;
        int                 nx = 1, ny = 1;
        std::vector<int>    head, next;
        std::vector<bool>   covered; ///< every trial in the cell is refused (see add())
        std::vector<Point>  points;
        std::vector<double> radius; ///< d at each point
        std::vector<Point>  far;    ///< fixed points beyond the grid
      };



      /// The part of the box [lo, hi] in the block of @p clip; false if there is none.
      bool
      restrict_to_block(const Sampling::Clip<2> &clip, Point &lo, Point &hi)
      {
        const auto block = clip.box();
        for (unsigned int k = 0; k < 2; ++k)
          {
            lo[k] = std::max(lo[k], block.first[k]);
            hi[k] = std::min(hi[k], block.second[k]);
            if (lo[k] > hi[k])
              return false;
          }
        return true;
      }



      /**
       * The random points of the 2D Poisson-disk sampling (poisson_disk_points()), in
       * the domain's box, or with @p clip in the part of it in one block of a tiled
       * network (the trials outside the block refused, the darts thrown into it only).
       */
      std::vector<Point>
      sample_2d(const Geometry::Region<2> &domain,
                const Spacing<2>          &d,
                const std::vector<Point>  &fixed,
                const std::uint64_t        seed,
                const std::string         &where,
                const Sampling::Clip<2>   *clip)
      {
        require(d.min > 0 && d.max >= d.min, where, "the minimum distance must be > 0");
        const auto domain_box = domain.bounding_box().get_boundary_points();
        require(std::isfinite(domain_box.second[0] - domain_box.first[0]) &&
                  std::isfinite(domain_box.second[1] - domain_box.first[1]),
                where,
                "the domain is unbounded");
        // The box of the sampling: the domain's, or its part in the block. The grid
        // covers it and a margin of 2 d_max, at most the box's size (the points there
        // may exclude trials in the domain); a block's margin is the tiling's.
        Point box_lo = domain_box.first, box_hi = domain_box.second;
        if (clip && !restrict_to_block(*clip, box_lo, box_hi))
          return {};
        const double margin =
          clip ? clip->margin : std::min(2 * d.max, std::max(box_hi[0] - box_lo[0], box_hi[1] - box_lo[1]));
        Grid2 grid(box_lo, box_hi, margin, d);
        // Whether the square [x0, x0 + size]^2 meets the box (where darts go).
        const auto meets = [&](const double x0, const double y0, const double size) {
          return std::max(x0, box_lo[0]) <= std::min(x0 + size, box_hi[0]) &&
                 std::max(y0, box_lo[1]) <= std::min(y0 + size, box_hi[1]);
        };
        const auto inside = [&](const Point &p) { return (!clip || clip->contains(p)) && domain.contains(p); };

        // The fixed points: in the grid (and the front) if within the margin.
        std::vector<unsigned int> active;
        std::vector<Point>        result;
        for (const auto &p : fixed)
          if (grid.in_grid(p))
            {
              active.push_back(grid.points.size());
              grid.add(p, d(p));
            }
          else
            grid.far.push_back(p);

        // Bridson: grow from active points by trial points in the annulus [d, 2 d]
        // around them until the front dies out.
        std::mt19937_64 rng(seed);
        const auto      try_add = [&](const Point &p) {
          double dp;
          if (!grid.free(p, dp, inside, clip != nullptr))
            return false;
          active.push_back(grid.points.size());
          grid.add(p, dp);
          result.push_back(p);
          return true;
        };
        const auto annulus = [&](const Point &c, const double dc) {
          const double r = dc * (1 + uniform(rng)), phi = 2 * M_PI * uniform(rng);
          return Point(c[0] + r * std::cos(phi), c[1] + r * std::sin(phi));
        };
        const auto grow = [&]() { Sampling::grow_front(active, grid.points, grid.radius, rng, annulus, try_add); };
        grow();
        // Up to @p trials random points in a square (its part in the box); the first
        // one that is free is added and the front grows from it.
        const auto darts = [&](const double x0, const double y0, const double size, const unsigned int trials) {
          const double ax = std::max(x0, box_lo[0]), bx = std::min(x0 + size, box_hi[0]);
          const double ay = std::max(y0, box_lo[1]), by = std::min(y0 + size, box_hi[1]);
          if (ax > bx || ay > by)
            return;
          const auto draw = [&]() {
            const double u = uniform(rng), v = uniform(rng);
            return Point(ax + u * (bx - ax), ay + v * (by - ay));
          };
          Sampling::throw_darts(trials, draw, try_add, grow);
        };
        // The gaps the front left (other components, the first seed, corners): 30
        // trials in every grid cell that no exclusion disk covers, in a fixed order,
        // and the front again from each point found. Points only cover more, so one
        // pass visits each cell once.
        std::vector<std::array<double, 3>> squares; // x0, y0, size: the gaps left
        for (int j = 0; j < grid.ny; ++j)
          for (int i = 0; i < grid.nx; ++i)
            {
              const double x0 = grid.lo[0] + i * grid.cell, y0 = grid.lo[1] + j * grid.cell;
              if (grid.covered[static_cast<std::size_t>(j) * grid.nx + i] || (clip && !meets(x0, y0, grid.cell)))
                continue;
              darts(x0, y0, grid.cell, 30);
              if (!grid.covered[static_cast<std::size_t>(j) * grid.nx + i])
                squares.push_back({{x0, y0, grid.cell}});
            }
        // The remaining gaps are slivers between exclusion disks: quarter every square
        // that is not covered (nor outside the domain at its corners and centre) and
        // throw 10 darts into each quarter, for 2 levels, down to cells / 4 (as in
        // the maximal Poisson-disk sampling of Ebeida et al., 2012). Two levels give
        // the density of the former sweeps of 20 darts per cell (0.68 A / d^2 and the
        // boundary rows; doc/rbsn.md); more levels approach the jamming limit, 3 %
        // denser.
        for (unsigned int level = 0; level < 2 && !squares.empty(); ++level)
          {
            std::vector<std::array<double, 3>> quarters;
            for (const auto &q : squares)
              for (unsigned int c = 0; c < 4; ++c)
                {
                  const double h = 0.5 * q[2], x0 = q[0] + (c % 2) * h, y0 = q[1] + (c / 2) * h;
                  const bool   in = domain.contains(Point(x0 + 0.5 * h, y0 + 0.5 * h)) ||
                                  domain.contains(Point(x0, y0)) || domain.contains(Point(x0 + h, y0)) ||
                                  domain.contains(Point(x0, y0 + h)) || domain.contains(Point(x0 + h, y0 + h));
                  if (in && (!clip || meets(x0, y0, h)) && !grid.square_covered(x0, y0, h))
                    quarters.push_back({{x0, y0, h}});
                }
            squares.clear();
            for (const auto &q : quarters)
              if (!grid.square_covered(q[0], q[1], q[2]))
                {
                  darts(q[0], q[1], q[2], 10);
                  if (!grid.square_covered(q[0], q[1], q[2]))
                    squares.push_back(q);
                }
          }
        return result;
      }
    } // namespace



    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const Spacing<2>                    &d,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where)
    {
      std::vector<Point> result = sample_2d(domain, d, fixed, seed, where, nullptr);
      result.insert(result.begin(), fixed.begin(), fixed.end());
      return result;
    }



    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const double                         d_m,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where)
    {
      require(d_m > 0 && std::isfinite(d_m), where, "the minimum distance must be > 0");
      return poisson_disk_points(domain, Spacing<2>(d_m), fixed, seed, where);
    }



    namespace Sampling
    {
      struct BodySampler2::Data
      {
        const Geometry::Region<2> &body;
        const Spacing<2>          &d;
        std::string                where;
      };



      BodySampler2::BodySampler2(const Geometry::Region<2> &body,
                                 const Spacing<2>          &d,
                                 const std::vector<Point> & /*fixed: the 2D sampler has no forbidden disks*/,
                                 const double /*boundary_h: the region is sampled as it is*/,
                                 const std::string &where)
        : data(new Data{body, d, where})
      {}



      BodySampler2::~BodySampler2() = default;



      std::vector<Point>
      BodySampler2::operator()(const std::vector<Point> &known, const std::uint64_t seed, const Clip<2> &clip) const
      {
        return sample_2d(data->body, data->d, known, seed, data->where, &clip);
      }
    } // namespace Sampling
  } // namespace RBSN
} // namespace hysteron
