#ifndef hysteron_source_rbsn_poisson_grid_3d_h
#define hysteron_source_rbsn_poisson_grid_3d_h

#include "rbsn/tessellation.h"

#include "rbsn/polyhedron.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

/**
 * @file
 * The background grid of the 3D Poisson-disk samplers (the points in the volume,
 * poisson_disk_3d.cc, and on the boundary's faces, boundary_points_3d.cc).
 */
namespace hysteron
{
  namespace RBSN
  {
    namespace Sampling
    {
      using Polyhedral::Box;
      using Polyhedral::Point;
      using Polyhedral::Vector;

      /**
       * The background grid of the Poisson-disk sampling in 3D: cubes of side
       * d_min / sqrt(3) (each holds at most one random point) over the domain's box
       * and a margin, the points of each cube listed from head[cube] through next[].
       * A cube is covered when one exclusion ball (radius d(q) / (1 + L), which
       * refuses every trial in it) holds its 8 corners.
       */
      class Grid3
      {
      public:
        /// The grid over @p box and a margin of 2 d_max, at most the box's size, or
        /// of @p block_margin >= 0 (a block of a tiled network: see free()).
        Grid3(const Box &box, const Spacing<3> &d, const double block_margin = -1)
          : d(d)
          , refuse_wide(block_margin >= 0)
        {
          double size = 0;
          for (unsigned int k = 0; k < 3; ++k)
            size = std::max(size, box.hi[k] - box.lo[k]);
          margin = refuse_wide ? block_margin : std::min(2 * d.max, size);
          double volume = 1;
          for (unsigned int k = 0; k < 3; ++k)
            {
              lo[k] = box.lo[k] - margin;
              hi[k] = box.hi[k] + margin;
              volume *= hi[k] - lo[k];
            }
          cell = std::max(d.min / std::sqrt(3.0), std::cbrt(volume / 4e7));
          for (unsigned int k = 0; k < 3; ++k)
            n[k] = std::max(1, static_cast<int>(std::ceil((hi[k] - lo[k]) / cell)));
          head.assign(static_cast<std::size_t>(n[0]) * n[1] * n[2], -1);
          covered.assign(head.size(), false);
          shrink = 1 / (1 + d.gradient);
        }

        bool
        in_grid(const Point &p) const
        {
          for (unsigned int k = 0; k < 3; ++k)
            if (p[k] < lo[k] || p[k] > hi[k])
              return false;
          return true;
        }

        int
        at(const double x, const unsigned int k) const
        {
          return std::clamp(static_cast<int>(std::floor((x - lo[k]) / cell)), 0, n[k] - 1);
        }

        std::size_t
        index(const int i, const int j, const int k) const
        {
          return (static_cast<std::size_t>(k) * n[1] + j) * n[0] + i;
        }

        /// Mark the cubes that the ball (c, R) holds entirely.
        void
        cover(const Point &c, const double R)
        {
          const int reach = static_cast<int>(std::ceil(R / cell));
          const int i = at(c[0], 0), j = at(c[1], 1), k = at(c[2], 2);
          for (int z = std::max(0, k - reach); z <= std::min(n[2] - 1, k + reach); ++z)
            for (int y = std::max(0, j - reach); y <= std::min(n[1] - 1, j + reach); ++y)
              for (int x = std::max(0, i - reach); x <= std::min(n[0] - 1, i + reach); ++x)
                {
                  // The corner of the cube farthest from c.
                  const double x0 = lo[0] + x * cell, y0 = lo[1] + y * cell, z0 = lo[2] + z * cell;
                  const double fx = std::max(std::abs(x0 - c[0]), std::abs(x0 + cell - c[0]));
                  const double fy = std::max(std::abs(y0 - c[1]), std::abs(y0 + cell - c[1]));
                  const double fz = std::max(std::abs(z0 - c[2]), std::abs(z0 + cell - c[2]));
                  if (fx * fx + fy * fy + fz * fz < R * R)
                    covered[index(x, y, z)] = true;
                }
        }

        /// Add a point with d(p) = @p dp (a fixed point beyond the grid is kept aside).
        void
        add(const Point &p, const double dp)
        {
          if (!in_grid(p))
            {
              far.push_back(p);
              return;
            }
          const std::size_t c = index(at(p[0], 0), at(p[1], 1), at(p[2], 2));
          next.push_back(head[c]);
          head[c] = static_cast<int>(points.size());
          points.push_back(p);
          radius.push_back(dp);
          cover(p, dp * shrink);
        }

        /**
         * Forbidden balls: a trial in one is refused whatever its d (kept in a grid of
         * cells of their largest radius, each in the cell of its centre).
         */
        void
        forbid(const std::vector<std::pair<Point, double>> &balls)
        {
          if (balls.empty())
            return;
          ball_cell = 0;
          for (const auto &b : balls)
            ball_cell = std::max(ball_cell, b.second);
          for (unsigned int k = 0; k < 3; ++k)
            m[k] = std::max(1, static_cast<int>(std::ceil((hi[k] - lo[k]) / ball_cell)));
          ball_head.assign(static_cast<std::size_t>(m[0]) * m[1] * m[2], -1);
          for (const auto &b : balls)
            {
              const std::size_t c = ball_index(b.first, 0, 0, 0);
              ball_next.push_back(ball_head[c]);
              ball_head[c] = static_cast<int>(ball.size());
              ball.push_back(b);
              cover(b.first, b.second);
            }
        }

