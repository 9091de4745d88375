#include <hysteron/base/exceptions.h>
#include <hysteron/rbsn/tessellation.h>

#include "rbsn/polyhedron.h"
#include "rbsn/cgal.h"
#include "rbsn/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      using Polyhedral::Box;
      using Polyhedral::Point;
      using Polyhedral::Vector;
      using Point2 = std::array<double, 2>;
      using Sampling::text;
      using Sampling::uniform;

      /// Whether x lies on the convex polygon (within @p tolerance of its plane and edges).
      bool
      on_polygon(const Polyhedral::ConvexPolygon &P, const Point &x, const double tolerance)
      {
        const auto &v = P.vertices;
        if (std::abs(P.normal * (x - v[0])) > tolerance)
          return false;
        for (unsigned int k = 0; k < v.size(); ++k)
          {
            const Vector e = v[(k + 1) % v.size()] - v[k];
            const Vector out = cross_product_3d(e, P.normal);
            if ((x - v[k]) * out > tolerance * out.norm())
              return false;
          }
        return true;
      }

      /**
       * The background grid of the Poisson-disk sampling in 3D: cubes of side
       * d_min / sqrt(3) (each holds at most one random point) over the domain's box
       * and a margin, the points of each cube listed from head[cube] through next[].
       * A cube is covered when one exclusion ball (radius d(q) / (1 + L), which
       * refuses every trial in it) holds its 8 corners.
       */
      class Sampler
      {
      public:
        /// The grid over @p box and a margin of 2 d_max, at most the box's size, or
        /// of @p block_margin >= 0 (a block of a tiled network: see free()).
        Sampler(const Box &box, const Spacing<3> &d, const double block_margin = -1)
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



      /// The faces of the domain's boundary grouped by their plane (and side).
      struct FaceGroup
      {
        unsigned int              plane = 0;
        bool                      flipped = false;
        std::vector<unsigned int> polygons;
      };

      std::vector<FaceGroup>
      face_groups(const std::vector<Polyhedral::BoundaryPolygon> &polygons)
      {
        std::vector<FaceGroup>                        groups;
        std::map<std::pair<unsigned int, bool>, unsigned int> number;
        for (unsigned int k = 0; k < polygons.size(); ++k)
          {
            const auto key = std::make_pair(polygons[k].plane, polygons[k].flipped);
            auto       g   = number.find(key);
            if (g == number.end())
              {
                g = number.emplace(key, groups.size()).first;
                groups.push_back(FaceGroup{key.first, key.second, {}});
              }
            groups[g->second].polygons.push_back(k);
          }
        return groups;
      }



      /**
       * Forbidden balls that keep random nuclei from owning any of the boundary where
       * the fixed points cover it. A point p owns the boundary point x if it is closer
       * to x than every fixed point, |p - x| < rho(x) = min_q |x - q|. On a boundary
       * polygon F, the part R_q of F nearest to the fixed point q (F clipped by the
       * bisector planes of q and the other fixed points: a convex polygon) has
       * |p - x|^2 - |q - x|^2 affine in x, so p is closer than q to a point of R_q iff
       * it is to a vertex v of R_q. The union of the balls B(x, rho(x)) over the
       * boundary is therefore the union of the balls B(v, |v - q|) over the vertices of
       * these restricted Voronoi regions: the circumcentres of the fixed points in a
       * face, and where the regions meet the polygons' edges and corners. This holds
       * for any polyhedral boundary: the faces of a box, and the narrow sides of a prism
       * or the small triangles of a geodesic sphere, which hold too few fixed points of
       * their own for a Delaunay triangulation in their plane. Balls of radius below
       * 1.25 d(v) are returned (a saturated surface; sparse user points are left alone).
       */
      std::vector<std::pair<Point, double>>
      boundary_balls(const Polyhedral::Domain                       &domain,
                     const std::vector<Polyhedral::BoundaryPolygon> &polygons,
                     const std::vector<Point>                       &fixed,
                     const Spacing<3>                               &d)
      {
        std::vector<std::pair<Point, double>> balls;
        if (fixed.empty())
          return balls;
        // Only vertices within reach = 1.25 d_max of their q give balls, and a fixed
        // point q' cuts such a vertex off R_q only if |q' - q| < 2 reach.
        const double reach = 1.25 * d.max;
        using Key          = std::array<long long, 3>;
        const auto key     = [&](const Point &p) {
          return Key{{static_cast<long long>(std::floor(p[0] / reach)), static_cast<long long>(std::floor(p[1] / reach)),
                      static_cast<long long>(std::floor(p[2] / reach))}};
        };
        std::map<Key, std::vector<unsigned int>> grid;
        for (unsigned int i = 0; i < fixed.size(); ++i)
          grid[key(fixed[i])].push_back(i);
        const auto within = [&](const Point &lo, const Point &hi, std::vector<unsigned int> &result) {
          result.clear();
          const Key a = key(lo), b = key(hi);
          for (long long z = a[2]; z <= b[2]; ++z)
            for (long long y = a[1]; y <= b[1]; ++y)
              for (long long x = a[0]; x <= b[0]; ++x)
                if (const auto g = grid.find(Key{{x, y, z}}); g != grid.end())
                  result.insert(result.end(), g->second.begin(), g->second.end());
        };
        // The fixed points within 2 reach of each q, nearest first (computed when needed).
        std::vector<std::vector<unsigned int>> neighbours(fixed.size());
        std::vector<bool>                      listed(fixed.size(), false);
        std::vector<unsigned int>              found;
        const auto                             neighbours_of = [&](const unsigned int q) -> const std::vector<unsigned int> & {
          if (!listed[q])
            {
              const Vector r({2 * reach, 2 * reach, 2 * reach});
              within(fixed[q] - r, fixed[q] + r, found);
              auto &list = neighbours[q];
              for (const unsigned int k : found)
                if (k != q && fixed[k].distance(fixed[q]) < 2 * reach && fixed[k].distance(fixed[q]) > domain.tolerance)
                  list.push_back(k);
              std::sort(list.begin(), list.end(), [&](const unsigned int a, const unsigned int b) {
                const double da = fixed[a].distance_square(fixed[q]), db = fixed[b].distance_square(fixed[q]);
                return da < db || (da == db && a < b);
              });
              listed[q] = true;
            }
          return neighbours[q];
        };
        Polyhedral::Clipper       clipper(domain.tolerance);
        Polyhedral::ConvexPolygon region, clipped;
        std::vector<unsigned int> candidates;
        for (const auto &b : polygons)
          {
            // The fixed points within reach of the polygon's box.
            const Box    box = b.polygon.bounding_box();
            const Vector r({reach, reach, reach});
            within(box.lo - r, box.hi + r, candidates);
            std::sort(candidates.begin(), candidates.end());
            for (const unsigned int q : candidates)
              {
                double gap = 0; // the distance of q from the box
                for (unsigned int k = 0; k < 3; ++k)
                  gap += std::pow(std::max({box.lo[k] - fixed[q][k], fixed[q][k] - box.hi[k], 0.0}), 2);
                if (gap >= reach * reach)
                  continue;
                region      = b.polygon;
                bool  empty = false;
                const auto farthest = [&]() {
                  double rho = 0;
                  for (const auto &v : region.vertices)
                    rho = std::max(rho, v.distance(fixed[q]));
                  return rho;
                };
                double rho_max = farthest();
                for (const unsigned int k : neighbours_of(q))
                  {
                    const Vector e = fixed[k] - fixed[q];
                    const double h = e.norm();
                    if (h > 2 * rho_max)
                      break; // its bisector misses the region (and so do the farther ones')
                    const Polyhedral::Plane bisector{e / h, (e / h) * (0.5 * (fixed[q] + fixed[k]))};
                    const auto              cut = clipper.clip(region, bisector, 0, clipped);
                    if (cut == Polyhedral::Cut::outside)
                      {
                        empty = true;
                        break;
                      }
                    if (cut == Polyhedral::Cut::cut)
                      {
                        region.vertices.swap(clipped.vertices);
                        rho_max = farthest();
                      }
                  }
                if (empty)
                  continue;
                for (const auto &v : region.vertices)
                  {
                    const double rho = v.distance(fixed[q]);
                    if (rho > domain.tolerance && rho < 1.25 * d(v))
                      balls.emplace_back(v, rho);
                  }
              }
          }
        return balls;
      }



      /**
       * Points along a polyline between two corners at equal steps of the normalised
       * arc length tau(s) = int_0^s ds / d (s / d_m for a constant d): the interior
       * points j = 1 .. pieces - 1 of pieces = ceil(tau_total), and the first point too
       * if @p with_start.
       */
      void
      spread(const std::vector<Point> &path,
             const Spacing<3>         &spacing,
             const bool                with_start,
             std::vector<Point>       &points)
      {
        double length = 0;
        for (unsigned int k = 0; k + 1 < path.size(); ++k)
          length += path[k].distance(path[k + 1]);
        // tau tabulated at arc lengths s (midpoint rule, steps of at most d / 4).
        std::vector<double> s_table{0.0}, tau_table{0.0};
        if (spacing.is_constant())
          {
            s_table.push_back(length);
            tau_table.push_back(length / spacing.min);
          }
        else
          for (unsigned int k = 0; k + 1 < path.size(); ++k)
            {
              const double seg = path[k].distance(path[k + 1]);
              const Vector r   = path[k + 1] - path[k];
              const double s0  = s_table.back();
              for (double t = 0; t < seg;)
                {
                  const double step = std::min(seg - t, 0.25 * spacing(path[k] + (t / seg) * r));
                  const double tau  = step / spacing(path[k] + ((t + 0.5 * step) / seg) * r);
                  t                 = step < seg - t ? t + step : seg;
                  s_table.push_back(s0 + t);
                  tau_table.push_back(tau_table.back() + tau);
                }
            }
        const double       total  = tau_table.back();
        const unsigned int pieces = std::max(1u, static_cast<unsigned int>(std::ceil(total - 1e-9)));
        double             walked = 0;
        unsigned int       k = 0, m = 0;
        for (unsigned int j = with_start ? 0 : 1; j < pieces; ++j)
          {
            double target = j * length / pieces;
            if (!spacing.is_constant())
              {
                const double tau = j * total / pieces;
                while (m + 2 < tau_table.size() && tau_table[m + 1] < tau)
                  ++m;
                const double dt = tau_table[m + 1] - tau_table[m];
                target = s_table[m] + (dt > 0 ? (tau - tau_table[m]) / dt : 0.0) * (s_table[m + 1] - s_table[m]);
              }
            while (k + 2 < path.size() && walked + path[k].distance(path[k + 1]) < target)
              walked += path[k].distance(path[k + 1]), ++k;
            const double seg = path[k].distance(path[k + 1]);
            const double f   = seg > 0 ? (target - walked) / seg : 0.0;
            points.push_back(path[k] + f * (path[k + 1] - path[k]));
          }
      }



      /// A convex 2D polygon clipped to the square [x0, x0 + size] x [y0, y0 + size].
      std::vector<Point2>
      clip_to_square(std::vector<Point2> poly, const double x0, const double y0, const double size)
      {
        for (unsigned int side = 0; side < 4 && poly.size() >= 3; ++side)
          {
            // inside: sign * (x_axis - bound) <= 0
            const unsigned int axis  = side % 2;
            const double       sign  = side < 2 ? -1 : 1;
            const double       bound = side < 2 ? (axis == 0 ? x0 : y0) : (axis == 0 ? x0 + size : y0 + size);
            std::vector<Point2> out;
            for (unsigned int k = 0; k < poly.size(); ++k)
              {
                const Point2 &a = poly[k], &b = poly[(k + 1) % poly.size()];
                const double  fa = sign * (a[axis] - bound), fb = sign * (b[axis] - bound);
                if (fa <= 0)
                  out.push_back(a);
                if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0))
                  {
                    const Point2 &i = fa < 0 ? a : b, &o = fa < 0 ? b : a;
                    const double  fi = fa < 0 ? fa : fb, fo = fa < 0 ? fb : fa;
                    const double  t  = fi / (fi - fo);
                    out.push_back({{i[0] + t * (o[0] - i[0]), i[1] + t * (o[1] - i[1])}});
                  }
              }
            poly.swap(out);
          }
        if (poly.size() < 3)
          poly.clear();
        return poly;
      }
    } // namespace



    namespace
    {
      /**
       * The random points of the 3D Poisson-disk sampling (poisson_disk_points()) in
       * @p domain, the @p fixed points in the grid and the front, the @p balls
       * forbidden; with @p clip in the part of the domain in one block of a tiled
       * network (the trials outside the block refused, the darts thrown into it only).
       */
      std::vector<Point>
      sample_3d(const Polyhedral::Domain                    &domain,
                const Spacing<3>                            &d,
                const std::vector<Point>                    &fixed,
                const std::vector<std::pair<Point, double>> &balls,
                const std::uint64_t                          seed,
                const Sampling::Clip<3>                     *clip)
      {
        Box box = domain.box;
        if (clip)
          {
            const auto block = clip->box();
            for (unsigned int k = 0; k < 3; ++k)
              {
                box.lo[k] = std::max(box.lo[k], block.first[k]);
                box.hi[k] = std::min(box.hi[k], block.second[k]);
                if (box.lo[k] > box.hi[k])
                  return {};
              }
          }
        Sampler grid(box, d, clip ? clip->margin : -1);
        for (const auto &p : fixed)
          grid.add(p, d(p));
        // The fixed points on the boundary own it: no random point may come closer to
        // a piece of it than they are.
        grid.forbid(balls);
        const auto in_domain = [&](const Point &p) { return (!clip || clip->contains(p)) && domain.contains(p); };
        // Whether the cube [corner, corner + size] meets the box (where darts go).
        const auto meets = [&](const Point &corner, const double size) {
          for (unsigned int k = 0; k < 3; ++k)
            if (std::max(corner[k], box.lo[k]) > std::min(corner[k] + size, box.hi[k]))
              return false;
          return true;
        };

        // Bridson: grow from active points by trials in the shell [d, 2 d] around them
        // (uniform directions) until the front dies out.
        std::vector<unsigned int> active;
        for (unsigned int k = 0; k < grid.points.size(); ++k)
          active.push_back(k);
        std::vector<Point> result;
        std::mt19937_64    rng(seed);
        const auto         try_add = [&](const Point &p) {
          double dp;
          if (!grid.free(p, dp, in_domain))
            return false;
          active.push_back(grid.points.size());
          grid.add(p, dp);
          result.push_back(p);
          return true;
        };
        // Uniform directions: z = cos(theta) uniform in [-1, 1], phi in [0, 2 pi).
        const auto shell = [&](const Point &c, const double dc) {
          const double r = dc * (1 + uniform(rng)), z = 2 * uniform(rng) - 1, phi = 2 * M_PI * uniform(rng);
          const double s = std::sqrt(std::max(0.0, 1 - z * z));
          return Point(c[0] + r * s * std::cos(phi), c[1] + r * s * std::sin(phi), c[2] + r * z);
        };
        const auto grow = [&]() { Sampling::grow_front(active, grid.points, grid.radius, rng, shell, try_add); };
        grow();
        // Up to @p trials random points in a cube (its part in the box); the first that
        // is free is added and the front grows from it.
        const auto darts = [&](const Point &corner, const double size, const unsigned int trials) {
          Point a, b;
          for (unsigned int k = 0; k < 3; ++k)
            {
              a[k] = std::max(corner[k], box.lo[k]);
              b[k] = std::min(corner[k] + size, box.hi[k]);
              if (a[k] > b[k])
                return;
            }
          const auto draw = [&]() {
            const double u = uniform(rng), v = uniform(rng), w = uniform(rng);
            return Point(a[0] + u * (b[0] - a[0]), a[1] + v * (b[1] - a[1]), a[2] + w * (b[2] - a[2]));
          };
          Sampling::throw_darts(trials, draw, try_add, grow);
        };
        const auto cube_covered = [&](const Point &corner, const double size) {
          Point corners[8];
          for (unsigned int c = 0; c < 8; ++c)
            corners[c] = corner + Vector({(c & 1) * size, ((c >> 1) & 1) * size, ((c >> 2) & 1) * size});
          return grid.covers(corners, 8);
        };
        // The gaps the front left: 30 trials in every cube that no exclusion ball
        // covers, in a fixed order, and the front again from each point found.
        std::vector<std::pair<Point, double>> cubes; // corner, size: the gaps left
        for (int k = 0; k < grid.n[2]; ++k)
          for (int j = 0; j < grid.n[1]; ++j)
            for (int i = 0; i < grid.n[0]; ++i)
              if (!grid.covered[grid.index(i, j, k)])
                {
                  const Point corner = grid.lo + grid.cell * Vector({1.0 * i, 1.0 * j, 1.0 * k});
                  if (clip && !meets(corner, grid.cell))
                    continue;
                  darts(corner, grid.cell, 30);
                  if (!grid.covered[grid.index(i, j, k)])
                    cubes.emplace_back(corner, grid.cell);
                }
        // The slivers between exclusion balls: split every cube that is not covered (nor
        // outside the domain at its corners and centre) into 8 and throw 10 darts into
        // each, for 2 levels (as the 2D sampling does with quarters).
        for (unsigned int level = 0; level < 2 && !cubes.empty(); ++level)
          {
            std::vector<std::pair<Point, double>> octants;
            for (const auto &q : cubes)
              for (unsigned int c = 0; c < 8; ++c)
                {
                  const double h = 0.5 * q.second;
                  const Point  x0 = q.first + Vector({(c & 1) * h, ((c >> 1) & 1) * h, ((c >> 2) & 1) * h});
                  bool         inside = domain.contains(x0 + Vector({0.5 * h, 0.5 * h, 0.5 * h}));
                  for (unsigned int e = 0; e < 8 && !inside; ++e)
                    inside = domain.contains(x0 + Vector({(e & 1) * h, ((e >> 1) & 1) * h, ((e >> 2) & 1) * h}));
                  if (inside && (!clip || meets(x0, h)) && !cube_covered(x0, h))
                    octants.emplace_back(x0, h);
                }
            cubes.clear();
            for (const auto &q : octants)
              if (!cube_covered(q.first, q.second))
                {
                  darts(q.first, q.second, 10);
                  if (!cube_covered(q.first, q.second))
                    cubes.push_back(q);
                }
          }
        return result;
      }
    } // namespace



    std::vector<dealii::Point<3>>
    poisson_disk_points(const Geometry::Region<3>           &region,
                        const Spacing<3>                    &d,
                        const std::vector<dealii::Point<3>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where,
                        const double                         boundary_h)
    {
      require(d.min > 0 && d.max >= d.min && std::isfinite(d.max), where, "the minimum distance must be > 0");
      const Polyhedral::Domain domain({&region}, boundary_h > 0 ? boundary_h : 0.25 * d.min, where);
      const auto boundary = domain.boundary();
      {
        // The saturated set's size: density V / d^3 for a constant d (V of the
        // polyhedral domain), else the sampled prediction.
        const double volume    = Polyhedral::Domain::volume(boundary);
        const double predicted = d.is_constant() ? Spacing<3>::density * volume / (d.min * d.min * d.min) :
                                                   d.predicted_points;
        std::ostringstream s;
        s << "about " << static_cast<long>(predicted) << " points predicted at this minimum distance ("
          << Spacing<3>::density << " int 1/d^3 dV over the body; at most 5e6)";
        require(predicted <= 5e6, where, s.str());
      }
      std::vector<Point> result = sample_3d(domain, d, fixed, boundary_balls(domain, boundary, fixed, d), seed, nullptr);
      result.insert(result.begin(), fixed.begin(), fixed.end());
      return result;
    }



    namespace Sampling
    {
      struct BodySampler3::Data
      {
        const Spacing<3>                      &d;
        Polyhedral::Domain                     domain;
        std::vector<std::pair<Point, double>> balls; ///< of the network's fixed points
      };



      BodySampler3::BodySampler3(const Geometry::Region<3> &body,
                                 const Spacing<3>          &d,
                                 const std::vector<Point>  &fixed,
                                 const double               boundary_h,
                                 const std::string         &where)
        : data(new Data{d, Polyhedral::Domain({&body}, boundary_h > 0 ? boundary_h : 0.25 * d.min, where), {}})
      {
        data->balls = boundary_balls(data->domain, data->domain.boundary(), fixed, d);
      }



      BodySampler3::~BodySampler3() = default;



      std::vector<Point>
      BodySampler3::operator()(const std::vector<Point> &known, const std::uint64_t seed, const Clip<3> &clip) const
      {
        // The forbidden balls that reach the block's grid (the block and its margin).
        const auto             block = clip.box();
        std::vector<std::pair<Point, double>> near;
        for (const auto &b : data->balls)
          {
            bool meets = true;
            for (unsigned int k = 0; k < 3 && meets; ++k)
              meets = b.first[k] >= block.first[k] - clip.margin - b.second &&
                      b.first[k] <= block.second[k] + clip.margin + b.second;
            if (meets)
              near.push_back(b);
          }
        return sample_3d(data->domain, data->d, known, near, seed, &clip);
      }
    } // namespace Sampling



    std::vector<dealii::Point<3>>
    boundary_points(const Geometry::Region<3> &region,
                    const Spacing<3>          &spacing,
                    const double               boundary_h,
                    const std::uint64_t        seed)
    {
      const std::string where = "the shape '" + region.expression() + "'";
      require(spacing.min > 0 && spacing.max >= spacing.min, where, "the minimum distance must be > 0");
      const Polyhedral::Domain domain({&region}, boundary_h, where);
      const auto               polygons = domain.boundary();
      const double             match    = 1e-9 * domain.scale;
      const double             sharp    = std::cos(20.0 * M_PI / 180.0);
      std::vector<Point>       points;

      // 1. The sharp edges: the edges of the boundary polygons (split where another
      // polygon's vertex lies on them) along which the surface turns by more than 20
      // degrees, found by the polygons that hold an edge's midpoint.
      Polyhedral::BoxTree polygon_tree, vertex_tree;
      std::vector<Point>  vertices;
      {
        std::vector<Box> boxes, vertex_boxes;
        for (const auto &b : polygons)
          {
            boxes.push_back(b.polygon.bounding_box());
            for (const auto &v : b.polygon.vertices)
              {
                vertices.push_back(v);
                vertex_boxes.emplace_back();
                vertex_boxes.back().add(v);
              }
          }
        polygon_tree.build(boxes);
        vertex_tree.build(vertex_boxes);
      }
      std::vector<std::array<Point, 2>> segments;
      std::vector<unsigned int>         found;
      for (unsigned int i = 0; i < polygons.size(); ++i)
        {
          const auto &v = polygons[i].polygon.vertices;
          for (unsigned int e = 0; e < v.size(); ++e)
            {
              const Point &a = v[e], &b = v[(e + 1) % v.size()];
              const Vector r = b - a;
              if (r.norm() <= match)
                continue;
              Box box;
              box.add(a);
              box.add(b);
              found.clear();
              vertex_tree.query(box, match, found);
              std::vector<double> cuts{0.0, 1.0};
              for (const unsigned int k : found)
                {
                  const double t = (vertices[k] - a) * r / r.norm_square();
                  if (t > 0 && t < 1 && (a + t * r).distance(vertices[k]) < match)
                    cuts.push_back(t);
                }
              std::sort(cuts.begin(), cuts.end());
              for (unsigned int c = 0; c + 1 < cuts.size(); ++c)
                {
                  if ((cuts[c + 1] - cuts[c]) * r.norm() <= match)
                    continue;
                  const Point m = a + (0.5 * (cuts[c] + cuts[c + 1])) * r;
                  Box         mb;
                  mb.add(m);
                  std::vector<unsigned int> around;
                  polygon_tree.query(mb, match, around);
                  bool neighbour = false, turn = false;
                  for (const unsigned int k : around)
                    if (k != i && on_polygon(polygons[k].polygon, m, match))
                      {
                        neighbour = true;
                        turn      = turn || polygons[k].polygon.normal * polygons[i].polygon.normal < sharp;
                      }
                  if (!neighbour || turn)
                    segments.push_back({{a + cuts[c] * r, a + cuts[c + 1] * r}});
                }
            }
        }

      // 2. The graph of the sharp edges: end points merged within `match` into nodes,
      // every edge once.
      std::vector<Point>                                   node;
      std::map<std::array<long long, 3>, std::vector<unsigned int>> bucket;
      const double                                         bucket_size = 10 * match;
      const auto                                           node_of     = [&](const Point &p) {
        std::array<long long, 3> key;
        for (unsigned int k = 0; k < 3; ++k)
          key[k] = static_cast<long long>(std::floor(p[k] / bucket_size));
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              {
                const auto b = bucket.find({{key[0] + dx, key[1] + dy, key[2] + dz}});
                if (b != bucket.end())
                  for (const unsigned int q : b->second)
                    if (node[q].distance(p) < match)
                      return q;
              }
        bucket[key].push_back(node.size());
        node.push_back(p);
        return static_cast<unsigned int>(node.size() - 1);
      };
      std::vector<std::pair<unsigned int, unsigned int>> edges;
      for (const auto &s : segments)
        {
          const unsigned int a = node_of(s[0]), b = node_of(s[1]);
          if (a != b)
            edges.emplace_back(std::min(a, b), std::max(a, b));
        }
      std::sort(edges.begin(), edges.end());
      edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
      std::vector<std::vector<unsigned int>> incident(node.size());
      for (unsigned int e = 0; e < edges.size(); ++e)
        {
          incident[edges[e].first].push_back(e);
          incident[edges[e].second].push_back(e);
        }
      const auto other = [&](const unsigned int e, const unsigned int v) {
        return edges[e].first == v ? edges[e].second : edges[e].first;
      };
      // Corners: where the number of sharp edges is not 2, or the two turn by more
      // than 20 degrees.
      std::vector<bool> corner(node.size(), false);
      for (unsigned int v = 0; v < node.size(); ++v)
        if (incident[v].size() != 2)
          corner[v] = !incident[v].empty();
        else
          {
            const Vector a = node[v] - node[other(incident[v][0], v)], b = node[other(incident[v][1], v)] - node[v];
            corner[v] = std::atan2(cross_product_3d(a, b).norm(), a * b) > 20.0 * M_PI / 180.0;
          }
      for (unsigned int v = 0; v < node.size(); ++v)
        if (corner[v])
          points.push_back(node[v]);
      // 3. Points along the runs of sharp edges from corner to corner (and around the
      // closed runs without a corner, from their first node).
      std::vector<bool> visited(edges.size(), false);
      const auto        walk = [&](const unsigned int start, unsigned int e) {
        std::vector<Point> path{node[start]};
        unsigned int       v = start;
        while (true)
          {
            visited[e] = true;
            v          = other(e, v);
            path.push_back(node[v]);
            if (corner[v] || v == start)
              break;
            const unsigned int f = incident[v][0] == e ? incident[v][1] : incident[v][0];
            if (visited[f])
              break;
            e = f;
          }
        return path;
      };
      for (unsigned int v = 0; v < node.size(); ++v)
        if (corner[v])
          for (const unsigned int e : incident[v])
            if (!visited[e])
              spread(walk(v, e), spacing, false, points);
      for (unsigned int e = 0; e < edges.size(); ++e)
        if (!visited[e])
          spread(walk(edges[e].first, e), spacing, true, points);

      // 4. Poisson-disk points on every planar face (the polygons of one plane),
      // keeping the distance rule from all points so far: Bridson's front in the
      // plane from the points on the face, then darts into the squares of a grid in
      // the plane that no exclusion ball covers (their part on the face), then into
      // their quarters, for 2 levels.
      Sampler grid(domain.box, spacing);
      for (const auto &p : points)
        grid.add(p, spacing(p));
      std::mt19937_64 rng(seed);
      for (const auto &group : face_groups(polygons))
        {
          const auto  &first = polygons[group.polygons[0]].polygon;
          const Vector n = first.normal, e1 = Polyhedral::perpendicular(n), e2 = cross_product_3d(n, e1);
          const Point  o = first.vertices[0];
          const auto   to_plane = [&](const Point &x) { return Point2{{(x - o) * e1, (x - o) * e2}}; };
          const auto   to_space = [&](const Point2 &q) { return o + q[0] * e1 + q[1] * e2; };
          std::vector<std::vector<Point2>> faces;
          Box                              box3;
          Point2                           lo{{1e300, 1e300}}, hi{{-1e300, -1e300}};
          for (const unsigned int k : group.polygons)
            {
              faces.emplace_back();
              for (const auto &v : polygons[k].polygon.vertices)
                {
                  faces.back().push_back(to_plane(v));
                  box3.add(v);
                  for (unsigned int a = 0; a < 2; ++a)
                    {
                      lo[a] = std::min(lo[a], faces.back().back()[a]);
                      hi[a] = std::max(hi[a], faces.back().back()[a]);
                    }
                }
            }
          const auto on_face = [&](const Point2 &q, const double tolerance) {
            for (const auto &f : faces)
              {
                bool in = true;
                for (unsigned int k = 0; k < f.size() && in; ++k)
                  {
                    const Point2 &a = f[k], &b = f[(k + 1) % f.size()];
                    const double  ex = b[0] - a[0], ey = b[1] - a[1];
                    in = ex * (q[1] - a[1]) - ey * (q[0] - a[0]) >= -tolerance * std::sqrt(ex * ex + ey * ey);
                  }
                if (in)
                  return true;
              }
            return false;
          };
          // The front starts from the points already on the face (its edges' points).
          std::vector<unsigned int> active;
          grid.near(box3, found);
          for (const unsigned int k : found)
            if (std::abs(n * (grid.points[k] - o)) <= match && on_face(to_plane(grid.points[k]), match))
              active.push_back(k);
          const auto anywhere = [](const Point &) { return true; };
          // A point q of the plane, if free (the darts are drawn on the face).
          const auto try_add = [&](const Point2 &q) {
            double      dp;
            const Point p = to_space(q);
            if (!grid.free(p, dp, anywhere))
              return false;
            active.push_back(grid.points.size());
            grid.add(p, dp);
            points.push_back(p);
            return true;
          };
          // The front's trials are drawn in the annulus about c in the plane, and
          // must lie on the face.
          const auto annulus = [&](const Point &c3, const double dc) {
            const Point2 c = to_plane(c3);
            const double r = dc * (1 + uniform(rng)), phi = 2 * M_PI * uniform(rng);
            return Point2{{c[0] + r * std::cos(phi), c[1] + r * std::sin(phi)}};
          };
          const auto try_add_on_face = [&](const Point2 &q) { return on_face(q, 0) && try_add(q); };
          const auto grow            = [&]() {
            Sampling::grow_front(active, grid.points, grid.radius, rng, annulus, try_add_on_face);
          };
          grow();
          // Darts uniformly over the part of the face in a square (its fan triangles).
          const auto darts = [&](const double x0, const double y0, const double size, const unsigned int trials) {
            std::vector<std::array<Point2, 3>> triangles;
            std::vector<double>                cumulative;
            double                             total = 0;
            for (const auto &f : faces)
              {
                const auto part = clip_to_square(f, x0, y0, size);
                for (unsigned int k = 1; k + 1 < part.size(); ++k)
                  {
                    const double area = 0.5 * ((part[k][0] - part[0][0]) * (part[k + 1][1] - part[0][1]) -
                                               (part[k][1] - part[0][1]) * (part[k + 1][0] - part[0][0]));
                    if (area <= 0)
                      continue;
                    triangles.push_back({{part[0], part[k], part[k + 1]}});
                    total += area;
                    cumulative.push_back(total);
                  }
              }
            if (triangles.empty())
              return false;
            // A triangle by area, then a uniform point in it (folded barycentrics).
            const auto draw = [&]() {
              const double pick = uniform(rng) * total;
              const auto   t    = std::min<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                                       cumulative.begin(),
                                                     triangles.size() - 1);
              double u = uniform(rng), v = uniform(rng);
              if (u + v > 1)
                {
                  u = 1 - u;
                  v = 1 - v;
                }
              const auto &T = triangles[t];
              return Point2{{T[0][0] + u * (T[1][0] - T[0][0]) + v * (T[2][0] - T[0][0]),
                             T[0][1] + u * (T[1][1] - T[0][1]) + v * (T[2][1] - T[0][1])}};
            };
            Sampling::throw_darts(trials, draw, try_add, grow);
            return true;
          };
          const auto square_covered = [&](const double x0, const double y0, const double size) {
            const Point corners[4] = {to_space({{x0, y0}}),
                                      to_space({{x0 + size, y0}}),
                                      to_space({{x0, y0 + size}}),
                                      to_space({{x0 + size, y0 + size}})};
            return grid.covers(corners, 4);
          };
          const double cell = spacing.min / std::sqrt(2.0);
          const int    nx   = std::max(1, static_cast<int>(std::ceil((hi[0] - lo[0]) / cell)));
          const int    ny   = std::max(1, static_cast<int>(std::ceil((hi[1] - lo[1]) / cell)));
          std::vector<std::array<double, 3>> squares;
          for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
              {
                const double x0 = lo[0] + i * cell, y0 = lo[1] + j * cell;
                if (!square_covered(x0, y0, cell) && darts(x0, y0, cell, 30) && !square_covered(x0, y0, cell))
                  squares.push_back({{x0, y0, cell}});
              }
          for (unsigned int level = 0; level < 2 && !squares.empty(); ++level)
            {
              std::vector<std::array<double, 3>> quarters;
              for (const auto &q : squares)
                for (unsigned int c = 0; c < 4; ++c)
                  {
                    const double h = 0.5 * q[2];
                    quarters.push_back({{q[0] + (c % 2) * h, q[1] + (c / 2) * h, h}});
                  }
              squares.clear();
              for (const auto &q : quarters)
                if (!square_covered(q[0], q[1], q[2]) && darts(q[0], q[1], q[2], 10) &&
                    !square_covered(q[0], q[1], q[2]))
                  squares.push_back(q);
            }
        }
      return points;
    }



    Tessellation<3>
    voronoi(const std::vector<dealii::Point<3>>            &nuclei,
            const std::vector<const Geometry::Region<3> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted)
    {
      using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
      using Vb     = CGAL::Triangulation_vertex_base_with_info_3<unsigned int, Kernel>;
      using Tds    = CGAL::Triangulation_data_structure_3<Vb>;
      using DT     = CGAL::Delaunay_triangulation_3<Kernel, Tds>;
      using namespace Polyhedral;

      const unsigned int n = nuclei.size();
      require(n >= 2, where, "a network needs at least two cells");
      require(wanted.empty() || wanted.size() == n, where, "one flag per nucleus is needed");
      const Domain domain(bodies, boundary_h, where);
      const double scale = domain.scale;
      for (const auto &p : nuclei)
        require(domain.contains(p, 1e-9 * scale), where, "the point " + text(p) + " lies outside the bodies");

      // The Delaunay triangulation gives every cell's Voronoi neighbours: its edges
      // (in any dimension: for coplanar or collinear nuclei CGAL keeps a 2D or 1D
      // triangulation, whose edges are the neighbours in the plane or along the line).
      std::vector<std::vector<unsigned int>> neighbours(n);
      {
        DT dt;
        std::vector<std::pair<Kernel::Point_3, unsigned int>> input;
        input.reserve(n);
        for (unsigned int i = 0; i < n; ++i)
          input.emplace_back(Kernel::Point_3(nuclei[i][0], nuclei[i][1], nuclei[i][2]), i);
        dt.insert(input.begin(), input.end());
        if (dt.number_of_vertices() != n)
          {
            std::vector<unsigned int> order(n);
            std::iota(order.begin(), order.end(), 0u);
            const auto less = [&](const unsigned int a, const unsigned int b) {
              return std::lexicographical_compare(nuclei[a].begin_raw(),
                                                  nuclei[a].end_raw(),
                                                  nuclei[b].begin_raw(),
                                                  nuclei[b].end_raw());
            };
            std::sort(order.begin(), order.end(), less);
            for (unsigned int k = 0; k + 1 < n; ++k)
              require(nuclei[order[k]] != nuclei[order[k + 1]],
                      where,
                      "two points coincide at " + text(nuclei[order[k]]));
          }
        for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e)
          {
            const unsigned int a = e->first->vertex(e->second)->info(), b = e->first->vertex(e->third)->info();
            neighbours[a].push_back(b);
            neighbours[b].push_back(a);
          }
        for (auto &list : neighbours)
          std::sort(list.begin(), list.end());
      }

      Tessellation<3> result;
      result.cells.resize(n);
      Clipper                       clipper(domain.tolerance);
      ConvexPolyhedron              start, X, next;
      std::vector<ConvexPolyhedron> pieces;
      std::vector<ConvexPolygon>    parts;
      const Vector                  margin({0.5 * scale, 0.5 * scale, 0.5 * scale});
      start.make_box(domain.box.lo - margin, domain.box.hi + margin, box_tag);
      std::vector<std::pair<double, unsigned int>>     order;
      std::vector<std::array<unsigned int, 3>>         facet_faces; // neighbour, piece, face
      std::vector<Point>                               loop;
      for (unsigned int i = 0; i < n; ++i)
        {
          if (!wanted.empty() && !wanted[i])
            continue;
          const Point &x = nuclei[i];
          // The Voronoi cell: the box clipped by the bisector of every neighbour, the
          // nearest first (the cell shrinks fastest).
          order.clear();
          for (const unsigned int j : neighbours[i])
            order.emplace_back(x.distance_square(nuclei[j]), j);
          std::sort(order.begin(), order.end());
          X = start;
          for (const auto &o : order)
            {
              const unsigned int j = o.second;
              const Vector       d = nuclei[j] - x;
              const Plane        bisector{d / d.norm(), (d / d.norm()) * Point(0.5 * (x + nuclei[j]))};
              const Cut cut = clipper.clip(X, bisector, static_cast<int>(j), next);
              if (cut == Cut::cut)
                std::swap(X, next);
              else if (cut == Cut::outside) // nuclei closer than the tolerance: no cell
                {
                  X.clear();
                  break;
                }
            }
          // Its pieces in the domain.
          pieces.clear();
          if (!X.empty())
            domain.intersect(X, pieces, clipper);

          Cell<3> &cell = result.cells[i];
          cell.nucleus  = x;
          Moments moments;
          for (const auto &piece : pieces)
            moments.add_volume(piece, x);
          require(moments.measure > 1e-15 * scale * scale * scale,
                  where,
                  "the cell of the point " + text(x) + " has no volume in the bodies");
          cell.volume   = moments.measure;
          cell.centroid = x + moments.first / moments.measure;
          cell.second_moment = moments.second;
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = a; b < 3; ++b)
              cell.second_moment[a][b] -= moments.first[a] * moments.first[b] / moments.measure;
          facet_faces.clear();
          cell.pieces.resize(pieces.size());
          for (unsigned int p = 0; p < pieces.size(); ++p)
            {
              const auto &piece = pieces[p];
              for (const auto &v : piece.vertices)
                cell.reach = std::max(cell.reach, v.distance(x));
              cell.pieces[p].resize(piece.n_faces());
              for (unsigned int f = 0; f < piece.n_faces(); ++f)
                {
                  auto &face = cell.pieces[p][f];
                  for (unsigned int k = piece.face_start[f]; k < piece.face_start[f + 1]; ++k)
                    face.push_back(piece.vertices[piece.face_vertices[k]]);
                  const int tag = piece.tags[f];
                  if (tag > static_cast<int>(i))
                    facet_faces.push_back({{static_cast<unsigned int>(tag), p, f}});
                  else if (is_plane_tag(tag))
                    {
                      // A face on a plane of the domain: the parts beyond which the
                      // domain does not continue are boundary (the rest is a cut
                      // between two pieces of this cell).
                      const unsigned int plane = tag_plane(tag);
                      const Vector       n = domain.plane(plane).normal;
                      ConvexPolygon      G{face, tag_flipped(tag) ? -n : n};
                      parts.clear();
                      domain.boundary_part(G, plane, parts, clipper);
                      for (auto &part : parts)
                        cell.boundary.push_back(std::move(part.vertices));
                    }
                }
            }

          // The facets with the neighbours b > i: the faces tagged b of all pieces.
          std::sort(facet_faces.begin(), facet_faces.end());
          for (unsigned int s = 0; s < facet_faces.size();)
            {
              const unsigned int b = facet_faces[s][0];
              Facet<3>           facet;
              facet.a                = i;
              facet.b                = b;
              const Vector d         = nuclei[b] - x;
              facet.distance         = d.norm();
              facet.normal           = d / facet.distance;
              const Point reference  = Point(0.5 * (x + nuclei[b]));
              Moments     area;
              for (; s < facet_faces.size() && facet_faces[s][0] == b; ++s)
                {
                  const auto &face = cell.pieces[facet_faces[s][1]][facet_faces[s][2]];
                  area.add_area(face.data(), face.size(), facet.normal, reference);
                  facet.polygons.push_back(face);
                }
              if (area.measure < 1e-12 * scale * scale)
                continue;
              facet.area     = area.measure;
              facet.midpoint = reference + area.first / area.measure;
              facet.h_a      = (facet.midpoint - x) * facet.normal;
              facet.h_b      = (nuclei[b] - facet.midpoint) * facet.normal;
              // The second moment about the centroid, in a basis (e1, e2) of the plane:
              // M = [[a, c], [c, b]]; its eigenvector of the larger eigenvalue at the
              // angle theta = atan2(2 c, a - b) / 2 from e1. axis_1 is the other one
              // (I_1 = int (xi . axis_2)^2 dA is the larger moment) and axis_2 =
              // normal x axis_1.
              dealii::SymmetricTensor<2, 3> J = area.second;
              for (unsigned int p = 0; p < 3; ++p)
                for (unsigned int q = p; q < 3; ++q)
                  J[p][q] -= area.first[p] * area.first[q] / area.measure;
              const Vector e1 = perpendicular(facet.normal), e2 = cross_product_3d(facet.normal, e1);
              const double a = e1 * (J * e1), bb = e2 * (J * e2), c = e1 * (J * e2);
              const double mean = 0.5 * (a + bb), radius = std::sqrt(0.25 * (a - bb) * (a - bb) + c * c);
              if (radius <= 1e-9 * std::abs(mean))
                {
                  facet.axis_1 = e1; // isotropic: the deterministic basis of the plane
                  facet.axis_2 = e2;
                }
              else
                {
                  const double theta = 0.5 * std::atan2(2 * c, a - bb);
                  facet.axis_1       = -std::sin(theta) * e1 + std::cos(theta) * e2;
                  facet.axis_2       = cross_product_3d(facet.normal, facet.axis_1);
                }
              facet.second_moment_1 = mean + radius;
              facet.second_moment_2 = mean - radius;
              result.facets.push_back(std::move(facet));
            }
        }
      return result;
    }
  } // namespace RBSN
} // namespace hysteron