        /// Whether p keeps its distance from every point and lies outside the forbidden
        /// balls; d(p) in @p dp. @p inside (the domain) is asked only for an uncovered p.
        /// Where d(p) exceeds the margin, the points beyond the grid (far) are checked one
        /// by one, or in a block such a trial is refused (no point beyond it is known).
        template <class Inside>
        bool
        free(const Point &p, double &dp, const Inside &inside) const
        {
          if (!in_grid(p))
            return false;
          const int i = at(p[0], 0), j = at(p[1], 1), k = at(p[2], 2);
          if (covered[index(i, j, k)] || !inside(p))
            return false;
          dp              = d(p);
          const int reach = static_cast<int>(std::ceil(dp / cell));
          for (int z = std::max(0, k - reach); z <= std::min(n[2] - 1, k + reach); ++z)
            for (int y = std::max(0, j - reach); y <= std::min(n[1] - 1, j + reach); ++y)
              for (int x = std::max(0, i - reach); x <= std::min(n[0] - 1, i + reach); ++x)
                for (int q = head[index(x, y, z)]; q >= 0; q = next[q])
                  {
                    const double r = std::min(dp, radius[q]);
                    if (points[q].distance_square(p) < r * r)
                      return false;
                  }
          if (dp > margin)
            {
              if (refuse_wide)
                return false;
              for (const auto &q : far)
                if (q.distance(p) < dp) // d(q) is not needed: the stricter test
                  return false;
            }
          if (!ball_head.empty())
            for (int z = -1; z <= 1; ++z)
              for (int y = -1; y <= 1; ++y)
                for (int x = -1; x <= 1; ++x)
                  for (int b = ball_head[ball_index(p, x, y, z)]; b >= 0; b = ball_next[b])
                    if (ball[b].first.distance_square(p) < ball[b].second * ball[b].second)
                      return false;
          return true;
        }

        /// Whether one exclusion ball (or a forbidden one) holds all @p corners.
        bool
        covers(const Point *corners, const unsigned int count) const
        {
          Vector mid;
          for (unsigned int c = 0; c < count; ++c)
            mid += corners[c];
          mid /= static_cast<double>(count);
          // A ball that holds the corners holds their mean: |centre - mid| < R.
          const auto holds = [&](const Point &centre, const double R) {
            if (centre.distance_square(Point(mid)) >= R * R)
              return false;
            for (unsigned int c = 0; c < count; ++c)
              if (corners[c].distance_square(centre) >= R * R)
                return false;
            return true;
          };
          const int reach = static_cast<int>(std::ceil(d.max * shrink / cell));
          const int i = at(mid[0], 0), j = at(mid[1], 1), k = at(mid[2], 2);
          for (int z = std::max(0, k - reach); z <= std::min(n[2] - 1, k + reach); ++z)
            for (int y = std::max(0, j - reach); y <= std::min(n[1] - 1, j + reach); ++y)
              for (int x = std::max(0, i - reach); x <= std::min(n[0] - 1, i + reach); ++x)
                for (int q = head[index(x, y, z)]; q >= 0; q = next[q])
                  if (holds(points[q], radius[q] * shrink))
                    return true;
          if (!ball_head.empty())
            for (int z = -1; z <= 1; ++z)
              for (int y = -1; y <= 1; ++y)
                for (int x = -1; x <= 1; ++x)
                  for (int b = ball_head[ball_index(Point(mid), x, y, z)]; b >= 0; b = ball_next[b])
                    if (holds(ball[b].first, ball[b].second))
                      return true;
          return false;
        }

        /// The points in the cubes that meet @p box.
        void
        near(const Box &box, std::vector<unsigned int> &result) const
        {
          result.clear();
          for (int z = at(box.lo[2], 2); z <= at(box.hi[2], 2); ++z)
            for (int y = at(box.lo[1], 1); y <= at(box.hi[1], 1); ++y)
              for (int x = at(box.lo[0], 0); x <= at(box.hi[0], 0); ++x)
                for (int q = head[index(x, y, z)]; q >= 0; q = next[q])
                  result.push_back(q);
          std::sort(result.begin(), result.end());
        }

        const Spacing<3>   &d;
        const bool          refuse_wide;
        Point               lo, hi;
        double              margin = 0, cell = 0, shrink = 1;
        int                 n[3];
        std::vector<int>    head, next;
        std::vector<bool>   covered;
        std::vector<Point>  points;
        std::vector<double> radius;
        std::vector<Point>  far;

      private:
        double                               ball_cell = 0;
        int                                  m[3]      = {1, 1, 1};
        std::vector<int>                     ball_head, ball_next;
        std::vector<std::pair<Point, double>> ball;

        std::size_t
        ball_index(const Point &p, const int dx, const int dy, const int dz) const
        {
          const auto c = [&](const unsigned int k, const int shift) {
            return std::clamp(static_cast<int>(std::floor((p[k] - lo[k]) / ball_cell)) + shift, 0, m[k] - 1);
          };
          return (static_cast<std::size_t>(c(2, dz)) * m[1] + c(1, dy)) * m[0] + c(0, dx);
        }
      };
    } // namespace Sampling
  }   // namespace RBSN
} // namespace hysteron

#endif
